// Forward kinematics of BVH skeletons (rules in keyanim/offline/fk.h).
#include "keyanim/offline/fk.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

namespace keyanim::offline {
namespace {

constexpr double kRadPerDeg = std::numbers::pi / 180.0;
constexpr Mat3 kIdentity{1, 0, 0, 0, 1, 0, 0, 0, 1};


// sin and cos of |x| <= pi/4 (error < 1 ulp): fdlibm's __kernel_sin and __kernel_cos with a
// zero tail. In-house rather than libm's so that FK gives the same bits on every platform and
// libm version, in a fraction of the instructions (the encoder's verification is mostly FK).
//
// Copyright (C) 1993 by Sun Microsystems, Inc. All rights reserved.
// Developed at SunPro, a Sun Microsystems, Inc. business.
// Permission to use, copy, modify, and distribute this software is freely granted, provided
// that this notice is preserved.
inline void kernel_sin_cos(double x, double& s, double& c) noexcept {
  constexpr double S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03,
                   S3 = -1.98412698298579493134e-04, S4 = 2.75573137070700676789e-06,
                   S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
  constexpr double C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03,
                   C3 = 2.48015872894767294178e-05, C4 = -2.75573143513906633035e-07,
                   C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;
  const double z = x * x;
  const double w = z * z;
  const double rs = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6);
  s = x + z * x * (S1 + z * rs);
  const double rc = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
  const double hz = 0.5 * z;
  const double one_minus = 1.0 - hz;
  c = one_minus + (((1.0 - one_minus) - hz) + z * rc);
}

}  // namespace

// Reducing to about [-45, 45] around the nearest multiple of 90 first makes 90/180/270 exact
// and makes a +-360 shift change nothing (the reduced angle is computed exactly; only an angle
// on a 45-degree tie may land in the other quadrant and differ in the last bit), so FK agrees
// with channel errors compared modulo 360.
void sin_cos_deg(double deg, double& s, double& c) noexcept {
  if (!(std::fabs(deg) < 1e15)) {  // NaN, inf or too large for an exact quadrant count
    s = std::sin(deg * kRadPerDeg);
    c = std::cos(deg * kRadPerDeg);
    return;
  }
  // Nearest quadrant by truncation (a plain conversion instruction, unlike nearbyint's libm
  // call); ties and the inexact 1/90 only pick between two equally valid quadrants.
  const double scaled = deg * (1.0 / 90.0);
  const int64_t quadrant = static_cast<int64_t>(scaled + (scaled >= 0 ? 0.5 : -0.5));
  const double r = (deg - static_cast<double>(quadrant) * 90.0) * kRadPerDeg;  // exact difference
  double sr, cr;
  kernel_sin_cos(r, sr, cr);
  switch (quadrant & 3) {
    case 0: s = sr; c = cr; break;
    case 1: s = cr; c = -sr; break;
    case 2: s = -sr; c = -cr; break;
    default: s = -cr; c = sr; break;
  }
}

namespace {

// m = m * R_axis(angle). Only the two columns other than `axis` change:
// col_a' = c*col_a + s*col_b, col_b' = c*col_b - s*col_a with (a, b) = (axis+1, axis+2) mod 3.
// One instance per axis, so that the indices are constants (FK is most of the encoder's time).
template <int Axis>
inline void post_rotate_axis(Mat3& m, double s, double c) noexcept {
  constexpr int a = (Axis + 1) % 3;
  constexpr int b = (Axis + 2) % 3;
  for (int r = 0; r < 3; ++r) {
    const double ma = m[r * 3 + a];
    const double mb = m[r * 3 + b];
    m[r * 3 + a] = c * ma + s * mb;
    m[r * 3 + b] = c * mb - s * ma;
  }
}
inline void post_rotate(Mat3& m, int axis, double s, double c) noexcept {
  switch (axis) {
    case 0: return post_rotate_axis<0>(m, s, c);
    case 1: return post_rotate_axis<1>(m, s, c);
    default: return post_rotate_axis<2>(m, s, c);
  }
}

inline bool is_root(const Joint& joint, size_t index) noexcept {
  return joint.parent < 0 || static_cast<size_t>(joint.parent) >= index;
}

struct ComputeSinCos {
  void operator()(uint32_t /*column*/, double deg, double& s, double& c) const noexcept { sin_cos_deg(deg, s, c); }
};
struct GivenSinCos {
  const double* sines;
  const double* cosines;
  void operator()(uint32_t column, double /*deg*/, double& s, double& c) const noexcept {
    s = sines[column], c = cosines[column];
  }
};

// The one FK loop everything else uses. pos and rot have room for every node. With `nodes`,
// only the nodes it marks (a set holding every ancestor of its members) are computed.
template <typename SinCos>
void pose_frame(const Skeleton& skeleton, const double* row, Vec3* pos, Mat3* rot, SinCos sin_cos,
                const uint8_t* nodes = nullptr) noexcept {
  const size_t n = skeleton.joints.size();
  for (size_t j = 0; j < n; ++j) {
    if (nodes && !nodes[j]) continue;
    const Joint& joint = skeleton.joints[j];
    const bool root = is_root(joint, j);
    const Mat3& parent_rot = root ? kIdentity : rot[joint.parent];
    Vec3 t = joint.offset;
    Mat3& r = rot[j];
    r = parent_rot;
    const double* v = row + joint.first_channel;
    for (size_t k = 0; k < joint.channels.size(); ++k) {
      const ChannelType type = joint.channels[k];
      if (is_rotation(type)) {
        double sn, cs;
        sin_cos(joint.first_channel + uint32_t(k), v[k], sn, cs);
        post_rotate(r, channel_axis(type), sn, cs);
      } else {
        t[static_cast<size_t>(channel_axis(type))] = v[k];
      }
    }
    if (root) {
      pos[j] = t;
    } else {
      const Vec3& pp = pos[joint.parent];
      const Mat3& m = parent_rot;
      pos[j] = {pp[0] + m[0] * t[0] + m[1] * t[1] + m[2] * t[2],
                pp[1] + m[3] * t[0] + m[4] * t[1] + m[5] * t[2],
                pp[2] + m[6] * t[0] + m[7] * t[1] + m[8] * t[2]};
    }
  }
}

}  // namespace

