// Forward kinematics of BVH skeletons (rules in keyanim/offline/fk.h).
#include "keyanim/offline/fk.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "keyanim/offline/error.h"

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
template <class D>  // double, or Lanes2 below: the same operations on each lane
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

// Two doubles at once (two frames posed together): SSE2 where there is SSE2 (every x86-64),
// else two plain doubles. Each lane goes through exactly the operations of a double.
#if defined(__SSE2__)
struct Lanes2 {
  __m128d v;
  Lanes2() = default;
  explicit Lanes2(__m128d x) : v(x) {}
  explicit Lanes2(double x) : v(_mm_set1_pd(x)) {}
  Lanes2(double a, double b) : v(_mm_set_pd(b, a)) {}
  double lane(int i) const {
    alignas(16) double out[2];
    _mm_store_pd(out, v);
    return out[i];
  }
  // Both lanes into a and b, without a round trip through the stack.
  void split(double& a, double& b) const {
    _mm_storel_pd(&a, v);
    _mm_storeh_pd(&b, v);
  }
};
inline Lanes2 operator+(Lanes2 a, Lanes2 b) { return Lanes2(_mm_add_pd(a.v, b.v)); }
inline Lanes2 operator-(Lanes2 a, Lanes2 b) { return Lanes2(_mm_sub_pd(a.v, b.v)); }
inline Lanes2 operator*(Lanes2 a, Lanes2 b) { return Lanes2(_mm_mul_pd(a.v, b.v)); }
#else
struct Lanes2 {
  double x[2];
  Lanes2() = default;
  explicit Lanes2(double v) : x{v, v} {}
  Lanes2(double a, double b) : x{a, b} {}
  double lane(int i) const { return x[i]; }
  void split(double& a, double& b) const { a = x[0], b = x[1]; }
};
inline Lanes2 operator+(Lanes2 a, Lanes2 b) { return {a.x[0] + b.x[0], a.x[1] + b.x[1]}; }
inline Lanes2 operator-(Lanes2 a, Lanes2 b) { return {a.x[0] - b.x[0], a.x[1] - b.x[1]}; }
inline Lanes2 operator*(Lanes2 a, Lanes2 b) { return {a.x[0] * b.x[0], a.x[1] * b.x[1]}; }
#endif

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

// sin_cos_deg of both lanes, bit for bit. Angles of 10^9 degrees or more (or NaN) take the
// scalar path: below that the quadrant fits a 32-bit integer.
inline void sin_cos_deg2(Lanes2 deg, Lanes2& s, Lanes2& c) noexcept {
#if defined(__SSE2__)
  const __m128d magnitude = _mm_andnot_pd(_mm_set1_pd(-0.0), deg.v);
  if (_mm_movemask_pd(_mm_cmplt_pd(magnitude, _mm_set1_pd(1e9))) != 3) {
    double s0, c0, s1, c1;
    sin_cos_deg(deg.lane(0), s0, c0);
    sin_cos_deg(deg.lane(1), s1, c1);
    s = Lanes2(s0, s1), c = Lanes2(c0, c1);
    return;
  }
  const __m128d scaled = _mm_mul_pd(deg.v, _mm_set1_pd(1.0 / 90.0));
  const __m128d ge = _mm_cmpge_pd(scaled, _mm_setzero_pd());
  const __m128d half = _mm_or_pd(_mm_and_pd(ge, _mm_set1_pd(0.5)), _mm_andnot_pd(ge, _mm_set1_pd(-0.5)));
  const __m128i q = _mm_cvttpd_epi32(_mm_add_pd(scaled, half));  // two int32, as the scalar int64
  const Lanes2 r((_mm_mul_pd(_mm_sub_pd(deg.v, _mm_mul_pd(_mm_cvtepi32_pd(q), _mm_set1_pd(90.0))),
                            _mm_set1_pd(kRadPerDeg))));
  Lanes2 sr, cr;
  kernel_sin_cos(r, sr, cr);
  // Per lane: swap for odd quadrants, negate s for quadrants 2 and 3, c for 1 and 2.
  const __m128i q64 = _mm_shuffle_epi32(q, _MM_SHUFFLE(1, 1, 0, 0));
  const __m128i one = _mm_set1_epi32(1), two = _mm_set1_epi32(2);
  const __m128d swap = _mm_castsi128_pd(_mm_cmpeq_epi32(_mm_and_si128(q64, one), one));
  const __m128d sign = _mm_set1_pd(-0.0);
  const __m128d neg_s = _mm_and_pd(_mm_castsi128_pd(_mm_cmpeq_epi32(_mm_and_si128(q64, two), two)), sign);
  const __m128d neg_c =
      _mm_and_pd(_mm_castsi128_pd(_mm_cmpeq_epi32(_mm_and_si128(_mm_add_epi32(q64, one), two), two)), sign);
  s = Lanes2(_mm_xor_pd(_mm_or_pd(_mm_and_pd(swap, cr.v), _mm_andnot_pd(swap, sr.v)), neg_s));
  c = Lanes2(_mm_xor_pd(_mm_or_pd(_mm_and_pd(swap, sr.v), _mm_andnot_pd(swap, cr.v)), neg_c));
#else
  sin_cos_deg(deg.x[0], s.x[0], c.x[0]);
  sin_cos_deg(deg.x[1], s.x[1], c.x[1]);
#endif
}

}  // namespace

