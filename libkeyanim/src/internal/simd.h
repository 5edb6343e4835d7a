// Four binary32 (F4) or int32 (I4) lanes with the operators cardinal.h's building blocks use,
// so that the runtime evaluates 4 channels at once with exactly the scalar expressions. SSE2
// is part of every x86-64 CPU, so no -march flag is needed; elsewhere plain arrays stand in
// (the compiler may vectorize them). Every arithmetic operation is one IEEE binary32
// operation per lane, rounded to nearest, as the scalar code computes it: results are
// bit-identical to the scalar path. Comparisons give lane masks (all ones or all zeros) as F4.
#pragma once
#include <cmath>
#include <cstdint>
#include <cstring>
#include <utility>

#if defined(__SSE2__) || defined(_M_X64)
#include <emmintrin.h>
#define KEYANIM_SSE2 1
#endif

namespace keyanim::internal {

#if KEYANIM_SSE2
struct F4 {
  __m128 v;
  F4() = default;
  explicit F4(__m128 x) : v(x) {}
  explicit F4(float x) : v(_mm_set1_ps(x)) {}
  static F4 load(const float* p) { return F4(_mm_loadu_ps(p)); }
  // Lanes from scalars, in registers (a vector load of four values just stored one by one
  // would wait for the stores: a store-forwarding stall).
  static F4 set(float a, float b, float c, float d) { return F4(_mm_setr_ps(a, b, c, d)); }
  static F4 load_mask(const uint32_t* p) { return F4(_mm_castsi128_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)))); }
  void store(float* p) const { _mm_storeu_ps(p, v); }
};
struct I4 {
  __m128i v;
  I4() = default;
  explicit I4(__m128i x) : v(x) {}
  static I4 load(const int32_t* p) { return I4(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p))); }
};
inline F4 operator+(F4 a, F4 b) { return F4(_mm_add_ps(a.v, b.v)); }
inline F4 operator-(F4 a, F4 b) { return F4(_mm_sub_ps(a.v, b.v)); }
inline F4 operator*(F4 a, F4 b) { return F4(_mm_mul_ps(a.v, b.v)); }
inline F4 operator/(F4 a, F4 b) { return F4(_mm_div_ps(a.v, b.v)); }
inline I4 operator-(I4 a, I4 b) { return I4(_mm_sub_epi32(a.v, b.v)); }
inline F4 to_float(I4 a) { return F4(_mm_cvtepi32_ps(a.v)); }  // round to nearest
inline F4 cmp_eq(F4 a, F4 b) { return F4(_mm_cmpeq_ps(a.v, b.v)); }
inline F4 cmp_ge(F4 a, F4 b) { return F4(_mm_cmpge_ps(a.v, b.v)); }
inline F4 cmp_not_gt(F4 a, F4 b) { return F4(_mm_cmpngt_ps(a.v, b.v)); }  // !(a > b)
inline F4 mask_or(F4 a, F4 b) { return F4(_mm_or_ps(a.v, b.v)); }
inline F4 sqrt_lanes(F4 a) { return F4(_mm_sqrt_ps(a.v)); }  // correctly rounded, as std::sqrt
inline F4 max0(F4 a) { return F4(_mm_max_ps(a.v, _mm_setzero_ps())); }  // a > 0 ? a : 0 (NaN: 0)
// Lanes of `mask` all ones take a, all zeros take b.
inline F4 select(F4 mask, F4 a, F4 b) { return F4(_mm_or_ps(_mm_and_ps(mask.v, a.v), _mm_andnot_ps(mask.v, b.v))); }
// Rows to columns: after the call a holds the first lane of a, b, c, d, and so on.
inline void transpose(F4& a, F4& b, F4& c, F4& d) { _MM_TRANSPOSE4_PS(a.v, b.v, c.v, d.v); }
// Bit i set when lane i of x is not in [lo, hi).
inline uint32_t outside(F4 x, F4 lo, F4 hi) {
  return static_cast<uint32_t>(_mm_movemask_ps(_mm_or_ps(_mm_cmpnle_ps(lo.v, x.v), _mm_cmpnlt_ps(x.v, hi.v))));
}
// Bit i set when lane i's sign bit is (a lane mask's: when the lane is all ones).
inline uint32_t sign_bits(F4 x) { return static_cast<uint32_t>(_mm_movemask_ps(x.v)); }
inline void transpose(I4& a, I4& b, I4& c, I4& d) {
  const __m128i t0 = _mm_unpacklo_epi32(a.v, b.v), t1 = _mm_unpacklo_epi32(c.v, d.v);
  const __m128i t2 = _mm_unpackhi_epi32(a.v, b.v), t3 = _mm_unpackhi_epi32(c.v, d.v);
  a.v = _mm_unpacklo_epi64(t0, t1), b.v = _mm_unpackhi_epi64(t0, t1);
  c.v = _mm_unpacklo_epi64(t2, t3), d.v = _mm_unpackhi_epi64(t2, t3);
}
#else
struct F4 {
  float v[4];
  F4() = default;
  explicit F4(float x) { v[0] = v[1] = v[2] = v[3] = x; }
  static F4 load(const float* p) { F4 r; std::memcpy(r.v, p, sizeof r.v); return r; }
  static F4 set(float a, float b, float c, float d) { F4 r; r.v[0] = a, r.v[1] = b, r.v[2] = c, r.v[3] = d; return r; }
  static F4 load_mask(const uint32_t* p) { F4 r; std::memcpy(r.v, p, sizeof r.v); return r; }
  void store(float* p) const { std::memcpy(p, v, sizeof v); }
};
struct I4 {
  int32_t v[4];
  static I4 load(const int32_t* p) { I4 r; std::memcpy(r.v, p, sizeof r.v); return r; }
};
#define KEYANIM_F4_OP(op)                                     \
  inline F4 operator op(F4 a, F4 b) {                         \
    F4 r;                                                     \
    for (int i = 0; i < 4; ++i) r.v[i] = a.v[i] op b.v[i];    \
    return r;                                                 \
  }