Mat3 local_rotation(const Joint& joint, const double* frame_row) {
  Mat3 m = kIdentity;
  const double* v = frame_row + joint.first_channel;
  for (size_t k = 0; k < joint.channels.size(); ++k) {
    if (is_rotation(joint.channels[k])) {
      double sn, cs;
      sin_cos_deg(v[k], sn, cs);
      post_rotate(m, channel_axis(joint.channels[k]), sn, cs);
    }
  }
  return m;
}

namespace {

// World positions into `out`, with a per-thread rotation scratch so that the encoder's
// per-frame calls allocate nothing after the first.
template <typename SinCos>
void positions_with_scratch(const Skeleton& skeleton, const double* frame_row, SinCos sin_cos,
                            std::vector<Vec3>& out, const uint8_t* nodes = nullptr) {
  thread_local std::vector<Mat3> rotations;
  const size_t n = skeleton.joints.size();
  if (rotations.size() < n) rotations.resize(n);
  out.resize(n);
  pose_frame(skeleton, frame_row, out.data(), rotations.data(), sin_cos, nodes);
}

}  // namespace

void world_positions(const Skeleton& skeleton, const double* frame_row, std::vector<Vec3>& out) {
  positions_with_scratch(skeleton, frame_row, ComputeSinCos{}, out);
}

void world_positions(const Skeleton& skeleton, const double* frame_row, const uint8_t* nodes, std::vector<Vec3>& out) {
  positions_with_scratch(skeleton, frame_row, ComputeSinCos{}, out, nodes);
}

void world_positions(const Skeleton& skeleton, const double* frame_row, const double* sines, const double* cosines,
                     std::vector<Vec3>& out) {
  positions_with_scratch(skeleton, frame_row, GivenSinCos{sines, cosines}, out);
}

void world_pose(const Skeleton& skeleton, const double* frame_row, std::vector<Vec3>& positions,
                std::vector<Mat3>& rotations) {
  const size_t n = skeleton.joints.size();
  positions.resize(n);
  rotations.resize(n);
  pose_frame(skeleton, frame_row, positions.data(), rotations.data(), ComputeSinCos{});
}

std::vector<Vec3> world_positions_all(const Motion& motion) {
  const size_t n = motion.skeleton.joints.size();
  const size_t channels = motion.channel_count();
  const size_t frames = motion.frame_count;
  // A malformed Motion (too few values) must not be read past its end.
  const size_t complete = !channel_columns_consistent(motion.skeleton) ? 0
                          : channels == 0 ? frames
                                          : std::min(frames, motion.values.size() / channels);
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  std::vector<Vec3> out(frames * n, Vec3{kNaN, kNaN, kNaN});
  std::vector<Mat3> rotations(n);
  for (size_t f = 0; f < complete; ++f) {
    pose_frame(motion.skeleton, motion.values.data() + f * channels, out.data() + f * n,
               rotations.data(), ComputeSinCos{});
  }
  return out;
}

bool channel_columns_consistent(const Skeleton& skeleton) noexcept {
  const size_t channels = skeleton.channel_count();
  for (const Joint& joint : skeleton.joints) {
    if (size_t(joint.first_channel) + joint.channels.size() > channels) return false;
  }
  return true;
}

double skeleton_size(const Skeleton& skeleton) {
  const size_t n = skeleton.joints.size();
  if (n == 0) return 0.0;
  std::vector<Vec3> rest(n);
  Vec3 lo{};
  Vec3 hi{};
  for (size_t j = 0; j < n; ++j) {
    const Joint& joint = skeleton.joints[j];
    const Vec3 base = is_root(joint, j) ? Vec3{} : rest[joint.parent];
    for (size_t a = 0; a < 3; ++a) rest[j][a] = base[a] + joint.offset[a];
    for (size_t a = 0; a < 3; ++a) {
      lo[a] = j == 0 ? rest[j][a] : std::min(lo[a], rest[j][a]);
      hi[a] = j == 0 ? rest[j][a] : std::max(hi[a], rest[j][a]);
    }
  }
  return std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
}

}  // namespace keyanim::offline
