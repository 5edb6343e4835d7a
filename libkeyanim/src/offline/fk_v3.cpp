// world_points of four frame rows in four AVX lanes (offline/fk_loop.h). Compiled with -mavx2 on
// x86-64 (libkeyanim/CMakeLists.txt) and called only where the CPU has it (fk.cpp); without
// FMA, and with -ffp-contract=off, so that each lane is the double arithmetic of fk.cpp. Nothing
// here but world_points_v3 has external linkage (no std::vector<Vec3> call, whose AVX copy the
// linker could pick for every caller): the outputs come sized.
#include "offline/fk_loop.h"

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace keyanim::offline {

#if defined(__AVX2__)
namespace {

struct Lanes4 {
  __m256d v;
  Lanes4() = default;
  explicit Lanes4(__m256d x) : v(x) {}
  explicit Lanes4(double x) : v(_mm256_set1_pd(x)) {}
  Lanes4(double a, double b, double c, double d) : v(_mm256_setr_pd(a, b, c, d)) {}
  void split(double* out) const { _mm256_storeu_pd(out, v); }
};
inline Lanes4 operator+(Lanes4 a, Lanes4 b) { return Lanes4(_mm256_add_pd(a.v, b.v)); }
inline Lanes4 operator-(Lanes4 a, Lanes4 b) { return Lanes4(_mm256_sub_pd(a.v, b.v)); }
inline Lanes4 operator*(Lanes4 a, Lanes4 b) { return Lanes4(_mm256_mul_pd(a.v, b.v)); }
inline Lanes4 operator/(Lanes4 a, Lanes4 b) { return Lanes4(_mm256_div_pd(a.v, b.v)); }
inline Lanes4 sqrt_of(Lanes4 a) { return Lanes4(_mm256_sqrt_pd(a.v)); }
inline Lanes4 max0(Lanes4 a) { return Lanes4(_mm256_max_pd(a.v, _mm256_setzero_pd())); }  // a > 0 ? a : 0

// sin_cos_deg of each lane, bit for bit (fk.cpp's sin_cos_deg2 on four lanes). Angles of 10^9
// degrees or more (or NaN) take the scalar path: below that the quadrant fits a 32-bit integer.
inline void sin_cos_deg4(Lanes4 deg, Lanes4& s, Lanes4& c) noexcept {
  const __m256d magnitude = _mm256_andnot_pd(_mm256_set1_pd(-0.0), deg.v);
  if (_mm256_movemask_pd(_mm256_cmp_pd(magnitude, _mm256_set1_pd(1e9), _CMP_LT_OQ)) != 15) {
    alignas(32) double d[4], sv[4], cv[4];
    _mm256_store_pd(d, deg.v);
    for (int i = 0; i < 4; ++i) sin_cos_deg(d[i], sv[i], cv[i]);
    s = Lanes4(_mm256_load_pd(sv)), c = Lanes4(_mm256_load_pd(cv));
    return;
  }
  const __m256d scaled = _mm256_mul_pd(deg.v, _mm256_set1_pd(1.0 / 90.0));
  const __m256d half = _mm256_blendv_pd(_mm256_set1_pd(-0.5), _mm256_set1_pd(0.5),
                                        _mm256_cmp_pd(scaled, _mm256_setzero_pd(), _CMP_GE_OQ));
  const __m128i q = _mm256_cvttpd_epi32(_mm256_add_pd(scaled, half));  // four int32, as the scalar int64
  const Lanes4 r(_mm256_mul_pd(_mm256_sub_pd(deg.v, _mm256_mul_pd(_mm256_cvtepi32_pd(q), _mm256_set1_pd(90.0))),
                               _mm256_set1_pd(kRadPerDeg)));
  Lanes4 sr, cr;
  kernel_sin_cos(r, sr, cr);
  // Per lane: swap for odd quadrants, negate s for quadrants 2 and 3, c for 1 and 2.
  const __m256i q64 = _mm256_cvtepi32_epi64(q);
  const __m256i one = _mm256_set1_epi64x(1), two = _mm256_set1_epi64x(2);
  const __m256d swap = _mm256_castsi256_pd(_mm256_cmpeq_epi64(_mm256_and_si256(q64, one), one));
  const __m256d sign = _mm256_set1_pd(-0.0);
  const __m256d neg_s = _mm256_and_pd(_mm256_castsi256_pd(_mm256_cmpeq_epi64(_mm256_and_si256(q64, two), two)), sign);
  const __m256d neg_c = _mm256_and_pd(
      _mm256_castsi256_pd(_mm256_cmpeq_epi64(_mm256_and_si256(_mm256_add_epi64(q64, one), two), two)), sign);
  s = Lanes4(_mm256_xor_pd(_mm256_blendv_pd(sr.v, cr.v, swap), neg_s));
  c = Lanes4(_mm256_xor_pd(_mm256_blendv_pd(cr.v, sr.v, swap), neg_c));
}

struct FourRows {
  using D = Lanes4;
  const double* const* rows;
  const QuatForms* quats = nullptr;
  D value(uint32_t column) const noexcept { return {rows[0][column], rows[1][column], rows[2][column], rows[3][column]}; }
  void sin_cos(uint32_t column, D& s, D& c) const noexcept { sin_cos_deg4(value(column), s, c); }
};

}  // namespace

namespace {

template <bool kBoth>
void points_v3(const Skeleton& skeleton, const double* const* rows, const uint8_t* nodes, PositionReading reading,
               double distance, Vec3* const* out, Vec3* const* out_add, const QuatForms* quats) {
  thread_local std::vector<std::array<Lanes4, 9>> rotations;
  thread_local std::vector<std::array<Lanes4, 3>> positions, positions_add;
  const size_t n = skeleton.joints.size();
  if (rotations.size() < n) rotations.resize(n), positions.resize(n);
  if (kBoth && positions_add.size() < n) positions_add.resize(n);
  pose_frame(skeleton, FourRows{rows, quats}, positions.data(), rotations.data(), nodes, reading,
             kBoth ? positions_add.data() : nullptr);
  const Lanes4 d(distance);
  alignas(32) double lanes[4];
  // Point k of node j, coordinate c, into the four outputs.
  auto put = [&](Vec3* const* to, Lanes4 x, size_t j, int k, int c) {
    _mm256_store_pd(lanes, x.v);
    for (int i = 0; i < 4; ++i) to[i][4 * j + size_t(k)][size_t(c)] = lanes[i];
  };
  auto points = [&](Vec3* const* to, const std::array<Lanes4, 3>& p, const std::array<Lanes4, 9>& r, size_t j) {
    for (int c = 0; c < 3; ++c) put(to, p[c], j, 0, c);
    if (distance > 0.0 && !skeleton.joints[j].end_site) {
      for (int axis = 0; axis < 3; ++axis)
        for (int c = 0; c < 3; ++c) put(to, p[c] + d * r[size_t(3 * c + axis)], j, 1 + axis, c);
    } else {
      for (int i = 0; i < 4; ++i) {
        Vec3* q = &to[i][4 * j];
        q[1] = q[2] = q[3] = q[0];
      }
    }
  };
  for (size_t j = 0; j < n; ++j) {
    if (nodes && !nodes[j]) continue;
    points(out, positions[j], rotations[j], j);
    if constexpr (kBoth) points(out_add, positions_add[j], rotations[j], j);
  }
}

}  // namespace

bool world_points_v3(const Skeleton& skeleton, const double* const* rows, const uint8_t* nodes,
                     PositionReading reading, double distance, Vec3* const* out, Vec3* const* out_add,
                     const QuatForms* quats) {
  if (out_add) points_v3<true>(skeleton, rows, nodes, reading, distance, out, out_add, quats);
  else points_v3<false>(skeleton, rows, nodes, reading, distance, out, nullptr, quats);
  return true;
}

#else

bool world_points_v3(const Skeleton&, const double* const*, const uint8_t*, PositionReading, double,
                     Vec3* const*, Vec3* const*, const QuatForms*) {
  return false;
}

#endif

}  // namespace keyanim::offline
