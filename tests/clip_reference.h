// A clip's channels evaluated the reference way: its keys (Clip::channel_keys) through
// eval_channel (cardinal.h, spec/FORMAT.md Appendix A). Tests compare the runtime's fast paths
// with this, bit for bit.
#pragma once
#include <cstdint>
#include <utility>
#include <vector>

#include "keyanim/cardinal.h"
#include "keyanim/clip.h"
#include "keyanim/rotation.h"

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

// A quaternion node (version 5, spec/FORMAT.md section 4.7) as the reference sees it: the
// channel of its stored x (y and z follow), the node and its reference, and the axes of its
// rotation channels in their order (Appendix B).
struct QuatChannels {
  uint32_t first = 0;
  QuatNode node;
  uint8_t axes[3] = {0, 0, 0};
};

// The clip's quaternion nodes (Clip::quat_node, in node order), each a quaternion_capable node.
inline std::vector<QuatChannels> quat_channels(const Clip& clip) {
  std::vector<QuatChannels> out;
  for (uint32_t i = 0; i < clip.quat_node_count(); ++i) {
    QuatChannels q;
    q.node = clip.quat_node(i);
    if (q.node.node >= clip.skeleton().joints.size()) continue;
    const Joint& j = clip.skeleton().joints[q.node.node];
    uint32_t at = 0;
    if (!quaternion_capable(j, &at)) continue;
    q.first = j.first_channel + at;
    for (int k = 0; k < 3; ++k) q.axes[k] = static_cast<uint8_t>(channel_axis(j.channels[at + k]));
    out.push_back(q);
  }
  return out;
}

// A quaternion node's Euler angles from its stored x, y, z, as Clip::sample gives its rotation
// channels: Appendix B in binary64 (stored_rotation, euler_from_quaternion), rounded to binary32.
inline void euler_of_stored(const QuatChannels& q, const float (&xyz)[3], float (&deg)[3]) {
  double r[4], d[3];
  stored_rotation(q.node, xyz[0], xyz[1], xyz[2], r);
  euler_from_quaternion(r, q.axes, d);
  for (int k = 0; k < 3; ++k) deg[k] = static_cast<float>(d[k]);
}

// What Clip::sample gives, the reference way: every channel's eval_channel on its keys (what
// sample_stored gives), then each quaternion node's three channels turned into its Euler angles.
struct SampleReference {
  std::vector<ChannelKeys> keys;
  std::vector<QuatChannels> quats;
  std::vector<int32_t> quat_of;  // per channel: index into quats of the node holding it, or -1
};

inline SampleReference sample_reference(const Clip& clip, std::vector<ChannelKeys> keys) {
  SampleReference r;
  r.keys = std::move(keys);
  r.quats = quat_channels(clip);
  r.quat_of.assign(r.keys.size(), -1);
  for (size_t i = 0; i < r.quats.size(); ++i)
    for (uint32_t k = 0; k < 3; ++k)
      if (r.quats[i].first + k < r.quat_of.size()) r.quat_of[r.quats[i].first + k] = static_cast<int32_t>(i);
  return r;
}

inline SampleReference sample_reference(const Clip& clip) { return sample_reference(clip, all_channel_keys(clip)); }

// Channel c at f as Clip::sample (and sample_channels, sample_channel) gives it.
inline float reference_sample(const Clip& clip, const SampleReference& r, uint32_t c, float f) {
  const int32_t i = r.quat_of[c];
  if (i < 0) return reference_value(clip, r.keys[c], f);
  const QuatChannels& q = r.quats[static_cast<size_t>(i)];
  float xyz[3], deg[3];
  for (uint32_t k = 0; k < 3; ++k) xyz[k] = reference_value(clip, r.keys[q.first + k], f);
  euler_of_stored(q, xyz, deg);
  return deg[c - q.first];
}

}  // namespace keyanim::test
