// Eight binary32 (F8) or int32 (I8) lanes with the operators of simd.h's F4, for the copy of
// the sampler compiled for the v3 level (internal/cpu.h: AVX2), which then evaluates 8 curves
// per instruction instead of 4. They are GCC/Clang vector extensions rather than AVX
// intrinsics: generic vector code compiles in any function (in 256-bit registers where AVX is
// enabled, as two 128-bit halves elsewhere), so these helpers need no target attribute and
// inline into the v3 copy. Every operation is one IEEE binary32 operation per lane, rounded to
// nearest, and the comparisons are F4's (false on NaN, except not-greater): results are
// bit-identical to F4's and to the scalar path (tests/scalar).
#pragma once
#include <cstdint>
#include <cstring>

#include "internal/cpu.h"
#include "internal/simd.h"

#if KEYANIM_SSE2
#define KEYANIM_WIDE_LANES 1

namespace keyanim::internal {

using V8f = float __attribute__((vector_size(32)));
using V8i = int32_t __attribute__((vector_size(32)));
using V4i = int32_t __attribute__((vector_size(16)));

struct F8 {
  V8f v;
  F8() = default;
  KEYANIM_INLINE explicit F8(const V8f& x) : v(x) {}
  KEYANIM_INLINE explicit F8(float x) : v(V8f{x, x, x, x, x, x, x, x}) {}
  KEYANIM_INLINE static F8 load(const float* p) {
    F8 r;
    std::memcpy(&r.v, p, sizeof r.v);
    return r;
  }
  KEYANIM_INLINE static F8 load_mask(const uint32_t* p) {
    F8 r;
    std::memcpy(&r.v, p, sizeof r.v);
    return r;
  }
  // Lanes 0-3 from lo, 4-7 from hi.
  KEYANIM_INLINE static F8 join(F4 lo, F4 hi) { return F8(__builtin_shufflevector(lo.v, hi.v, 0, 1, 2, 3, 4, 5, 6, 7)); }
  KEYANIM_INLINE void store(float* p) const { std::memcpy(p, &v, sizeof v); }
  KEYANIM_INLINE F4 low() const { return F4(__builtin_shufflevector(v, v, 0, 1, 2, 3)); }
  KEYANIM_INLINE F4 high() const { return F4(__builtin_shufflevector(v, v, 4, 5, 6, 7)); }
};

struct I8 {
  V8i v;
  KEYANIM_INLINE static I8 splat(int32_t x) { return I8{V8i{x, x, x, x, x, x, x, x}}; }
  KEYANIM_INLINE static I8 join(I4 lo, I4 hi) {
    return I8{__builtin_shufflevector(V4i(lo.v), V4i(hi.v), 0, 1, 2, 3, 4, 5, 6, 7)};
  }
};

KEYANIM_INLINE inline F8 operator+(F8 a, F8 b) { return F8(a.v + b.v); }
KEYANIM_INLINE inline F8 operator-(F8 a, F8 b) { return F8(a.v - b.v); }
KEYANIM_INLINE inline F8 operator*(F8 a, F8 b) { return F8(a.v * b.v); }
KEYANIM_INLINE inline F8 operator/(F8 a, F8 b) { return F8(a.v / b.v); }
KEYANIM_INLINE inline I8 operator-(I8 a, I8 b) { return I8{a.v - b.v}; }
KEYANIM_INLINE inline F8 to_float(I8 a) { return F8(__builtin_convertvector(a.v, V8f)); }  // round to nearest
// A comparison's lanes are all ones or all zeros (int32 -1 or 0), kept as F8 bits as F4 keeps them.
KEYANIM_INLINE inline F8 lane_mask(V8i m) { return F8(V8f(m)); }
KEYANIM_INLINE inline F8 cmp_eq(F8 a, F8 b) { return lane_mask(a.v == b.v); }
KEYANIM_INLINE inline F8 cmp_ge(F8 a, F8 b) { return lane_mask(a.v >= b.v); }
KEYANIM_INLINE inline F8 cmp_not_gt(F8 a, F8 b) { return lane_mask(~(a.v > b.v)); }  // !(a > b): true on NaN
KEYANIM_INLINE inline F8 mask_or(F8 a, F8 b) { return lane_mask(V8i(a.v) | V8i(b.v)); }
// Lanes of `mask` all ones take a, all zeros take b.
KEYANIM_INLINE inline F8 select(F8 mask, F8 a, F8 b) {
  const V8i m = V8i(mask.v);
  return lane_mask((m & V8i(a.v)) | (~m & V8i(b.v)));
}
// Each half as F4's (one correctly rounded square root per lane).
KEYANIM_INLINE inline F8 sqrt_lanes(F8 a) { return F8::join(sqrt_lanes(a.low()), sqrt_lanes(a.high())); }
KEYANIM_INLINE inline F8 max0(F8 a) { return select(lane_mask(a.v > V8f{}), a, F8(0.0f)); }  // a > 0 ? a : 0
template <> struct IntLanes<F8> { using type = I8; };

}  // namespace keyanim::internal
#else
#define KEYANIM_WIDE_LANES 0
#endif
