// Reading four records at once at the v3 level (internal/cpu.h: AVX2, BMI): read_window and
// dequantize4 of image.h and sampler.cpp for four block curves, one curve per 64-bit lane, so
// that the sampler's first pass costs about a third of the instructions of four scalar reads.
// Only the usual records take this path (values of at most 14 bits, context frames of at most
// 12 bits where the window needs them, |q_base + Base| below 2^50); for any other the caller
// reads the four scalar. Every result is an integer operation or the same binary64 product and
// rounding to binary32 as dequantize(): bit-identical to the scalar reads (tests/scalar, and
// every corpus clip against eval_channel).
#pragma once
#include <cstdint>

#include "internal/cpu.h"
#include "runtime/image.h"

// (A build for a level with popcnt but without AVX2 has no v3 copy of its own: internal/cpu.h.)
#if defined(__x86_64__) && (!defined(__POPCNT__) || defined(__AVX2__))
#include <immintrin.h>
#define KEYANIM_RECORDS_V3 1

namespace keyanim::internal::v3 {

// Index of the highest set bit of each lane (lanes that are 0 give garbage, for the caller to
// discard): the exponent of the lane's upper or lower half converted exactly to binary64
// (x | 2^52's bits, minus 2^52, is x for x < 2^32).
KEYANIM_V3_TARGET KEYANIM_INLINE inline __m256i top_bit4(__m256i x) noexcept {
  const __m256i magic = _mm256_set1_epi64x(0x4330000000000000);
  const __m256i hi = _mm256_srli_epi64(x, 32);
  const __m256i use_hi = _mm256_cmpgt_epi64(hi, _mm256_setzero_si256());
  const __m256i half = _mm256_blendv_epi8(_mm256_and_si256(x, _mm256_set1_epi64x(0xFFFFFFFF)), hi, use_hi);
  const __m256d d = _mm256_sub_pd(_mm256_castsi256_pd(_mm256_or_si256(half, magic)), _mm256_castsi256_pd(magic));
  const __m256i log2 = _mm256_sub_epi64(_mm256_srli_epi64(_mm256_castpd_si256(d), 52), _mm256_set1_epi64x(1023));
  return _mm256_add_epi64(log2, _mm256_and_si256(use_hi, _mm256_set1_epi64x(32)));
}
// Index of the lowest set bit: the highest of x & -x.
KEYANIM_V3_TARGET KEYANIM_INLINE inline __m256i low_bit4(__m256i x) noexcept {
  return top_bit4(_mm256_and_si256(x, _mm256_sub_epi64(_mm256_setzero_si256(), x)));
}
// Set bits per lane: a table of the 16 nibbles, summed per 64-bit lane.
KEYANIM_V3_TARGET KEYANIM_INLINE inline __m256i popcount4(__m256i x) noexcept {
  const __m256i table = _mm256_setr_epi8(0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4, 0, 1, 1, 2, 1, 2, 2, 3, 1, 2,
                                         2, 3, 2, 3, 3, 4);
  const __m256i nibble = _mm256_set1_epi8(0x0F);
  const __m256i lo = _mm256_shuffle_epi8(table, _mm256_and_si256(x, nibble));
  const __m256i hi = _mm256_shuffle_epi8(table, _mm256_and_si256(_mm256_srli_epi16(x, 4), nibble));
  return _mm256_sad_epu8(_mm256_add_epi8(lo, hi), _mm256_setzero_si256());
}
KEYANIM_V3_TARGET KEYANIM_INLINE inline __m256i unzigzag4(__m256i u) noexcept {
  const __m256i sign = _mm256_sub_epi64(_mm256_setzero_si256(), _mm256_and_si256(u, _mm256_set1_epi64x(1)));
  return _mm256_xor_si256(_mm256_srli_epi64(u, 1), sign);
}
KEYANIM_V3_TARGET KEYANIM_INLINE inline __m256i gather8(const uint8_t* base, __m256i at) noexcept {
  return _mm256_i64gather_epi64(reinterpret_cast<const long long*>(base), at, 1);
}
// (1 << n) - 1 per lane (n < 64).
KEYANIM_V3_TARGET KEYANIM_INLINE inline __m256i low_ones4(__m256i n) noexcept {
  return _mm256_sub_epi64(_mm256_sllv_epi64(_mm256_set1_epi64x(1), n), _mm256_set1_epi64x(1));
}
// The low 32 bits of each lane, as four int32.
KEYANIM_V3_TARGET KEYANIM_INLINE inline __m128i narrow4(__m256i x) noexcept {
  return _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(x, _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7)));
}