KEYANIM_F4_OP(+)
KEYANIM_F4_OP(-)
KEYANIM_F4_OP(*)
KEYANIM_F4_OP(/)
#undef KEYANIM_F4_OP
inline I4 operator-(I4 a, I4 b) { I4 r; for (int i = 0; i < 4; ++i) r.v[i] = a.v[i] - b.v[i]; return r; }
inline F4 sqrt_lanes(F4 a) { F4 r; for (int i = 0; i < 4; ++i) r.v[i] = std::sqrt(a.v[i]); return r; }
inline F4 max0(F4 a) { F4 r; for (int i = 0; i < 4; ++i) r.v[i] = a.v[i] > 0.0f ? a.v[i] : 0.0f; return r; }
inline F4 to_float(I4 a) { F4 r; for (int i = 0; i < 4; ++i) r.v[i] = static_cast<float>(a.v[i]); return r; }
inline F4 lane_mask(const bool* b) {
  F4 r;
  for (int i = 0; i < 4; ++i) { const uint32_t m = b[i] ? ~0u : 0u; std::memcpy(&r.v[i], &m, 4); }
  return r;
}
inline F4 cmp_eq(F4 a, F4 b) { bool m[4]; for (int i = 0; i < 4; ++i) m[i] = a.v[i] == b.v[i]; return lane_mask(m); }
inline F4 cmp_ge(F4 a, F4 b) { bool m[4]; for (int i = 0; i < 4; ++i) m[i] = a.v[i] >= b.v[i]; return lane_mask(m); }
inline F4 cmp_not_gt(F4 a, F4 b) { bool m[4]; for (int i = 0; i < 4; ++i) m[i] = !(a.v[i] > b.v[i]); return lane_mask(m); }
inline F4 select(F4 mask, F4 a, F4 b) {
  F4 r;
  for (int i = 0; i < 4; ++i) {
    uint32_t m, x, y;
    std::memcpy(&m, &mask.v[i], 4), std::memcpy(&x, &a.v[i], 4), std::memcpy(&y, &b.v[i], 4);
    const uint32_t z = (x & m) | (y & ~m);
    std::memcpy(&r.v[i], &z, 4);
  }
  return r;
}
inline F4 mask_or(F4 a, F4 b) { F4 ones; const uint32_t all = ~0u; for (auto& x : ones.v) std::memcpy(&x, &all, 4); return select(a, ones, b); }
inline uint32_t outside(F4 x, F4 lo, F4 hi) {
  uint32_t r = 0;
  for (int i = 0; i < 4; ++i) r |= uint32_t(!(lo.v[i] <= x.v[i] && x.v[i] < hi.v[i])) << i;
  return r;
}
inline uint32_t sign_bits(F4 x) {
  uint32_t r = 0;
  for (int i = 0; i < 4; ++i) {
    uint32_t b;
    std::memcpy(&b, &x.v[i], 4);
    r |= (b >> 31) << i;
  }
  return r;
}
template <class T>
inline void transpose(T& a, T& b, T& c, T& d) {
  T* r[4] = {&a, &b, &c, &d};
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) std::swap(r[i]->v[j], r[j]->v[i]);
}
#endif

// The integer vector of a float vector's lanes (F4: I4; simd8.h adds F8: I8), for code
// written once for both widths.
template <class V> struct IntLanes;
template <> struct IntLanes<F4> { using type = I4; };

}  // namespace keyanim::internal