namespace {

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

// Where pose_frame gets a channel's value and the sine and cosine of a rotation's.
struct OneRow {
  using D = double;
  const double* row;
  D value(uint32_t column) const noexcept { return row[column]; }
  void sin_cos(uint32_t column, D& s, D& c) const noexcept { sin_cos_deg(row[column], s, c); }
};
struct GivenSinCos {
  using D = double;
  const double* row;
  const double* sines;
  const double* cosines;
  D value(uint32_t column) const noexcept { return row[column]; }
  void sin_cos(uint32_t column, D& s, D& c) const noexcept { s = sines[column], c = cosines[column]; }
};
struct TwoRows {
  using D = Lanes2;
  const double* a;
  const double* b;
  D value(uint32_t column) const noexcept { return {a[column], b[column]}; }
  void sin_cos(uint32_t column, D& s, D& c) const noexcept { sin_cos_deg2(value(column), s, c); }
};

// The one FK loop everything else uses, on one frame (double) or two (Lanes2). pos and rot have
// room for every node. With `nodes`, only the nodes it marks (a set holding every ancestor of
// its members) are computed.
template <typename Values, typename D = typename Values::D>
void pose_frame(const Skeleton& skeleton, const Values& values, std::array<D, 3>* pos, std::array<D, 9>* rot,
                const uint8_t* nodes = nullptr, PositionReading reading = PositionReading::replace) noexcept {
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
    std::array<D, 9>& r = rot[j];
    r = parent_rot;
    for (size_t k = 0; k < joint.channels.size(); ++k) {
      const ChannelType type = joint.channels[k];
      const uint32_t column = joint.first_channel + uint32_t(k);
      if (is_rotation(type)) {
        D sn, cs;
        values.sin_cos(column, sn, cs);
        post_rotate(r, channel_axis(type), sn, cs);
      } else {
        const size_t axis = static_cast<size_t>(channel_axis(type));
        t[axis] = add ? D(joint.offset[axis]) + values.value(column) : values.value(column);
      }
    }
    if (root) {
      pos[j] = t;
    } else {
      const std::array<D, 3>& pp = pos[joint.parent];
      const std::array<D, 9>& m = parent_rot;
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

Quat local_quaternion(const Joint& joint, const double* frame_row) {
  Quat q{0, 0, 0, 1};
  const double* v = frame_row + joint.first_channel;
  for (size_t k = 0; k < joint.channels.size(); ++k)
    if (is_rotation(joint.channels[k])) q = quat_multiply(q, axis_quaternion(channel_axis(joint.channels[k]), v[k]));
  return q;
}

Quat axis_quaternion(int axis, double degrees) {
  double s, c;
  sin_cos_deg(0.5 * degrees, s, c);
  Quat q{0, 0, 0, c};
  q[size_t(axis)] = s;
  return q;
}

Quat quat_multiply(const Quat& a, const Quat& b) noexcept {
  return {a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1],
          a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0],
          a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3],
          a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2]};
}

namespace {

// World positions into `out`, with a per-thread rotation scratch so that the encoder's
// per-frame calls allocate nothing after the first.
template <typename Values>
void positions_with_scratch(const Skeleton& skeleton, const Values& values, std::vector<Vec3>& out,
                            const uint8_t* nodes, PositionReading reading) {
  thread_local std::vector<Mat3> rotations;
  const size_t n = skeleton.joints.size();
  if (rotations.size() < n) rotations.resize(n);
  out.resize(n);
  pose_frame(skeleton, values, out.data(), rotations.data(), nodes, reading);
}

}  // namespace

void world_positions(const Skeleton& skeleton, const double* frame_row, std::vector<Vec3>& out,
                     PositionReading reading) {
  positions_with_scratch(skeleton, OneRow{frame_row}, out, nullptr, reading);
}

