// Sine and cosine of half an angle given in degrees, for Euler-to-quaternion conversion: four
// angles at a time (F4: SSE2), eight (F8: the AVX2 copies), and a scalar twin that performs the same binary32 operations
// (so both give identical results). Accurate to about 1 ulp for the angles motion capture
// holds (|angle| < 10^6 degrees): the angle is reduced by multiples of 90 degrees exactly
// before it is converted to radians, and the polynomials are Cephes' sinf/cosf on [-pi/4, pi/4].
#pragma once
#include <cmath>
#include <cstdint>

#include "internal/simd.h"
#include "internal/simd8.h"

namespace keyanim::internal {

inline constexpr float kRadPerDeg = 0.017453292519943295f;

// Scalar: s = sin(deg / 2), c = cos(deg / 2).
inline void half_sincos_deg(float deg, float& s, float& c) noexcept {
  const float h = deg * 0.5f;
  const float r = std::nearbyint(h * (1.0f / 90.0f));  // quadrant, round to nearest even
  // As the SSE2 twin's cvtps2dq: outside int32's range (|angle| > 3.9e11 degrees) or NaN, the
  // quadrant is INT32_MIN, and k is that, so that both paths give the same (meaningless) bits
  // without an out-of-range conversion (undefined behaviour; fuzz_c_api found it).
  const int32_t q = r >= -2147483648.0f && r < 2147483648.0f ? static_cast<int32_t>(r) : INT32_MIN;
  const float k = static_cast<float>(q);                // = r inside the range
  const float x = (h - k * 90.0f) * kRadPerDeg;         // h - 90k is exact (Sterbenz)
  const float z = x * x;
  const float sp = ((-1.9515295891e-4f * z + 8.3321608736e-3f) * z - 1.6666654611e-1f) * z * x + x;
  const float cp = ((2.443315711809948e-5f * z - 1.388731625493765e-3f) * z + 4.166664568298827e-2f) * z * z -
                   0.5f * z + 1.0f;
  const float a = (q & 1) ? cp : sp;  // sin of the reduced angle's quadrant
  const float b = (q & 1) ? sp : cp;
  s = (q & 2) ? -a : a;
  c = ((q + 1) & 2) ? -b : b;
}

#if KEYANIM_SSE2
// Four angles at once: the scalar twin's operations lane by lane.
inline void half_sincos_deg(F4 deg, F4& s, F4& c) noexcept {
  const __m128 half = _mm_set1_ps(0.5f);
  const __m128i one = _mm_set1_epi32(1), two = _mm_set1_epi32(2);
  const __m128 sign = _mm_set1_ps(-0.0f);
  const __m128 h = _mm_mul_ps(deg.v, half);
  const __m128i q = _mm_cvtps_epi32(_mm_mul_ps(h, _mm_set1_ps(1.0f / 90.0f)));  // round to nearest even (MXCSR default)
  const __m128 k = _mm_cvtepi32_ps(q);
  const __m128 x = _mm_mul_ps(_mm_sub_ps(h, _mm_mul_ps(k, _mm_set1_ps(90.0f))), _mm_set1_ps(kRadPerDeg));
  const __m128 z = _mm_mul_ps(x, x);
  __m128 sp = _mm_add_ps(_mm_mul_ps(_mm_set1_ps(-1.9515295891e-4f), z), _mm_set1_ps(8.3321608736e-3f));
  sp = _mm_sub_ps(_mm_mul_ps(sp, z), _mm_set1_ps(1.6666654611e-1f));
  sp = _mm_add_ps(_mm_mul_ps(_mm_mul_ps(sp, z), x), x);
  __m128 cp = _mm_sub_ps(_mm_mul_ps(_mm_set1_ps(2.443315711809948e-5f), z), _mm_set1_ps(1.388731625493765e-3f));
  cp = _mm_add_ps(_mm_mul_ps(cp, z), _mm_set1_ps(4.166664568298827e-2f));
  cp = _mm_add_ps(_mm_sub_ps(_mm_mul_ps(_mm_mul_ps(cp, z), z), _mm_mul_ps(half, z)), _mm_set1_ps(1.0f));
  const __m128 swap = _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(q, one), one));
  const __m128 a = _mm_or_ps(_mm_and_ps(swap, cp), _mm_andnot_ps(swap, sp));
  const __m128 b = _mm_or_ps(_mm_and_ps(swap, sp), _mm_andnot_ps(swap, cp));
  const __m128 sa = _mm_and_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(q, two), two)), sign);
  const __m128 sb = _mm_and_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(_mm_add_epi32(q, one), two), two)), sign);
  s = F4(_mm_xor_ps(a, sa));
  c = F4(_mm_xor_ps(b, sb));
}
#else
inline void half_sincos_deg(F4 deg, F4& s, F4& c) noexcept {
  for (int i = 0; i < 4; ++i) half_sincos_deg(deg.v[i], s.v[i], c.v[i]);
}
#endif

#if KEYANIM_WIDE_LANES
// cvtps2dq (F4's quadrant) in generic vector code: round to nearest even of |x| by adding and
// subtracting 2^23 (exact below 2^23; from there on every binary32 is an integer), the sign
// put back, and INT32_MIN where x is outside int32's range or NaN, as cvtps2dq gives.
KEYANIM_INLINE inline V8i round_to_int32(V8f x) noexcept {
  const V8i sign_bit = I8::splat(INT32_MIN).v;
  const V8f two23 = F8(8388608.0f).v;
  const V8f ax = V8f(V8i(x) & ~sign_bit);
  const V8i small = ax < two23;
  const V8f rounded = V8f(V8i((ax + two23) - two23) | (V8i(x) & sign_bit));
  const V8f r = V8f((small & V8i(rounded)) | (~small & V8i(x)));
  const V8i in_range = (r >= F8(-2147483648.0f).v) & (r < F8(2147483648.0f).v);
  const V8i q = __builtin_convertvector(V8f(in_range & V8i(r)), V8i);  // in range: exact (r is whole)
  return (in_range & q) | (~in_range & sign_bit);
}

// Eight angles at once: the F4 twin's operations, in its order, lane by lane.
KEYANIM_INLINE inline void half_sincos_deg(F8 deg, F8& s, F8& c) noexcept {
  const V8i one = I8::splat(1).v, two = I8::splat(2).v, sign = I8::splat(INT32_MIN).v;
  const V8f h = deg.v * F8(0.5f).v;
  const V8i q = round_to_int32(h * F8(1.0f / 90.0f).v);
  const V8f k = __builtin_convertvector(q, V8f);
  const V8f x = (h - k * F8(90.0f).v) * F8(kRadPerDeg).v;
  const V8f z = x * x;
  V8f sp = F8(-1.9515295891e-4f).v * z + F8(8.3321608736e-3f).v;
  sp = sp * z - F8(1.6666654611e-1f).v;
  sp = sp * z * x + x;
  V8f cp = F8(2.443315711809948e-5f).v * z - F8(1.388731625493765e-3f).v;
  cp = cp * z + F8(4.166664568298827e-2f).v;
  cp = (cp * z * z - F8(0.5f).v * z) + F8(1.0f).v;
  const V8i swap = (q & one) == one;
  const V8i a = (swap & V8i(cp)) | (~swap & V8i(sp));
  const V8i b = (swap & V8i(sp)) | (~swap & V8i(cp));
  s = F8(V8f(a ^ (((q & two) == two) & sign)));
  c = F8(V8f(b ^ ((((q + one) & two) == two) & sign)));
}
#endif

}  // namespace keyanim::internal
