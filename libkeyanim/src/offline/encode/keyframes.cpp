#include "keyanim/offline/keyframes.h"

#include <algorithm>
#include <string>

#include "keyanim/offline/error.h"

namespace keyanim::offline {

std::vector<uint32_t> uniform_keys(uint32_t frame_count, uint32_t interval) {
  std::vector<uint32_t> keys;
  if (frame_count == 0) return keys;
  if (interval == 0) interval = 1;  // the contract says >= 1; do not loop forever if broken
  const uint32_t last = frame_count - 1;
  keys.reserve(last / interval + 2);
  // Step in 64 bits: f + interval may overflow 32 bits near the top of the range.
  for (uint64_t f = 0; f < last; f += interval) keys.push_back(static_cast<uint32_t>(f));
  keys.push_back(last);
  return keys;
}

std::vector<uint32_t> manual_keys(std::vector<uint32_t> frames, uint32_t frame_count) {
  for (const uint32_t f : frames) {
    if (f >= frame_count)
      throw Error(ErrorKind::invalid_argument,
                  frame_count == 0 ? "key frame " + std::to_string(f) + " given, but the motion has no frames"
                                   : "key frame " + std::to_string(f) + " is out of range [0, " +
                                         std::to_string(frame_count - 1) + "]");
  }
  if (frame_count == 0) return {};
  frames.push_back(0);
  frames.push_back(frame_count - 1);
  std::sort(frames.begin(), frames.end());
  frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
  return frames;
}

}  // namespace keyanim::offline