void world_positions(const Skeleton& skeleton, const double* frame_row, const uint8_t* nodes, std::vector<Vec3>& out,
                     PositionReading reading) {
  positions_with_scratch(skeleton, OneRow{frame_row}, out, nodes, reading);
}

void world_points(const Skeleton& skeleton, const double* row_a, const double* row_b, const uint8_t* nodes,
                  PositionReading reading, double distance, std::vector<Vec3>& out_a, std::vector<Vec3>& out_b) {
  thread_local std::vector<std::array<Lanes2, 9>> rotations;
  thread_local std::vector<std::array<Lanes2, 3>> positions;
  const size_t n = skeleton.joints.size();
  if (rotations.size() < n) rotations.resize(n), positions.resize(n);
  out_a.resize(4 * n), out_b.resize(4 * n);
  pose_frame(skeleton, TwoRows{row_a, row_b}, positions.data(), rotations.data(), nodes, reading);
  const Lanes2 d(distance);
  for (size_t j = 0; j < n; ++j) {
    if (nodes && !nodes[j]) continue;
    const std::array<Lanes2, 3>& p = positions[j];
    const std::array<Lanes2, 9>& r = rotations[j];
    Vec3* a = &out_a[4 * j];
    Vec3* b = &out_b[4 * j];
    for (int c = 0; c < 3; ++c) p[c].split(a[0][c], b[0][c]);
    if (distance > 0.0 && !skeleton.joints[j].end_site) {
      for (int axis = 0; axis < 3; ++axis)
        for (int c = 0; c < 3; ++c) (p[c] + d * r[3 * c + axis]).split(a[1 + axis][c], b[1 + axis][c]);
    } else {
      a[1] = a[2] = a[3] = a[0], b[1] = b[2] = b[3] = b[0];
    }
  }
}

void world_positions(const Skeleton& skeleton, const double* row_a, const double* row_b, const uint8_t* nodes,
                     std::vector<Vec3>& out_a, std::vector<Vec3>& out_b, PositionReading reading) {
  thread_local std::vector<std::array<Lanes2, 9>> rotations;
  thread_local std::vector<std::array<Lanes2, 3>> positions;
  const size_t n = skeleton.joints.size();
  if (rotations.size() < n) rotations.resize(n), positions.resize(n);
  out_a.resize(n), out_b.resize(n);
  pose_frame(skeleton, TwoRows{row_a, row_b}, positions.data(), rotations.data(), nodes, reading);
  for (size_t j = 0; j < n; ++j) {
    if (nodes && !nodes[j]) continue;
    for (int a = 0; a < 3; ++a) positions[j][a].split(out_a[j][a], out_b[j][a]);
  }
}

void world_positions(const Skeleton& skeleton, const double* frame_row, const double* sines, const double* cosines,
                     std::vector<Vec3>& out) {
  positions_with_scratch(skeleton, GivenSinCos{frame_row, sines, cosines}, out, nullptr, PositionReading::replace);
}

void world_pose(const Skeleton& skeleton, const double* frame_row, std::vector<Vec3>& positions,
                std::vector<Mat3>& rotations, PositionReading reading) {
  const size_t n = skeleton.joints.size();
  positions.resize(n);
  rotations.resize(n);
  pose_frame(skeleton, OneRow{frame_row}, positions.data(), rotations.data(), nullptr, reading);
}

std::vector<Vec3> world_positions_all(const Motion& motion, PositionReading reading) {
  const size_t n = motion.skeleton.joints.size();
  const size_t channels = motion.channel_count();
  const size_t frames = motion.frame_count;
  // A malformed Motion must not be read past its end.
  if (!channel_columns_consistent(motion.skeleton) || motion.values.size() < frames * channels)
    throw Error(ErrorKind::invalid_argument, "the motion's values do not fill frames x channels, or its channel "
                                             "columns lie outside a frame");
  std::vector<Vec3> out(frames * n);
  std::vector<Mat3> rotations(n);
  for (size_t f = 0; f < frames; ++f) {
    pose_frame(motion.skeleton, OneRow{motion.values.data() + f * channels}, out.data() + f * n, rotations.data(),
               nullptr, reading);
  }
  return out;
}

bool has_position_channels_below_root(const Skeleton& skeleton) noexcept {
  for (size_t j = 0; j < skeleton.joints.size(); ++j) {
    const Joint& joint = skeleton.joints[j];
    if (is_root(joint, j)) continue;
    for (ChannelType t : joint.channels)
      if (!is_rotation(t)) return true;
  }
  return false;
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
