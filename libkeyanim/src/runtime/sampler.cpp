// Sampling the runtime image. Two passes over chunks of channels: a scalar pass reads each
// curve's record (image.h: read_window) into its four key frames and dequantized values, then
// a SIMD pass evaluates Appendix A with cardinal.h's building blocks 4 channels at a time (8 in
// the AVX2 copy: internal/simd8.h). Both passes compute exactly Appendix A, so every value is
// bit-identical to eval_channel's (tests check every channel of every test vector and corpus clip).
#include "runtime/sampler.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "internal/cpu.h"
#include "internal/prefetch.h"
#include "internal/simd.h"
#include "internal/simd8.h"
#include "runtime/gather.h"

namespace keyanim::internal {
namespace {

constexpr uint32_t kChunk = 32;  // a multiple of 4 (SIMD lanes)

// Pass one's output for a chunk: per lane its keys j-1 .. j+2 (frames relative to the block,
// dequantized values), and the per-curve facts the evaluation needs (which the sampler of all
// curves reads straight from the image instead).
struct Batch {
  alignas(16) int32_t frames[kChunk][4];
  alignas(16) float values[kChunk][4];
  float s[kChunk], first_frame[kChunk], last_frame[kChunk], first_value[kChunk], last_value[kChunk];
  uint32_t linear[kChunk];
};

// The per-curve facts of a chunk, wherever they are.
struct Facts {
  const float *s, *first_frame, *last_frame, *first_value, *last_value;
  const uint32_t* linear;
};

// Block curve `curve` alone in track `track`'s record into lane i.
template <bool kPopcnt>
[[gnu::always_inline]] inline void gather(const BlockView& v, uint32_t track, uint32_t curve, Batch& b,
                                          uint32_t i) noexcept {
  const Curve& cv = v.curves[curve];
  const uint8_t* rec = v.payload + v.offsets[track];
  Window w;
  read_window<kPopcnt>(rec, cv.base_bits, v.upto, w);
  std::memcpy(b.frames[i], w.frame, sizeof w.frame);
  dequantize4(rec, w, cv, b.values[i]);
}

// Quaternion track `track`'s curves x, y, z (indices curve[0..2]) into lanes lane[0..2] (gather.h:
// read_track); `only` < 3: that component alone.
template <bool kPopcnt>
[[gnu::always_inline]] inline void gather_track(const BlockView& v, uint32_t track, const uint32_t (&curve)[3],
                                                Batch& b, const uint32_t (&lane)[3],
                                                uint32_t only = kTrackCurves) noexcept {
  int32_t frame[4];
  float* values[3] = {nullptr, nullptr, nullptr};
  for (uint32_t k = 0; k < kTrackCurves; ++k)
    if (only == kTrackCurves || only == k) values[k] = b.values[lane[k]];
  read_track<kPopcnt>(v, track, curve, frame, values);
  for (uint32_t k = 0; k < kTrackCurves; ++k)
    if (values[k] != nullptr) std::memcpy(b.frames[lane[k]], frame, sizeof frame);
}

// Block curve `curve`, whichever track holds it (for the paths that list channels).
template <bool kPopcnt>
[[gnu::always_inline]] inline void gather_curve(const Image& img, const BlockView& v, uint32_t curve, Batch& b,
                                                uint32_t i) noexcept {
  const Image::TrackOf t = img.track_of(curve);
  if (t.curves == 1) return gather<kPopcnt>(v, t.track, curve, b, i);
  const uint32_t T = img.quat_tracks;
  gather_track<kPopcnt>(v, t.track, {t.track, T + t.track, 2 * T + t.track}, b, {i, i, i}, t.component);
}


KEYANIM_INLINE inline void gather_list(const Image& img, uint32_t curve, const Position& at, Batch& b, uint32_t i) noexcept {
  ListWindow w;
  list_window(img, img.lists[curve - img.block_curves], at.f, w);
  const int64_t start = int64_t(at.block) << kBlockShift;  // frames relative to f's block, as records
  for (int k = 0; k < 4; ++k) b.frames[i][k] = static_cast<int32_t>(w.frame[k] - start);
  std::memcpy(b.values[i], w.value, sizeof w.value);
}

KEYANIM_INLINE inline void set_fixed(Batch& b, uint32_t i, float v) noexcept {
  std::memset(b.frames[i], 0, sizeof b.frames[i]);
  b.frames[i][2] = b.frames[i][3] = 1;
  std::memset(b.values[i], 0, sizeof b.values[i]);
  b.s[i] = 0.0f;
  b.first_frame[i] = std::numeric_limits<float>::infinity();  // every position is "before"
  b.last_frame[i] = std::numeric_limits<float>::infinity();
  b.first_value[i] = b.last_value[i] = v;
  b.linear[i] = 0;
}

KEYANIM_INLINE inline void copy_facts(const Image& img, uint32_t curve, Batch& b, uint32_t i) noexcept {
  b.s[i] = img.curve_s[curve];
  b.first_frame[i] = img.first_frame[curve];
  b.last_frame[i] = img.last_frame[curve];
  b.first_value[i] = img.first_value[curve];
  b.last_value[i] = img.last_value[curve];
  b.linear[i] = img.curve_linear[curve];
}

// Pass two's loads of one group of lanes from i: the frames and values of each lane's four
// keys, transposed into k_{j-1} .. k_{j+2} and p_{j-1} .. p_{j+2} vectors.
KEYANIM_INLINE inline void load_keys(const Batch& b, uint32_t i, I4 (&k)[4], F4 (&p)[4]) noexcept {
  for (int r = 0; r < 4; ++r) k[r] = I4::load(b.frames[i + r]), p[r] = F4::load(b.values[i + r]);
  transpose(k[0], k[1], k[2], k[3]);
  transpose(p[0], p[1], p[2], p[3]);
}
#if KEYANIM_WIDE_LANES
KEYANIM_INLINE inline void load_keys(const Batch& b, uint32_t i, I8 (&k)[4], F8 (&p)[4]) noexcept {
  I4 klo[4], khi[4];
  F4 plo[4], phi[4];
  load_keys(b, i, klo, plo), load_keys(b, i + 4, khi, phi);
  for (int r = 0; r < 4; ++r) k[r] = I8::join(klo[r], khi[r]), p[r] = F8::join(plo[r], phi[r]);
}
#endif

// Appendix A for the lanes of one V (F4: 4, F8: 8) from batch lane lane0 + i, whose facts are
// x's from index i.
template <class V, bool kAdjusted>
KEYANIM_INLINE inline void evaluate_lanes(const Batch& b, const Facts& x, const V& f, const V& rel, uint32_t lane0,
                                          uint32_t i, float* res) noexcept {
  typename IntLanes<V>::type k[4];
  V p[4];
  load_keys(b, lane0 + i, k, p);
  // Lengths rounded once from the integer differences, as Appendix A; the uniform rule is
  // the step-adjusted one with equal lengths (tangent_scale then gives exactly 1).
  const V k0 = to_float(k[1]), k1 = to_float(k[2]), len = to_float(k[2] - k[1]);
  const V a0 = kAdjusted ? tangent_scale(len, to_float(k[1] - k[0])) : V(1.0f);
  const V a1 = kAdjusted ? tangent_scale(len, to_float(k[3] - k[2])) : V(1.0f);
  const V u = segment_u(rel, k0, k1);
  const Operands<V> o = cardinal_operands(p[0], p[1], p[2], p[3], V::load(x.s + i), a0, a1);
  const V value = select(V::load_mask(x.linear + i), linear_value(o.p0, o.d, u), hermite(o, u));
  // Appendix A's cases: f <= K_0 gives v_0, f >= K_{n-1} gives v_{n-1}, f == K_j gives v_j.
  const V before = cmp_not_gt(f, V::load(x.first_frame + i));
  const V after = cmp_ge(f, V::load(x.last_frame + i));
  const V direct = select(before, V::load(x.first_value + i), select(after, V::load(x.last_value + i), p[1]));
  select(mask_or(mask_or(before, after), cmp_eq(rel, k0)), direct, value).store(res + lane0 + i);
}

// Pass two: Appendix A for batch lanes [lane0, lane0 + count), count a multiple of 4, whose
// facts are x's [0, count); 8 lanes at a time when kWide (the v3 copy), the last 4 if any on
// their own (the facts arrays are padded to 4).
template <bool kAdjusted, bool kWide>
KEYANIM_INLINE inline void evaluate(const Batch& b, const Facts& x, const Position& at, uint32_t lane0,
                                   uint32_t count, float* res) noexcept {
  uint32_t i = 0;
#if KEYANIM_WIDE_LANES
  if constexpr (kWide) {
    const F8 f(at.f), rel(at.rel);
    for (; i + 8 <= count; i += 8) evaluate_lanes<F8, kAdjusted>(b, x, f, rel, lane0, i, res);
  }
#endif
  const F4 f(at.f), rel(at.rel);
  for (; i < count; i += 4) evaluate_lanes<F4, kAdjusted>(b, x, f, rel, lane0, i, res);
}

template <bool kWide>
KEYANIM_INLINE inline void evaluate(const Image& img, const Batch& b, const Facts& x, const Position& at,
                                   uint32_t count, float* res, uint32_t lane0 = 0) noexcept {
  if (img.rule == TangentRule::step_adjusted)
    evaluate<true, kWide>(b, x, at, lane0, count, res);
  else
    evaluate<false, kWide>(b, x, at, lane0, count, res);
}

// The facts copied into the batch, from lane `lane0`.
Facts batch_facts(const Batch& b, uint32_t lane0 = 0) {
  return {b.s + lane0, b.first_frame + lane0, b.last_frame + lane0, b.first_value + lane0, b.last_value + lane0,
          b.linear + lane0};
}
// The image's facts of curves [first, ...).
Facts image_facts(const Image& img, uint32_t first) {
  return {img.curve_s.data() + first,      img.first_frame.data() + first, img.last_frame.data() + first,
          img.first_value.data() + first, img.last_value.data() + first,  img.curve_linear.data() + first};
}

// The two passes over chunks of lanes [from, count) at position `at`: fill(b, at, view, base,
// m) gathers lanes [base, base + m) into b, facts(b, base, m) says where their per-curve facts
// are, emit(res, base, m) writes the results.
template <bool kWide, class Fill, class FactsOf, class Emit>
[[gnu::always_inline]] inline void run_chunks(const Image& img, const Position& at, const BlockView& view,
                                              uint32_t from, uint32_t count, Fill fill, FactsOf facts,
                                              Emit emit) noexcept {
  Batch b;
  alignas(16) float res[kChunk];
  for (uint32_t base = from, m = 0; base < count; base += m) {
    m = std::min(kChunk, count - base);
    fill(b, at, view, base, m);
    const uint32_t lanes = (m + 3) & ~3u;
    for (uint32_t i = m; i < lanes; ++i) set_fixed(b, i, 0.0f);
    evaluate<kWide>(img, b, facts(b, base, m), at, lanes, res);
    emit(res, base, m);
  }
}

// The listed channels at f, out[i] for channels[i].
template <bool kPopcnt, bool kWide>
[[gnu::always_inline]] inline void sample_chunks(const Image& img, float f, const uint32_t* channels, uint32_t count,
                                                 float* out) noexcept {
  auto fill = [&](Batch& b, const Position& at, const BlockView& view, uint32_t base, uint32_t m) KEYANIM_INLINE {
    for (uint32_t i = 0; i < m; ++i) {
      const uint32_t c = channels[base + i];
      const uint32_t curve = img.curve_of[c];
      if (curve == kNoCurve) {
        set_fixed(b, i, img.fixed_value[c]);
        continue;
      }
      if (curve < img.block_curves)
        gather_curve<kPopcnt>(img, view, curve, b, i);
      else
        gather_list(img, curve, at, b, i);
      copy_facts(img, curve, b, i);
    }
  };
  auto facts = [](const Batch& b, uint32_t, uint32_t) KEYANIM_INLINE { return batch_facts(b); };
  auto emit = [&](const float* res, uint32_t base, uint32_t m) KEYANIM_INLINE {
    std::memcpy(out + base, res, m * sizeof(float));
  };
  const Position at = position(img, f);
  run_chunks<kWide>(img, at, block_view(img, at), 0, count, fill, facts, emit);
}

// A record's largest size per curve in bytes, rounded up (spec 9.3: a curve's record is 10
// bytes, four contexts of up to 31 bits, a base and 68 values of up to 55 bits: 500; a
// quaternion track's, 12 bytes, the contexts, three bases and 3 x 68 values: 1,451 for its three
// curves, 484 each): a block's records take at most this many per curve, which bounds the range
// asked for when a hostile file's offsets are far apart.
constexpr uint64_t kRecordBytesBound = 512;

// What a pose of every curve reads, asked for at once: the loops below read each array a few
// curves at a time, so that on a cold clip their misses would come one curve's work apart
// (the out-of-order window holds about two curves' instructions). The block's records lie
// together (block-major offsets), so one range holds them, where a prefetch per record a few
// curves ahead (the earlier design) cost an instruction per curve and missed the first ones.
// A runtime-profile file's offsets are bounded by its payload but not ordered, so a range
// that runs backwards is skipped. Measured in bench_vs_acl against 50ee059 (two interleaved
// runs of each, cold_local median, keyanim / ACL): CMU 2.48 and 2.74 -> 1.83 and 1.87, Bandai
// 3.47 and 3.33 -> 1.89 and 2.57; a warm local pose costs about 3% more instructions.
[[gnu::always_inline]] inline void prefetch_pose(const Image& img, const BlockView& view, uint32_t block) noexcept {
  // The fixed channels, the per-curve arrays and the quaternion nodes' and tracks' arrays are
  // one range of the image (spec 9.2's order; an empty array lies where it would start).
  using L = ImageLayout;
  static_assert(L::curves == L::fixed_channels + 1 && L::curve_channel == L::curves + 7 &&
                    L::quat_reference == L::curve_channel + 3,
                "fixed_channels, curves, curve_s .. curve_linear, curve_channel, quat_node .. quat_reference are consecutive");
  const auto* from = reinterpret_cast<const uint8_t*>(img.fixed_channels.data());
  const auto* to = reinterpret_cast<const uint8_t*>(img.quat_reference.data() + img.quat_reference.size());
  prefetch_bytes(from, size_t(to - from));
  if (!img.fixed_channels.empty()) prefetch_array(img.fixed_value.data(), img.fixed_value.size());  // by channel
  if (img.block_tracks == 0) return;
  prefetch_array(view.offsets, img.block_tracks);
  const uint64_t first = view.offsets[0];
  const uint64_t last = block + 1 < img.block_count ? view.offsets[img.block_tracks] : img.payload.size();
  if (first < last) prefetch_array(view.payload + first, std::min(last - first, img.block_curves * kRecordBytesBound));
}

// Quaternion tracks [t0, t0 + n) (n <= 8): their x's into batch lanes [0, g), y's into [g, 2g),
// z's into [2g, 3g) (g: n rounded up to 4), evaluated with each curve's facts where the arrays
// hold them for all g lanes (a whole group), else with facts copied into the batch; written to
// their channels.
template <bool kPopcnt, bool kWide>
[[gnu::always_inline]] inline void sample_quat_group(const Image& img, const Position& at, const BlockView& view,
                                                     uint32_t t0, uint32_t n, Batch& b, float* res,
                                                     float* out) noexcept {
  const uint32_t T = img.quat_tracks, g = (n + 3) & ~3u;
  const bool whole = n == g;
  for (uint32_t j = 0; j < n; ++j) {
    const uint32_t t = t0 + j;
    const uint32_t curve[3] = {t, T + t, 2 * T + t}, lane[3] = {j, g + j, 2 * g + j};
    gather_track<kPopcnt>(view, t, curve, b, lane);
    if (!whole)
      for (uint32_t k = 0; k < kTrackCurves; ++k) copy_facts(img, curve[k], b, lane[k]);
  }
  for (uint32_t j = n; j < g; ++j)
    for (uint32_t k = 0; k < kTrackCurves; ++k) set_fixed(b, k * g + j, 0.0f);
  for (uint32_t k = 0; k < kTrackCurves; ++k)
    evaluate<kWide>(img, b, whole ? image_facts(img, t0 + k * T) : batch_facts(b, k * g), at, g, res, k * g);
  const uint32_t* channel = img.curve_channel.data();
  for (uint32_t k = 0; k < kTrackCurves; ++k)
    for (uint32_t j = 0; j < n; ++j) out[channel[t0 + j + k * T]] = res[k * g + j];
}

// Every curve, written to its channel; the fixed channels separately. The quaternion tracks
// first, 8 at a time (24 lanes); then the other curves in chunks, their facts read from the
// image directly where the arrays (padded to whole groups of 4) hold the chunk's lanes.
// Without kTracks, the quaternion tracks' curves are left out (their channels untouched).
template <bool kPopcnt, bool kWide, bool kTracks = true>
[[gnu::always_inline]] inline void sample_curves(const Image& img, float f, float* out) noexcept {
  const Position at = position(img, f);
  const BlockView view = block_view(img, at);
  if (img.block_count > 0) prefetch_pose(img, view, at.block);
  for (uint32_t c : img.fixed_channels) out[c] = img.fixed_value[c];
  const uint32_t T = img.quat_tracks;
  if (kTracks && T > 0) {
    Batch b;
    alignas(16) float res[kChunk];
    static_assert(3 * 8 <= kChunk, "a group of 8 quaternion tracks fits a batch");
    for (uint32_t t0 = 0; t0 < T; t0 += 8)
      sample_quat_group<kPopcnt, kWide>(img, at, view, t0, std::min(8u, T - t0), b, res, out);
  }
  const uint32_t nb = img.block_curves, padded = static_cast<uint32_t>(img.curve_s.size());
  auto copied = [padded](uint32_t base, uint32_t m) { return base + ((m + 3) & ~3u) > padded; };
  auto fill = [&](Batch& b, const Position& p, const BlockView& v, uint32_t base, uint32_t m) KEYANIM_INLINE {
    const uint32_t blocked = base < nb ? std::min(m, nb - base) : 0;
    for (uint32_t i = 0; i < blocked; ++i) gather<kPopcnt>(v, base + i - 2 * T, base + i, b, i);
    for (uint32_t i = blocked; i < m; ++i) gather_list(img, base + i, p, b, i);
    if (copied(base, m))  // the facts' lanes run past the arrays
      for (uint32_t i = 0; i < m; ++i) copy_facts(img, base + i, b, i);
  };
  auto facts = [&](const Batch& b, uint32_t base, uint32_t m) KEYANIM_INLINE {
    return copied(base, m) ? batch_facts(b) : image_facts(img, base);
  };
  auto emit = [&](const float* res, uint32_t base, uint32_t m) KEYANIM_INLINE {
    const uint32_t* channel = img.curve_channel.data() + base;
    for (uint32_t i = 0; i < m; ++i) out[channel[i]] = res[i];
  };
  run_chunks<kWide>(img, at, view, 3 * T, static_cast<uint32_t>(img.curves.size()), fill, facts, emit);
}

// One copy per CPU level (internal/cpu.h); popcnt from the popcnt level on, 8 lanes at v3.
constexpr bool kWideAtV3 = KEYANIM_WIDE_LANES != 0;
KEYANIM_V3_TARGET void all_v3(const Image& img, float f, float* out) noexcept {
  sample_curves<true, kWideAtV3>(img, f, out);
}
KEYANIM_POPCNT_TARGET void all_popcnt(const Image& img, float f, float* out) noexcept {
  sample_curves<true, false>(img, f, out);
}
void all_plain(const Image& img, float f, float* out) noexcept { sample_curves<false, false>(img, f, out); }
KEYANIM_V3_TARGET void other_v3(const Image& img, float f, float* out) noexcept {
  sample_curves<true, kWideAtV3, false>(img, f, out);
}
KEYANIM_POPCNT_TARGET void other_popcnt(const Image& img, float f, float* out) noexcept {
  sample_curves<true, false, false>(img, f, out);
}
void other_plain(const Image& img, float f, float* out) noexcept { sample_curves<false, false, false>(img, f, out); }
KEYANIM_V3_TARGET void listed_v3(const Image& img, float f, const uint32_t* ch, uint32_t n, float* out) noexcept {
  sample_chunks<true, kWideAtV3>(img, f, ch, n, out);
}
KEYANIM_POPCNT_TARGET void listed_popcnt(const Image& img, float f, const uint32_t* ch, uint32_t n,
                                         float* out) noexcept {
  sample_chunks<true, false>(img, f, ch, n, out);
}
void listed_plain(const Image& img, float f, const uint32_t* ch, uint32_t n, float* out) noexcept {
  sample_chunks<false, false>(img, f, ch, n, out);
}

}  // namespace

void sample_all(const Image& img, float f, float* out) noexcept {
  switch (cpu_level()) {
    case CpuLevel::v3: return all_v3(img, f, out);
    case CpuLevel::popcnt: return all_popcnt(img, f, out);
    default: return all_plain(img, f, out);
  }
}

void sample_all_but_quat_tracks(const Image& img, float f, float* out) noexcept {
  switch (cpu_level()) {
    case CpuLevel::v3: return other_v3(img, f, out);
    case CpuLevel::popcnt: return other_popcnt(img, f, out);
    default: return other_plain(img, f, out);
  }
}

void sample_listed(const Image& img, float f, const uint32_t* channels, uint32_t count, float* out) noexcept {
  switch (cpu_level()) {
    case CpuLevel::v3: return listed_v3(img, f, channels, count, out);
    case CpuLevel::popcnt: return listed_popcnt(img, f, channels, count, out);
    default: return listed_plain(img, f, channels, count, out);
  }
}

void sample_range(const Image& img, float f, uint32_t first, uint32_t count, float* out) noexcept {
  uint32_t list[kChunk];
  for (uint32_t done = 0; done < count; done += kChunk) {
    const uint32_t m = std::min(kChunk, count - done);
    for (uint32_t i = 0; i < m; ++i) list[i] = first + done + i;
    sample_listed(img, f, list, m, out + done);
  }
}


}  // namespace keyanim::internal