// The windows of curves first .. first + 3 (block curves) at the position whose frames_upto is
// `upto`, in the block whose records start at payload + offsets[first + l]: frame r (key j-1+r,
// relative to the block) of lane l into frames[r * stride + l], its value into values[...].
// False, with nothing written, when a record is not one this path reads.
KEYANIM_V3_TARGET KEYANIM_INLINE inline bool read_windows4(const uint8_t* payload, const uint32_t* offsets,
                                                           const Curve* curves, uint32_t first, uint64_t upto,
                                                           int32_t* frames, float* values, size_t stride) noexcept {
  const __m256i zero = _mm256_setzero_si256();
  const __m256i off = _mm256_cvtepu32_epi64(_mm_loadu_si128(reinterpret_cast<const __m128i*>(offsets + first)));
  const __m256i mask = gather8(payload, off);
  const __m256i header = gather8(payload + 8, off);  // Value_Bits, Context_Bits, 48 bits of Context
  const __m256i vw = _mm256_and_si256(header, _mm256_set1_epi64x(0xFF));
  const __m256i kw = _mm256_and_si256(_mm256_srli_epi64(header, 8), _mm256_set1_epi64x(0xFF));
  // The curves' q_base, step and base_bits (Curve: 24 bytes).
  const uint8_t* facts = reinterpret_cast<const uint8_t*>(curves + first);
  const __m256i at_curve = _mm256_setr_epi64x(0, 24, 48, 72);
  const __m256i q_base = gather8(facts, at_curve);
  const __m256d step = _mm256_castsi256_pd(gather8(facts + 8, at_curve));
  const __m256i base_bits = _mm256_and_si256(gather8(facts + 16, at_curve), _mm256_set1_epi64x(0xFFFFFFFF));

  const __m256i upto4 = _mm256_set1_epi64x(static_cast<int64_t>(upto));
  const __m256i below = _mm256_and_si256(mask, upto4), above = _mm256_andnot_si256(upto4, mask);
  const __m256i top = top_bit4(_mm256_or_si256(below, _mm256_set1_epi64x(1)));
  const __m256i below_rest = _mm256_andnot_si256(_mm256_sllv_epi64(_mm256_set1_epi64x(1), top), below);
  const __m256i above_rest = _mm256_and_si256(above, _mm256_sub_epi64(above, _mm256_set1_epi64x(1)));
  __m256i f0 = top_bit4(below_rest), f1 = top, f2 = low_bit4(above), f3 = low_bit4(above_rest);
  const __m256i no_below_rest = _mm256_cmpeq_epi64(below_rest, zero), no_above_rest = _mm256_cmpeq_epi64(above_rest, zero);
  const __m256i context = _mm256_or_si256(no_below_rest, no_above_rest);  // lanes that need context keys
  __m256i refuse = _mm256_cmpgt_epi64(vw, _mm256_set1_epi64x(14));
  if (!_mm256_testz_si256(context, context)) {
    refuse = _mm256_or_si256(refuse, _mm256_and_si256(context, _mm256_cmpgt_epi64(kw, _mm256_set1_epi64x(12))));
    const __m256i ctx = _mm256_srli_epi64(header, 16), m = low_ones4(kw);
    const __m256i c0 = unzigzag4(_mm256_and_si256(ctx, m));
    const __m256i c1 = unzigzag4(_mm256_and_si256(_mm256_srlv_epi64(ctx, kw), m));
    const __m256i kw2 = _mm256_add_epi64(kw, kw), block = _mm256_set1_epi64x(kBlockFrames);
    const __m256i c2 = _mm256_add_epi64(unzigzag4(_mm256_and_si256(_mm256_srlv_epi64(ctx, kw2), m)), block);
    const __m256i c3 = _mm256_add_epi64(
        unzigzag4(_mm256_and_si256(_mm256_srlv_epi64(ctx, _mm256_add_epi64(kw2, kw)), m)), block);
    const __m256i no_below = _mm256_cmpeq_epi64(below, zero), no_above = _mm256_cmpeq_epi64(above, zero);
    f0 = _mm256_blendv_epi8(f0, _mm256_blendv_epi8(c1, c0, no_below), no_below_rest);
    f1 = _mm256_blendv_epi8(f1, c1, no_below);
    f2 = _mm256_blendv_epi8(f2, c2, no_above);
    f3 = _mm256_blendv_epi8(f3, _mm256_blendv_epi8(c2, c3, no_above), no_above_rest);
  }
  // Base (base_bits wide at bit 80 + 4 kw), and the four values from key j-1's (image.h).
  const __m256i base_at = _mm256_add_epi64(_mm256_set1_epi64x(kRecordBitsAt), _mm256_slli_epi64(kw, 2));
  const __m256i base = _mm256_and_si256(
      _mm256_srlv_epi64(gather8(payload, _mm256_add_epi64(off, _mm256_srli_epi64(base_at, 3))),
                        _mm256_and_si256(base_at, _mm256_set1_epi64x(7))),
      low_ones4(base_bits));
  const __m256i low = _mm256_add_epi64(q_base, base);
  const __m256i limit = _mm256_set1_epi64x(int64_t(1) << 50);
  refuse = _mm256_or_si256(refuse, _mm256_or_si256(_mm256_cmpgt_epi64(low, limit),
                                                   _mm256_cmpgt_epi64(_mm256_sub_epi64(zero, limit), low)));
  if (!_mm256_testz_si256(refuse, refuse)) return false;
  const __m256i at = _mm256_add_epi64(_mm256_add_epi64(base_at, base_bits), _mm256_mul_epu32(popcount4(below), vw));
  const __m256i word = _mm256_srlv_epi64(gather8(payload, _mm256_add_epi64(off, _mm256_srli_epi64(at, 3))),
                                         _mm256_and_si256(at, _mm256_set1_epi64x(7)));
  const __m256i m = low_ones4(vw);
  // q = low + value, below 2^51 in magnitude: adding 1.5 * 2^52's bits gives the binary64
  // 1.5 * 2^52 + q exactly, and subtracting 1.5 * 2^52 gives q.
  const __m256i magic = _mm256_set1_epi64x(0x4338000000000000);
  __m256i shift = zero;
  for (int r = 0; r < 4; ++r, shift = _mm256_add_epi64(shift, vw)) {
    const __m256i q = _mm256_add_epi64(low, _mm256_and_si256(_mm256_srlv_epi64(word, shift), m));
    const __m256d d = _mm256_sub_pd(_mm256_castsi256_pd(_mm256_add_epi64(q, magic)), _mm256_castsi256_pd(magic));
    _mm_storeu_ps(values + r * stride, _mm256_cvtpd_ps(_mm256_mul_pd(d, step)));
  }
  const __m256i f[4] = {f0, f1, f2, f3};
  for (int r = 0; r < 4; ++r) _mm_storeu_si128(reinterpret_cast<__m128i*>(frames + r * stride), narrow4(f[r]));
  return true;
}

}  // namespace keyanim::internal::v3
#else
#define KEYANIM_RECORDS_V3 0
#endif
