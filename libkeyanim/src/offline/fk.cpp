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

#include "internal/cpu.h"
#include "keyanim/offline/error.h"
#include "offline/fk_loop.h"

namespace keyanim::offline {
namespace {

constexpr Mat3 kIdentity{1, 0, 0, 0, 1, 0, 0, 0, 1};


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
inline Lanes2 operator/(Lanes2 a, Lanes2 b) { return Lanes2(_mm_div_pd(a.v, b.v)); }
inline Lanes2 sqrt_of(Lanes2 a) { return Lanes2(_mm_sqrt_pd(a.v)); }
inline Lanes2 max0(Lanes2 a) { return Lanes2(_mm_max_pd(a.v, _mm_setzero_pd())); }  // a > 0 ? a : 0, as max0(double)
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
inline Lanes2 operator/(Lanes2 a, Lanes2 b) { return {a.x[0] / b.x[0], a.x[1] / b.x[1]}; }
inline Lanes2 sqrt_of(Lanes2 a) { return {std::sqrt(a.x[0]), std::sqrt(a.x[1])}; }
inline Lanes2 max0(Lanes2 a) { return {max0(a.x[0]), max0(a.x[1])}; }
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

// Where pose_frame gets a channel's value and the sine and cosine of a rotation's.
struct OneRow {
  using D = double;
  const double* row;
  const QuatForms* quats = nullptr;
  D value(uint32_t column) const noexcept { return row[column]; }
  void sin_cos(uint32_t column, D& s, D& c) const noexcept { sin_cos_deg(row[column], s, c); }
};
struct GivenSinCos {
  using D = double;
  const double* row;
  const double* sines;
  const double* cosines;
  const QuatForms* quats = nullptr;
  D value(uint32_t column) const noexcept { return row[column]; }
  void sin_cos(uint32_t column, D& s, D& c) const noexcept { s = sines[column], c = cosines[column]; }
};
struct TwoRows {
  using D = Lanes2;
  const double* a;
  const double* b;
  const QuatForms* quats = nullptr;
  D value(uint32_t column) const noexcept { return {a[column], b[column]}; }
  void sin_cos(uint32_t column, D& s, D& c) const noexcept { sin_cos_deg2(value(column), s, c); }
};

}  // namespace

QuatForms::QuatForms(const Skeleton& skeleton, const std::vector<QuatNode>& nodes)
    : of_node(skeleton.joints.size(), -1) {
  for (size_t i = 0; i < nodes.size(); ++i) {
    const QuatNode& n = nodes[i];
    uint32_t first = 0;
    quaternion_capable(skeleton.joints[n.node], &first);
    of_node[n.node] = int32_t(i);
    double ref[4];
    reference_of(n, ref);
    reference.push_back({ref[0], ref[1], ref[2], ref[3]});
    node.push_back(n.node);
    column.push_back(skeleton.joints[n.node].first_channel + first);
  }
}

namespace {

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
                  PositionReading reading, double distance, std::vector<Vec3>& out_a, std::vector<Vec3>& out_b,
                  std::vector<Vec3>* add_a, std::vector<Vec3>* add_b, const QuatForms* quats) {
  thread_local std::vector<std::array<Lanes2, 9>> rotations;
  thread_local std::vector<std::array<Lanes2, 3>> positions, positions_add;
  const size_t n = skeleton.joints.size();
  const bool both = add_a && add_b;
  if (rotations.size() < n) rotations.resize(n), positions.resize(n);
  if (both && positions_add.size() < n) positions_add.resize(n);
  out_a.resize(4 * n), out_b.resize(4 * n);
  if (both) add_a->resize(4 * n), add_b->resize(4 * n);
  pose_frame(skeleton, TwoRows{row_a, row_b, quats}, positions.data(), rotations.data(), nodes, reading,
             both ? positions_add.data() : nullptr);
  const Lanes2 d(distance);
  auto points = [&](const std::array<Lanes2, 3>& p, const std::array<Lanes2, 9>& r, size_t j, Vec3* a, Vec3* b) {
    for (int c = 0; c < 3; ++c) p[c].split(a[0][c], b[0][c]);
    if (distance > 0.0 && !skeleton.joints[j].end_site) {
      for (int axis = 0; axis < 3; ++axis)
        for (int c = 0; c < 3; ++c) (p[c] + d * r[3 * c + axis]).split(a[1 + axis][c], b[1 + axis][c]);
    } else {
      a[1] = a[2] = a[3] = a[0], b[1] = b[2] = b[3] = b[0];
    }
  };
  for (size_t j = 0; j < n; ++j) {
    if (nodes && !nodes[j]) continue;
    points(positions[j], rotations[j], j, &out_a[4 * j], &out_b[4 * j]);
    if (both) points(positions_add[j], rotations[j], j, &(*add_a)[4 * j], &(*add_b)[4 * j]);
  }
}

void world_points(const Skeleton& skeleton, const std::array<const double*, 4>& rows, const uint8_t* nodes,
                  PositionReading reading, double distance, std::array<std::vector<Vec3>, 4>& out,
                  std::array<std::vector<Vec3>, 4>* out_add, const QuatForms* quats) {
  if (internal::cpu_level() == internal::CpuLevel::v3) {
    Vec3* points[4];
    Vec3* points_add[4];
    for (size_t i = 0; i < 4; ++i) out[i].resize(4 * skeleton.joints.size()), points[i] = out[i].data();
    if (out_add)
      for (size_t i = 0; i < 4; ++i) (*out_add)[i].resize(4 * skeleton.joints.size()), points_add[i] = (*out_add)[i].data();
    if (world_points_v3(skeleton, rows.data(), nodes, reading, distance, points, out_add ? points_add : nullptr, quats))
      return;
  }
  auto add = [&](size_t i) { return out_add ? &(*out_add)[i] : nullptr; };
  world_points(skeleton, rows[0], rows[1], nodes, reading, distance, out[0], out[1], add(0), add(1), quats);
  world_points(skeleton, rows[2], rows[3], nodes, reading, distance, out[2], out[3], add(2), add(3), quats);
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
                std::vector<Mat3>& rotations, PositionReading reading, const QuatForms* quats) {
  const size_t n = skeleton.joints.size();
  positions.resize(n);
  rotations.resize(n);
  pose_frame(skeleton, OneRow{frame_row, quats}, positions.data(), rotations.data(), nullptr, reading);
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
