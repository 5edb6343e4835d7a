// The scalar pass of sampling (sampler.cpp, quat_tracks.cpp, key_stream.h): where a position
// falls, a block's record read into its keys' frames and dequantized values, a list's keys
// around a position. Internal to the runtime;
// everything here has internal linkage, so that each file's copies compiled for a CPU level
// (internal/cpu.h) stay its own.
#pragma once
#include <algorithm>
#include <cstdint>
#include <cstring>

#include "internal/cpu.h"
#include "internal/simd.h"
#include "internal/simd8.h"
#include "runtime/image.h"


namespace keyanim::internal {
namespace {

// Where position f falls: its block, and f relative to the block's start (exact: see below).
struct Position {
  float f;    // the position
  float rel;  // f - block start, exact (Sterbenz: the start is 0, or >= 64 and > f / 2)
  uint32_t block, t;
};

KEYANIM_INLINE inline Position position(const Image& img, float f) noexcept {
  Position p;
  p.f = f;
  if (img.block_count == 0) return {f, f, 0, 0};
  // Outside the clip every curve is clamped, whatever block is read; NaN never reaches here.
  const float end = static_cast<float>((img.block_count << kBlockShift) - 1);
  const float clamped = std::min(std::max(f, 0.0f), end);
  p.block = static_cast<uint32_t>(clamped) >> kBlockShift;
  const float start = static_cast<float>(p.block << kBlockShift);
  p.t = std::min(static_cast<uint32_t>(clamped - start), kBlockFrames - 1);
  p.rel = f - start;
  return p;
}

// q = q_base + base + value, dequantized as Appendix A says (binary64 product, one rounding).
// double(q_base + base) + double(value) is exact (|q| <= 2^53), so two lanes at a time with
// SSE2 give the very same values.
#if KEYANIM_SSE2
[[gnu::always_inline]] inline void dequantize4(__m128i v, int64_t low, double step, float* out) noexcept {
  const __m128d lowd = _mm_set1_pd(static_cast<double>(low)), s = _mm_set1_pd(step);
  const __m128d a = _mm_mul_pd(_mm_add_pd(_mm_cvtepi32_pd(v), lowd), s);
  const __m128d b = _mm_mul_pd(_mm_add_pd(_mm_cvtepi32_pd(_mm_unpackhi_epi64(v, v)), lowd), s);
  _mm_storeu_ps(out, _mm_movelh_ps(_mm_cvtpd_ps(a), _mm_cvtpd_ps(b)));
}
#endif

[[gnu::always_inline]] inline void dequantize4(const uint8_t* rec, const Window& w, const Curve& cv, float* out) noexcept {
  const int64_t low = cv.q_base + static_cast<int64_t>(w.base);
  [[maybe_unused]] const uint32_t vw = w.value_bits;  // unused without SSE2
#if KEYANIM_SSE2
  if (vw <= 14) {  // the usual widths: the four values in one load, split in two 64-bit lanes
    uint64_t x;
    std::memcpy(&x, rec + (w.at >> 3), 8);
    x >>= w.at & 7;  // 4 vw + 7 <= 63 bits
    const __m128i m = _mm_set1_epi64x(static_cast<int64_t>((uint64_t(1) << vw) - 1));
    const __m128i v = _mm_set_epi64x(static_cast<int64_t>(x >> (2 * vw)), static_cast<int64_t>(x));  // v0 v1 | v2 v3
    const __m128i even = _mm_and_si128(v, m);                                        // v0, v2
    const __m128i odd = _mm_and_si128(_mm_srl_epi64(v, _mm_cvtsi32_si128(static_cast<int>(vw))), m);  // v1, v3
    dequantize4(_mm_or_si128(even, _mm_slli_epi64(odd, 32)), low, cv.step, out);
    return;
  }
#endif
  uint64_t value[4];
  window_values(rec, w, value);
#if KEYANIM_SSE2
  if (vw <= 31) {
    dequantize4(_mm_set_epi32(static_cast<int32_t>(value[3]), static_cast<int32_t>(value[2]),
                              static_cast<int32_t>(value[1]), static_cast<int32_t>(value[0])),
                low, cv.step, out);
    return;
  }
#endif
  for (int k = 0; k < 4; ++k) out[k] = dequantize(low + static_cast<int64_t>(value[k]), cv.step);
}

#if KEYANIM_WIDE_LANES
// The AVX2 copies' usual case (vw <= 14, SSE2 above): the four values split by variable shifts
// of one load in four 64-bit lanes, made doubles exactly (the bits of 2^52 + v, less 2^52),
// then (low + v) x step rounded to binary32: the same operations, so the same bits, as above.
// GCC vector extensions, as simd8.h's (no target attribute needed; vpsrlvq and 256-bit
// doubles in the v3 copy).
using V4u64 = uint64_t __attribute__((vector_size(32)));
using V4f64 = double __attribute__((vector_size(32)));
using V4f32 = float __attribute__((vector_size(16)));
[[gnu::always_inline]] inline void dequantize4_wide(const uint8_t* rec, uint64_t at, uint32_t vw, int64_t low,
                                                    double step, float* out) noexcept {
  uint64_t x;
  std::memcpy(&x, rec + (at >> 3), 8);
  x >>= at & 7;  // 4 vw + 7 <= 63 bits
  const uint64_t w = vw, mask = (uint64_t(1) << vw) - 1;
  const V4u64 v = (V4u64{x, x, x, x} >> V4u64{0, w, 2 * w, 3 * w}) & mask;
  const uint64_t two52_bits = 0x4330000000000000u;  // 2^52
  const V4f64 d = (V4f64)(v | two52_bits) - 4503599627370496.0;  // a vector cast keeps the bits
  const V4f32 f = __builtin_convertvector((d + static_cast<double>(low)) * step, V4f32);
  std::memcpy(out, &f, sizeof f);
}
#endif

// dequantize4 in the AVX2 copies (kWide) where it can, else as above.
template <bool kWide>
[[gnu::always_inline]] inline void dequantize4_at(const uint8_t* rec, const Window& w, const Curve& cv,
                                                  float* out) noexcept {
#if KEYANIM_WIDE_LANES
  if constexpr (kWide) {
    if (w.value_bits <= 14) {
      dequantize4_wide(rec, w.at, w.value_bits, cv.q_base + static_cast<int64_t>(w.base), cv.step, out);
      return;
    }
  }
#endif
  dequantize4(rec, w, cv, out);
}

// The image's arrays for one block, loaded once per pose rather than once per curve.
struct BlockView {
  const uint8_t* payload;
  const uint32_t* offsets;  // the block's row of record offsets, one per track
  const Curve* curves;
  uint64_t upto;            // frames_upto(t): the block's keys at or before the position
};

KEYANIM_INLINE inline BlockView block_view(const Image& img, const Position& at) noexcept {
  return {img.payload.data(), img.record_offset.data() + size_t(at.block) * img.block_tracks, img.curves.data(),
          frames_upto(at.t)};
}

// Quaternion track `track`'s curves x, y, z (their indices curve[0..2]): one search of the
// shared mask gives every curve's window (their key frames are the same), into frame[0..4);
// their Bases, then their Values, follow one another: curve k's four values into values[k]
// (skipped where null). Straight-line code for the three, so that their fields stay in
// registers.
template <bool kPopcnt, bool kWide = false>
[[gnu::always_inline]] inline void read_track(const BlockView& v, uint32_t track, const uint32_t (&curve)[3],
                                              int32_t* frame, float* const (&values)[3]) noexcept {
  const uint8_t* rec = v.payload + v.offsets[track];
  uint64_t mask;
  std::memcpy(&mask, rec, 8);
  const uint32_t kw = rec[kTrackRecordBitsAt / 8 - 1];
  const uint32_t count = window_frames<kPopcnt>(rec, mask, kTrackRecordBitsAt / 8, kw, v.upto, frame);
  const uint64_t n = popcount64<kPopcnt>(mask) + kContextKeys;  // values per curve
  const Curve& c0 = v.curves[curve[0]];
  const Curve& c1 = v.curves[curve[1]];
  const Curve& c2 = v.curves[curve[2]];
  const uint32_t vw0 = rec[8], vw1 = rec[9], vw2 = rec[10];
  const uint64_t base0 = kTrackRecordBitsAt + uint64_t(kContextKeys) * kw, base1 = base0 + c0.base_bits,
                 base2 = base1 + c1.base_bits;
  const uint64_t run0 = base2 + c2.base_bits, run1 = run0 + n * vw0, run2 = run1 + n * vw1;
  auto one = [&](const Curve& cv, uint64_t base_at, uint64_t run_at, uint32_t vw, float* out) KEYANIM_INLINE {
    if (out == nullptr) return;
    Window w;
    w.base = read_bits(rec, base_at, cv.base_bits);
    w.value_bits = vw;
    w.at = run_at + uint64_t(count) * vw;
    dequantize4_at<kWide>(rec, w, cv, out);
  };
  one(c0, base0, run0, vw0, values[0]);
  one(c1, base1, run1, vw1, values[1]);
  one(c2, base2, run2, vw2, values[2]);
}

// A list curve's keys j-1 .. j+2 around f (j: the segment Appendix A finds, clamped to the
// first or last segment outside the keys), with virtual keys beyond the ends as in records.
struct ListWindow {
  int64_t frame[4];
  float value[4];
  uint32_t j;  // index of key j in the list
};

KEYANIM_INLINE inline void list_window(const Image& img, const ListSpan& list, float f, ListWindow& w) noexcept {
  const uint32_t* k = img.list_frames.data() + list.first;
  const float* v = img.list_values.data() + list.first;
  const uint32_t n = list.count;
  const float clamped = std::min(std::max(f, static_cast<float>(k[0])), static_cast<float>(k[n - 1]));
  const uint32_t j = find_segment(k, n, clamped);
  w.j = j;
  w.frame[0] = j > 0 ? int64_t(k[j - 1]) : 2 * int64_t(k[0]) - int64_t(k[1]);
  w.frame[1] = k[j];
  w.frame[2] = k[j + 1];
  w.frame[3] = j + 2 < n ? int64_t(k[j + 2]) : 2 * int64_t(k[n - 1]) - int64_t(k[n - 2]);
  w.value[0] = v[j > 0 ? j - 1 : 0];
  w.value[1] = v[j];
  w.value[2] = v[j + 1];
  w.value[3] = v[j + 2 < n ? j + 2 : n - 1];
}

}  // namespace
}  // namespace keyanim::internal
