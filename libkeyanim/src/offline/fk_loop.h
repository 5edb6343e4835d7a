// The forward kinematics loop, templated on the lane type: one frame as double, or several
// frames in SIMD lanes (fk.cpp: two in SSE2; fk_v3.cpp: four in AVX), each lane going through
// exactly the operations of a double, so that every instruction set gives the same bits.
// Internal to fk.cpp and fk_v3.cpp. Everything here has internal linkage: each translation unit
// keeps its own copy, compiled for its instruction set (an inline function merged across them
// could run AVX code on a machine without it).
#pragma once
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <vector>

#include "keyanim/offline/fk.h"

namespace keyanim::offline {

// world_points of four frame rows in four AVX lanes (fk_v3.cpp), into out[0..4), each sized
// 4 x the nodes, and under the add reading into out_add[0..4) when it is not null; false, with
// nothing done, where this build has no AVX2 copy (not x86-64). The caller checks the CPU.
bool world_points_v3(const Skeleton& skeleton, const double* const* rows, const uint8_t* nodes,
                     PositionReading reading, double distance, Vec3* const* out, Vec3* const* out_add,
                     const QuatForms* quats);

namespace {

constexpr double kRadPerDeg = std::numbers::pi / 180.0;

// sin and cos of |x| <= pi/4 (error < 1 ulp): fdlibm's __kernel_sin and __kernel_cos with a
// zero tail. In-house rather than libm's so that FK gives the same bits on every platform and
// libm version, in a fraction of the instructions (the encoder's verification is mostly FK).
//
// Copyright (C) 1993 by Sun Microsystems, Inc. All rights reserved.
// Developed at SunPro, a Sun Microsystems, Inc. business.
// Permission to use, copy, modify, and distribute this software is freely granted, provided
// that this notice is preserved.
inline double sqrt_of(double x) noexcept { return std::sqrt(x); }
inline double max0(double x) noexcept { return x > 0.0 ? x : 0.0; }

template <class D>  // double, or a lane type: the same operations on each lane
inline void kernel_sin_cos(D x, D& s, D& c) noexcept {
  constexpr double S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03,
                   S3 = -1.98412698298579493134e-04, S4 = 2.75573137070700676789e-06,
                   S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
  constexpr double C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03,
                   C3 = 2.48015872894767294178e-05, C4 = -2.75573143513906633035e-07,
                   C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;
  const D z = x * x;
  const D w = z * z;
  const D rs = D(S2) + z * (D(S3) + z * D(S4)) + z * w * (D(S5) + z * D(S6));
  s = x + z * x * (D(S1) + z * rs);
  const D rc = z * (D(C1) + z * (D(C2) + z * D(C3))) + w * w * (D(C4) + z * (D(C5) + z * D(C6)));
  const D hz = D(0.5) * z;
  const D one_minus = D(1.0) - hz;
  c = one_minus + (((D(1.0) - one_minus) - hz) + z * rc);
}

// m = m * R_axis(angle). Only the two columns other than `axis` change:
// col_a' = c*col_a + s*col_b, col_b' = c*col_b - s*col_a with (a, b) = (axis+1, axis+2) mod 3.
// One instance per axis, so that the indices are constants (FK is most of the encoder's time).
template <int Axis, class D>
inline void post_rotate_axis(std::array<D, 9>& m, D s, D c) noexcept {
  constexpr int a = (Axis + 1) % 3;
  constexpr int b = (Axis + 2) % 3;
  for (int r = 0; r < 3; ++r) {
    const D ma = m[r * 3 + a];
    const D mb = m[r * 3 + b];
    m[r * 3 + a] = c * ma + s * mb;
    m[r * 3 + b] = c * mb - s * ma;
  }
}
template <class D>
inline void post_rotate(std::array<D, 9>& m, int axis, D s, D c) noexcept {
  switch (axis) {
    case 0: return post_rotate_axis<0>(m, s, c);
    case 1: return post_rotate_axis<1>(m, s, c);
    default: return post_rotate_axis<2>(m, s, c);
  }
}

inline bool is_root(const Joint& joint, size_t index) noexcept {
  return joint.parent < 0 || static_cast<size_t>(joint.parent) >= index;
}

// pos[j]: translation t from the parent's position and rotation m (a root's: t itself).
template <class D>
inline void place(std::array<D, 3>* pos, size_t j, int32_t parent, const std::array<D, 9>& m,
                  const std::array<D, 3>& t) noexcept {
  if (parent < 0) {
    pos[j] = t;
    return;
  }
  const std::array<D, 3>& pp = pos[parent];
  pos[j] = {pp[0] + m[0] * t[0] + m[1] * t[1] + m[2] * t[2],
            pp[1] + m[3] * t[0] + m[4] * t[1] + m[5] * t[2],
            pp[2] + m[6] * t[0] + m[7] * t[1] + m[8] * t[2]};
}

// m = m * R(q) for a quaternion node (QuatForms): q from its stored x, y, z as keyanim/
// rotation.h computes it, in binary64 (sqrt_of and max0 are D's), then its rotation matrix.
template <class D, class Values>
inline void post_rotate_quat(std::array<D, 9>& m, const Values& values, const QuatForms& quats, int32_t i) noexcept {
  const std::array<double, 4>& r = quats.reference[size_t(i)];
  const D ref[4] = {D(r[0]), D(r[1]), D(r[2]), D(r[3])};
  const uint32_t c = quats.column[size_t(i)];
  D q[4];
  stored_rotation<D>(ref, values.value(c), values.value(c + 1), values.value(c + 2), q,
                     [](D x) { return sqrt_of(x); }, [](D x) { return max0(x); });
  const D one(1.0), two(2.0);
  const D xx = q[0] * q[0], yy = q[1] * q[1], zz = q[2] * q[2];
  const D xy = q[0] * q[1], xz = q[0] * q[2], yz = q[1] * q[2], xw = q[0] * q[3], yw = q[1] * q[3], zw = q[2] * q[3];
  const D b[9] = {one - two * (yy + zz), two * (xy - zw),       two * (xz + yw),
                  two * (xy + zw),       one - two * (xx + zz), two * (yz - xw),
                  two * (xz - yw),       two * (yz + xw),       one - two * (xx + yy)};
  const std::array<D, 9> a = m;
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col)
      m[size_t(3 * row + col)] = (a[size_t(3 * row)] * b[col] + a[size_t(3 * row + 1)] * b[3 + col]) +
                                 a[size_t(3 * row + 2)] * b[6 + col];
}

// The one FK loop everything else uses, on one frame (double) or several in SIMD lanes. `values`
// gives a channel's value (value(column)) and the sine and cosine of a rotation's
// (sin_cos(column, s, c)), as D, and its `quats` (null, or a clip's quaternion nodes, whose
// rotation channels hold stored x, y, z). pos and rot have room for every node. With `nodes`, only the nodes it marks (a set holding every ancestor of
// its members) are computed. With `pos_add`, the positions under the add reading go there as
// well (`reading` then says replace): the rotations, most of the work, do not depend on the
// reading, so both readings cost one pass, each position the same operations as its own pass.
template <bool kBoth, typename Values, typename D>
void pose_frame_readings(const Skeleton& skeleton, const Values& values, std::array<D, 3>* pos, std::array<D, 9>* rot,
                         const uint8_t* nodes, PositionReading reading, std::array<D, 3>* pos_add) noexcept {
  const bool add = reading == PositionReading::add;
  const D zero(0.0), one(1.0);
  const std::array<D, 9> identity{one, zero, zero, zero, one, zero, zero, zero, one};
  const size_t n = skeleton.joints.size();
  for (size_t j = 0; j < n; ++j) {
    if (nodes && !nodes[j]) continue;
    const Joint& joint = skeleton.joints[j];
    const bool root = is_root(joint, j);
    const std::array<D, 9>& parent_rot = root ? identity : rot[joint.parent];
    std::array<D, 3> t{D(joint.offset[0]), D(joint.offset[1]), D(joint.offset[2])};
    [[maybe_unused]] std::array<D, 3> t_add;
    if constexpr (kBoth) t_add = t;
    std::array<D, 9>& r = rot[j];
    r = parent_rot;
    const int32_t quat = values.quats ? values.quats->of_node[j] : -1;
    if (quat >= 0) post_rotate_quat(r, values, *values.quats, quat);
    for (size_t k = 0; k < joint.channels.size(); ++k) {
      const ChannelType type = joint.channels[k];
      const uint32_t column = joint.first_channel + uint32_t(k);
      if (is_rotation(type)) {
        if (quat >= 0) continue;
        D sn, cs;
        values.sin_cos(column, sn, cs);
        post_rotate(r, channel_axis(type), sn, cs);
      } else {
        const size_t axis = static_cast<size_t>(channel_axis(type));
        const D v = values.value(column);
        t[axis] = add ? D(joint.offset[axis]) + v : v;
        if constexpr (kBoth) t_add[axis] = D(joint.offset[axis]) + v;
      }
    }
    place(pos, j, root ? -1 : joint.parent, parent_rot, t);
    if constexpr (kBoth) place(pos_add, j, root ? -1 : joint.parent, parent_rot, t_add);
  }
}

template <typename Values, typename D = typename Values::D>
void pose_frame(const Skeleton& skeleton, const Values& values, std::array<D, 3>* pos, std::array<D, 9>* rot,
                const uint8_t* nodes = nullptr, PositionReading reading = PositionReading::replace,
                std::array<D, 3>* pos_add = nullptr) noexcept {
  if (pos_add) return pose_frame_readings<true>(skeleton, values, pos, rot, nodes, reading, pos_add);
  pose_frame_readings<false>(skeleton, values, pos, rot, nodes, reading, pos_add);
}

}  // namespace
}  // namespace keyanim::offline
