// Which channels of a version 5 clip hold quaternion curves (spec/FORMAT.md section 4.7, QUAT):
// the one rule the container writer, the loader and the image share, so that they cannot
// disagree on which channel's key frames KTIM stores.
#pragma once
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

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
inline uint32_t quat_column(const Skeleton& s, uint32_t node) noexcept {
  uint32_t first = 0;
  quaternion_capable(s.joints[node], &first);
  return s.joints[node].first_channel + first;
}

// Per channel (frame column), what it stores; `nodes` follow section 4.7's rules (increasing,
// each quaternion_capable, channel columns assigned).
inline std::vector<Stored> stored_kinds(const Skeleton& s, std::span<const QuatNode> nodes) {
  std::vector<Stored> out(s.channel_count(), Stored::value);
  for (const QuatNode& n : nodes) {
    const uint32_t c = quat_column(s, n.node);
    out[c] = Stored::quat_x, out[c + 1] = Stored::quat_y, out[c + 2] = Stored::quat_z;
  }
  return out;
}

// Whether a reference is a unit quaternion in binary32 (section 4.7): finite, its squared norm
// within kQuatNormSlack of 1.
inline bool valid_reference(const float (&r)[4]) noexcept {
  const double n = double(r[0]) * r[0] + double(r[1]) * r[1] + double(r[2]) * r[2] + double(r[3]) * r[3];
  return std::isfinite(n) && std::fabs(n - 1.0) <= kQuatNormSlack;
}

}  // namespace keyanim::internal
