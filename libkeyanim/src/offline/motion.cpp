#include "keyanim/offline/motion.h"

namespace keyanim::offline {

std::vector<double> Motion::channel(uint32_t c) const {
  const uint32_t n = channel_count();
  std::vector<double> out(frame_count);
  for (uint32_t f = 0; f < frame_count; ++f) out[f] = values[size_t(f) * n + c];
  return out;
}

}  // namespace keyanim::offline
