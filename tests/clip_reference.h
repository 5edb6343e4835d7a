// A clip's channels evaluated the reference way: its keys (Clip::channel_keys) through
// eval_channel (cardinal.h, spec/FORMAT.md Appendix A). Tests compare the runtime's fast paths
// with this, bit for bit.
#pragma once
#include <cstdint>
#include <vector>

#include "keyanim/cardinal.h"
#include "keyanim/clip.h"

namespace keyanim::test {

struct ChannelKeys {
  std::vector<uint32_t> frames;
  std::vector<float> values;
  Interpolation interp = Interpolation::cardinal;
  float s = 0.5f;
};

inline ChannelKeys channel_keys(const Clip& clip, uint32_t c) {
  const ChannelInfo info = clip.channel(c);
  ChannelKeys k;
  k.frames.resize(info.key_count);
  k.values.resize(info.key_count);
  if (clip.channel_keys(c, k.frames, k.values) != Status::ok) k.frames.clear(), k.values.clear();
  k.interp = info.interp;
  k.s = tension_to_s(info.tension);
  return k;
}

inline std::vector<ChannelKeys> all_channel_keys(const Clip& clip) {
  std::vector<ChannelKeys> out;
  for (uint32_t c = 0; c < clip.channel_count(); ++c) out.push_back(channel_keys(clip, c));
  return out;
}

inline float reference_value(const Clip& clip, const ChannelKeys& k, float f) {
  return eval_channel(k.frames.data(), k.values.data(), static_cast<uint32_t>(k.frames.size()), f, k.interp, k.s,
                      clip.tangent_rule());
}

}  // namespace keyanim::test
