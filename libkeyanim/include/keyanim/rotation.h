// Rotations stored as quaternion curves (spec/FORMAT.md section 4.7, QUAT, and Appendix B): a
// node whose three rotation channels hold the x, y, z curves of its rotation relative to a
// reference rotation, w rebuilt. A pose then needs a square root, a product and a
// normalization per node instead of three sines and cosines, and its three curves share their
// key frames (one search per node). The arithmetic here is the one place both sides compute it:
// the encoder in binary64 (its error guarantee), the runtime in binary32 lanes (its poses),
// through the same template.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "keyanim/skeleton.h"

namespace keyanim {

// A node stored as a quaternion (QUAT): its rotation channels c, c + 1, c + 2 (its first three,
// consecutive in its channel list) hold x, y, z of the rotation relative to its reference, a
// unit quaternion given by its x, y, z in units of 2^-15 (kReferenceUnit), w = sqrt(1 - x^2 -
// y^2 - z^2) >= 0: the identity (0, 0, 0) for most joints, whose rotation stays near the rest
// pose's, so that the references of a short clip cost a few bytes.
struct QuatNode {
  uint32_t node = 0;
  int16_t reference[3] = {0, 0, 0};  // x^2 + y^2 + z^2 <= 2^30
};
inline constexpr double kReferenceUnit = 1.0 / 32768.0;

// The reference of `n` as a unit quaternion (x, y, z, w) in binary64: x, y, z exactly, w =
// sqrt(1 - (x^2 + y^2 + z^2)) (the sum exact in binary64: integers below 2^31 times 2^-30).
inline void reference_of(const QuatNode& n, double (&q)[4]) noexcept {
  const double x = n.reference[0], y = n.reference[1], z = n.reference[2];
  const double sum = (x * x + y * y) + z * z;
  q[0] = x * kReferenceUnit, q[1] = y * kReferenceUnit, q[2] = z * kReferenceUnit;
  q[3] = std::sqrt(std::max(0.0, 1.0 - sum * (kReferenceUnit * kReferenceUnit)));
}
// The same rounded to binary32 (what a runtime image holds).
inline void reference_of(const QuatNode& n, float (&q)[4]) noexcept {
  double d[4];
  reference_of(n, d);
  for (int k = 0; k < 4; ++k) q[k] = static_cast<float>(d[k]);
}

// Whether `joint` can be stored as a quaternion (spec 4.7): exactly three rotation channels,
// consecutive in its channel list, about three different axes. `first` gets the index in its
// channel list of the first of them.
inline bool quaternion_capable(const Joint& joint, uint32_t* first = nullptr) noexcept {
  uint32_t count = 0, at = 0, axes = 0;
  for (uint32_t k = 0; k < joint.channels.size(); ++k) {
    if (!is_rotation(joint.channels[k])) continue;
    if (count == 0) at = k;
    if (k != at + count) return false;  // not consecutive
    axes |= 1u << channel_axis(joint.channels[k]);
    ++count;
  }
  if (count != 3 || axes != 7u) return false;
  if (first) *first = at;
  return true;
}

// The rotation of a quaternion node from its three stored values (spec Appendix B): the
// relative rotation (x, y, z, w) with w = sqrt(max(0, 1 - (x^2 + y^2 + z^2))), turned by the
// reference, q = reference * (x, y, z, w) (Hamilton product), then normalized. T is double (the
// encoder, converters), float or a lane type of floats (the runtime: the same operations in
// every lane, so that every instruction set gives the same bits). `sqrt_of` and `max0` (x if
// x > 0, else 0) are T's.
template <class T, class Sqrt, class Max0>
inline void stored_rotation(const T (&ref)[4], T x, T y, T z, T (&q)[4], Sqrt sqrt_of, Max0 max0) noexcept {
  const T one(1.0f);
  const T w = sqrt_of(max0(one - ((x * x + y * y) + z * z)));
  const T qx = ((ref[3] * x + ref[0] * w) + ref[1] * z) - ref[2] * y;
  const T qy = ((ref[3] * y - ref[0] * z) + ref[1] * w) + ref[2] * x;
  const T qz = ((ref[3] * z + ref[0] * y) - ref[1] * x) + ref[2] * w;
  const T qw = ((ref[3] * w - ref[0] * x) - ref[1] * y) - ref[2] * z;
  const T inv = one / sqrt_of(((qx * qx + qy * qy) + qz * qz) + qw * qw);
  q[0] = qx * inv, q[1] = qy * inv, q[2] = qz * inv, q[3] = qw * inv;
}

// The binary64 form (encoder, converters).
inline void stored_rotation(const QuatNode& n, double x, double y, double z, double (&q)[4]) noexcept {
  double ref[4];
  reference_of(n, ref);
  stored_rotation<double>(ref, x, y, z, q, [](double v) { return std::sqrt(v); },
                          [](double v) { return v > 0.0 ? v : 0.0; });
}

// Euler angles in degrees (a, b, c) of the unit quaternion q for a node whose rotation channels
// are about `axes` (three different axes, 0 X, 1 Y, 2 Z, in channel order), intrinsic:
// R(q) = R_axes[0](a) R_axes[1](b) R_axes[2](c), with b in [-90, 90] (spec Appendix B's channel
// values of a quaternion node). Near b = +-90 (gimbal lock), where only a +- c is defined, c is
// computed from the a found, so that the angles recompose q. Binary64 throughout.
void euler_from_quaternion(const double (&q)[4], const uint8_t (&axes)[3], double (&deg)[3]) noexcept;

// Of the two Euler solutions of the same rotation ((a, b, c) and (a + 180, 180 - b, c + 180)),
// each angle moved by whole turns to lie within 180 degrees of `previous`, the one nearest it
// (the sum of the three differences): what a converter writes frame after frame, so that a
// rebuilt BVH file's channels are continuous.
void nearest_euler(const double (&previous)[3], double (&deg)[3]) noexcept;

}  // namespace keyanim
