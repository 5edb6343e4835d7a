// Four binary32 lanes with the operators cardinal.h's building blocks use, so that the runtime
// evaluates 4 channels at once with exactly the scalar expressions. SSE2 is part of every
// x86-64 CPU, so no -march flag is needed; elsewhere a plain array stands in (the compiler may
// vectorize it). Every operation is one IEEE binary32 operation per lane, rounded to nearest,
// as the scalar code computes it: results are bit-identical to the scalar path.
#pragma once
#include <cstdint>
#include <cstring>

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
  void store(float* p) const { _mm_storeu_ps(p, v); }
};
inline F4 operator+(F4 a, F4 b) { return F4(_mm_add_ps(a.v, b.v)); }
inline F4 operator-(F4 a, F4 b) { return F4(_mm_sub_ps(a.v, b.v)); }
inline F4 operator*(F4 a, F4 b) { return F4(_mm_mul_ps(a.v, b.v)); }
inline F4 operator/(F4 a, F4 b) { return F4(_mm_div_ps(a.v, b.v)); }
// Lanes of `mask` all ones take a, all zeros take b.
inline F4 select(const uint32_t* mask, F4 a, F4 b) {
  const __m128 m = _mm_castsi128_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(mask)));
  return F4(_mm_or_ps(_mm_and_ps(m, a.v), _mm_andnot_ps(m, b.v)));
}
#else
struct F4 {
  float v[4];
  F4() = default;
  explicit F4(float x) { v[0] = v[1] = v[2] = v[3] = x; }
  static F4 load(const float* p) { F4 r; std::memcpy(r.v, p, sizeof r.v); return r; }
  void store(float* p) const { std::memcpy(p, v, sizeof v); }
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
inline F4 select(const uint32_t* mask, F4 a, F4 b) {
  F4 r;
  for (int i = 0; i < 4; ++i) {
    uint32_t x, y;
    std::memcpy(&x, &a.v[i], 4);
    std::memcpy(&y, &b.v[i], 4);
    const uint32_t z = (x & mask[i]) | (y & ~mask[i]);
    std::memcpy(&r.v[i], &z, 4);
  }
  return r;
}
#endif

}  // namespace keyanim::internal
