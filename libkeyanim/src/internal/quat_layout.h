// Which channels of a version 5 clip hold quaternion curves (spec/FORMAT.md section 4.7, QUAT):
// the one rule the container writer, the loader and the image share, so that they cannot
// disagree on which channel's key frames KTIM stores.
#pragma once
#include <cmath>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "internal/clip_source.h"
#include "internal/format.h"
#include "keyanim/rotation.h"
#include "keyanim/skeleton.h"

namespace keyanim::internal {

// What a channel stores.
enum class Stored : uint8_t {
  value = 0,   // its own value (a position, or an Euler angle)
  quat_x = 1,  // a quaternion node's x: its key frames are stored in KTIM
  quat_y = 2,  // y and z: their key frames are x's (not stored again)
  quat_z = 3,
};

// The first column of `node`'s three rotation channels (the node must be quaternion_capable).
inline uint32_t first_quat_channel(const Skeleton& s, uint32_t node) noexcept {
  uint32_t first = 0;
  quaternion_capable(s.joints[node], &first);
  return s.joints[node].first_channel + first;
}

// Per channel (frame column), what it stores; `nodes` follow section 4.7's rules (increasing,
// each quaternion_capable, channel columns assigned).
inline std::vector<Stored> stored_kinds(const Skeleton& s, std::span<const QuatNode> nodes) {
  std::vector<Stored> out(s.channel_count(), Stored::value);
  for (const QuatNode& n : nodes) {
    const uint32_t c = first_quat_channel(s, n.node);
    out[c] = Stored::quat_x, out[c + 1] = Stored::quat_y, out[c + 2] = Stored::quat_z;
  }
  return out;
}

// Whether a reference's x, y, z are those of a unit quaternion (section 4.7): x^2 + y^2 + z^2 <=
// 2^30 (in units of 2^-15).
inline bool valid_reference(const int16_t (&r)[3]) noexcept {
  const int64_t x = r[0], y = r[1], z = r[2];
  return x * x + y * y + z * z <= (int64_t(1) << 30);
}
// The binary32 reference an image holds for `n` (reference_of), and whether four floats are
// that of some valid reference (its x, y, z back in `n`).
inline bool reference_from_floats(const float (&q)[4], QuatNode& n) noexcept {
  for (int k = 0; k < 3; ++k) {
    const double v = double(q[k]) / kReferenceUnit;
    if (!(v >= -32768.0 && v <= 32767.0) || v != std::floor(v)) return false;
    n.reference[k] = static_cast<int16_t>(v);
  }
  if (!valid_reference(n.reference)) return false;
  float back[4];
  reference_of(n, back);
  return std::memcmp(back, q, sizeof back) == 0;
}

// Section 4.7's bound on a quaternion node's stored x, y, z: every key's value within +-16. A
// rotation's components are within +-1 (the encoder's keys within +-2); the bound keeps every
// in-between's square sum far from binary32's overflow (about 1.8e19 squared), where a binary32
// pose and a binary64 one would disagree (a zero or NaN rotation against a finite one).
inline constexpr double kMaxStoredQuatValue = 16.0;

// The first channel of `src` (keys decoded) holding a quaternion node's stored x, y or z with a
// key beyond kMaxStoredQuatValue, or UINT32_MAX when none has.
inline uint32_t stored_quat_out_of_range(const ClipSource& src) {
  if (src.quat_nodes.empty()) return UINT32_MAX;
  const std::vector<Stored> kinds = stored_kinds(src.skeleton, src.quat_nodes);
  for (uint32_t c = 0; c < src.channels.size(); ++c) {
    if (kinds[c] == Stored::value) continue;
    const SourceChannel& sc = src.channels[c];
    for (uint64_t i = sc.first_key; i < sc.first_key + sc.key_count; ++i)
      if (!(std::fabs(dequantize(src.q[i], sc.step)) <= kMaxStoredQuatValue)) return c;
  }
  return UINT32_MAX;
}

}  // namespace keyanim::internal
