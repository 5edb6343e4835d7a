// Quaternion tracks to rotations. Per group of 8 tracks (4 below the AVX2 level), a scalar pass
// reads each track's record once (gather.h: read_track) into its keys' frames and its x, y, z's
// values; a SIMD pass evaluates Appendix A for the three curves, whose key frames are the same,
// with one segment parameter and one pair of tangent scales per track, then builds each
// rotation (keyanim/rotation.h) and stores it. Each curve's value is computed with the very
// operations of the sampler (sampler.cpp: evaluate_lanes), so the rotations are the generic
// path's bit for bit (tests compare them), without writing the curves' values anywhere.
#include "runtime/quat_tracks.h"

#include <algorithm>
#include <cstring>
#include <limits>

#include "internal/cpu.h"
#include "internal/simd.h"
#include "internal/simd8.h"
#include "keyanim/cardinal.h"
#include "runtime/gather.h"
#include "runtime/quat_lanes.h"

namespace keyanim::internal {
namespace {

constexpr uint32_t kGroup = 8;  // tracks per group: one F8, or two F4
constexpr int32_t kPaddingFrames[4] = {0, 0, 1, 1};  // a padding lane's keys: any segment of nonzero length

// A group's keys and, for a group whose facts run past the image's arrays (the last one), its
// facts: per track s, linear, first and last key frames; per curve the first and last values.
struct TrackBatch {
  alignas(32) int32_t frames[kGroup][4];
  alignas(32) float values[kTrackCurves][kGroup][4];
  alignas(32) float s[kGroup], first_frame[kGroup], last_frame[kGroup];
  alignas(32) float first_value[kTrackCurves][kGroup], last_value[kTrackCurves][kGroup];
  alignas(32) uint32_t linear[kGroup];
};

// Where a group's facts are (per track; per curve for the values).
struct TrackFacts {
  const float *s, *first_frame, *last_frame;
  const uint32_t* linear;
  const float *first_value[kTrackCurves], *last_value[kTrackCurves];
};

// Lanes from row i of AoS [lane][4] arrays, transposed: r[k] holds lane i + l's entry k.
KEYANIM_INLINE inline void load_rows(const int32_t (*rows)[4], uint32_t i, I4 (&r)[4]) noexcept {
  for (int k = 0; k < 4; ++k) r[k] = I4::load(rows[i + k]);
  transpose(r[0], r[1], r[2], r[3]);
}
KEYANIM_INLINE inline void load_rows(const float (*rows)[4], uint32_t i, F4 (&r)[4]) noexcept {
  for (int k = 0; k < 4; ++k) r[k] = F4::load(rows[i + k]);
  transpose(r[0], r[1], r[2], r[3]);
}
#if KEYANIM_WIDE_LANES
KEYANIM_INLINE inline void load_rows(const int32_t (*rows)[4], uint32_t i, I8 (&r)[4]) noexcept {
  I4 lo[4], hi[4];
  load_rows(rows, i, lo), load_rows(rows, i + 4, hi);
  for (int k = 0; k < 4; ++k) r[k] = I8::join(lo[k], hi[k]);
}
KEYANIM_INLINE inline void load_rows(const float (*rows)[4], uint32_t i, F8 (&r)[4]) noexcept {
  F4 lo[4], hi[4];
  load_rows(rows, i, lo), load_rows(rows, i + 4, hi);
  for (int k = 0; k < 4; ++k) r[k] = F8::join(lo[k], hi[k]);
}
#endif

// The lanes of one V from lane i of a group starting at track t0: Appendix A for x, y, z (the
// operations of sampler.cpp's evaluate_lanes, with u and the tangent scales computed once for
// the three), then their rotations.
template <class V, bool kAdjusted>
KEYANIM_INLINE inline void track_lanes(const Image& img, const TrackBatch& b, const TrackFacts& x, const V& f,
                                       const V& rel, uint32_t t0, uint32_t i, uint32_t lanes, Transform* out) noexcept {
  typename IntLanes<V>::type k[4];
  load_rows(b.frames, i, k);
  const V k0 = to_float(k[1]), k1 = to_float(k[2]), len = to_float(k[2] - k[1]);
  const V a0 = kAdjusted ? tangent_scale(len, to_float(k[1] - k[0])) : V(1.0f);
  const V a1 = kAdjusted ? tangent_scale(len, to_float(k[3] - k[2])) : V(1.0f);
  const V u = segment_u(rel, k0, k1);
  const V s = V::load(x.s + i), linear = V::load_mask(x.linear + i);
  const V before = cmp_not_gt(f, V::load(x.first_frame + i));
  const V after = cmp_ge(f, V::load(x.last_frame + i));
  const V at_key = mask_or(mask_or(before, after), cmp_eq(rel, k0));
  V value[kTrackCurves];
  for (uint32_t c = 0; c < kTrackCurves; ++c) {
    V p[4];
    load_rows(b.values[c], i, p);
    const Operands<V> o = cardinal_operands(p[0], p[1], p[2], p[3], s, a0, a1);
    const V curve = select(linear, linear_value(o.p0, o.d, u), hermite(o, u));
    const V direct = select(before, V::load(x.first_value[c] + i), select(after, V::load(x.last_value[c] + i), p[1]));
    value[c] = select(at_key, direct, curve);
  }
  store_quat_rotations(img, t0 + i, lanes, value[0], value[1], value[2], 0, out);
}

// Tracks [t0, t0 + n), n <= kGroup: the scalar pass, then the SIMD pass 8 or 4 lanes at a time.
// Lanes past n (up to the group's whole registers) are fixed at 0 and never stored.
template <bool kPopcnt, bool kWide, bool kAdjusted>
KEYANIM_INLINE inline void track_group(const Image& img, const Position& at, const BlockView& view, uint32_t t0,
                                       uint32_t n, TrackBatch& b, Transform* out) noexcept {
  const uint32_t T = img.quat_tracks, g = (n + 3) & ~3u;
  for (uint32_t j = 0; j < n; ++j) {
    const uint32_t t = t0 + j;
    float* values[3] = {b.values[0][j], b.values[1][j], b.values[2][j]};
    read_track<kPopcnt, kWide>(view, t, {t, T + t, 2 * T + t}, b.frames[j], values);
  }
  // The facts from the image where its arrays hold the group's lanes (every group but the
  // last, and that one when whole), else copied.
  TrackFacts x;
  if (t0 + g <= T) {
    x = {img.curve_s.data() + t0, img.first_frame.data() + t0, img.last_frame.data() + t0,
         img.curve_linear.data() + t0, {}, {}};
    for (uint32_t c = 0; c < kTrackCurves; ++c)
      x.first_value[c] = img.first_value.data() + t0 + c * T, x.last_value[c] = img.last_value.data() + t0 + c * T;
  } else {
    for (uint32_t j = 0; j < g; ++j) {
      const bool real = j < n;
      const uint32_t t = t0 + j;
      b.s[j] = real ? img.curve_s[t] : 0.0f;
      b.linear[j] = real ? img.curve_linear[t] : 0u;
      b.first_frame[j] = real ? img.first_frame[t] : std::numeric_limits<float>::infinity();
      b.last_frame[j] = real ? img.last_frame[t] : std::numeric_limits<float>::infinity();
      for (uint32_t c = 0; c < kTrackCurves; ++c) {
        b.first_value[c][j] = real ? img.first_value[t + c * T] : 0.0f;
        b.last_value[c][j] = real ? img.last_value[t + c * T] : 0.0f;
      }
      if (!real) {  // a padding lane: before its first key, so its values are its (zero) first values
        std::memcpy(b.frames[j], kPaddingFrames, sizeof b.frames[j]);
        for (uint32_t c = 0; c < kTrackCurves; ++c) std::memset(b.values[c][j], 0, sizeof b.values[c][j]);
      }
    }
    x = {b.s, b.first_frame, b.last_frame, b.linear, {b.first_value[0], b.first_value[1], b.first_value[2]},
         {b.last_value[0], b.last_value[1], b.last_value[2]}};
  }
  uint32_t i = 0;
#if KEYANIM_WIDE_LANES
  if constexpr (kWide) {
    if (g == kGroup) {
      track_lanes<F8, kAdjusted>(img, b, x, F8(at.f), F8(at.rel), t0, 0, n, out);
      return;
    }
  }
#endif
  for (; i < g; i += 4) track_lanes<F4, kAdjusted>(img, b, x, F4(at.f), F4(at.rel), t0, i, std::min(4u, n - i), out);
}

template <bool kPopcnt, bool kWide>
KEYANIM_INLINE inline void tracks_impl(const Image& img, float f, Transform* out) noexcept {
  const Position at = position(img, f);
  const BlockView view = block_view(img, at);
  TrackBatch b;
  const bool adjusted = img.rule == TangentRule::step_adjusted;
  for (uint32_t t0 = 0; t0 < img.quat_tracks; t0 += kGroup) {
    const uint32_t n = std::min(kGroup, img.quat_tracks - t0);
    if (adjusted)
      track_group<kPopcnt, kWide, true>(img, at, view, t0, n, b, out);
    else
      track_group<kPopcnt, kWide, false>(img, at, view, t0, n, b, out);
  }
}

// One copy per CPU level (internal/cpu.h); popcnt from the popcnt level on, 8 lanes at v3.
KEYANIM_V3_TARGET void tracks_v3(const Image& img, float f, Transform* out) noexcept {
  tracks_impl<true, KEYANIM_WIDE_LANES != 0>(img, f, out);
}
KEYANIM_POPCNT_TARGET void tracks_popcnt(const Image& img, float f, Transform* out) noexcept {
  tracks_impl<true, false>(img, f, out);
}
void tracks_plain(const Image& img, float f, Transform* out) noexcept { tracks_impl<false, false>(img, f, out); }

}  // namespace

void quat_track_rotations(const Image& img, float f, Transform* out) noexcept {
  if (img.quat_tracks == 0) return;
  switch (cpu_level()) {
    case CpuLevel::v3: return tracks_v3(img, f, out);
    case CpuLevel::popcnt: return tracks_popcnt(img, f, out);
    default: return tracks_plain(img, f, out);
  }
}

}  // namespace keyanim::internal
