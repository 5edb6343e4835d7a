// Cursor: playback state. Each curve keeps its current segment's operands (so a position
// inside the same segments costs only the polynomial) and a stream over its record (so the
// next segment costs one key). A quaternion track's three curves share their key frames: one
// range check, one walk of the keys and one value each per step, and a pose's rotations built
// from their values as they lie (curve order), without going through the channels.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <new>

#include "internal/cpu.h"
#include "internal/next_float.h"
#include "internal/simd.h"
#include "internal/simd8.h"
#include "runtime/clip_access.h"
#include "runtime/cursor_state.h"
#include "runtime/quat_lanes.h"

namespace keyanim {

using internal::Image;

Cursor::Cursor() = default;
Cursor::~Cursor() = default;
Cursor::Cursor(Cursor&&) noexcept = default;
Cursor& Cursor::operator=(Cursor&&) noexcept = default;

Status Cursor::prepare(const Clip& clip) noexcept {
  try {
    auto st = std::make_unique<State>();
    const Image& img = ClipAccess::image(clip);
    st->image = ClipAccess::shared(clip);
    // An empty range (lo = +inf) makes every curve refresh; the padding lanes of the last group
    // are evaluated with the others, and their results never read.
    internal::SegmentLanes empty{};
    std::fill(std::begin(empty.lo), std::end(empty.lo), std::numeric_limits<float>::infinity());
    std::fill(std::begin(empty.k1), std::end(empty.k1), 1.0f);
    std::fill(std::begin(empty.direct), std::end(empty.direct), ~0u);
    st->lanes.assign((img.curves.size() + 7) / 8, empty);
    st->streams.assign(img.curves.size(), internal::KeyStream{});
    st->results.assign(8 * (st->lanes.size() + 1), 0.0f);
    st->channels.assign(img.interp.size(), 0.0f);
    state_ = std::move(st);
    return Status::ok;
  } catch (const std::bad_alloc&) {
    state_.reset();
    return Status::limit_exceeded;
  }
}

bool Cursor::prepared_for(const Clip& clip) const noexcept {
  const Image& img = ClipAccess::image(clip);
  return state_ && state_->image && state_->image->id == img.id;
}

namespace internal {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
// Stale curves (a quaternion track counts once) refreshed together: enough for a few SIMD
// batches of operands, few enough to stay in registers' reach (a multiple of 4).
constexpr uint32_t kRefreshBatch = 32;
// Curves a refresh can position: a batch (a group of 4 lanes may pass kRefreshBatch by 3) of
// tracks, three curves each, and padding lanes to a multiple of 4.
constexpr uint32_t kRefreshCurves = 3 * (kRefreshBatch + 3) + 3;

// The state's arrays, as plain pointers: held in registers through a refresh (a vector's data
// pointer is read again after every store through a uint8_t).
struct Play {
  SegmentLanes* lanes;
  KeyStream* streams;
};

// Curve i's state: its group of lanes and its lane there.
struct Slot {
  SegmentLanes& g;
  uint32_t l;
};
KEYANIM_INLINE inline Slot slot(Play st, uint32_t i) noexcept { return {st.lanes[i >> 3], i & 7}; }

// A state where curve i's value is `value` for lo <= f < hi.
KEYANIM_INLINE inline void set_direct(Slot s, float value, float lo, float hi) noexcept {
  SegmentLanes& g = s.g;
  const uint32_t l = s.l;
  g.lo[l] = lo, g.hi[l] = hi, g.value[l] = value;
  g.k0[l] = 0.0f, g.k1[l] = 1.0f, g.p0[l] = g.d[l] = g.m0[l] = g.m1[l] = 0.0f;
  g.linear[l] = 0u, g.direct[l] = ~0u;
}

// Curves c[0 .. n) (one curve, or a quaternion track's three, whose key frames are the same)
// clamped at f outside their keys: true (their states set), else false.
KEYANIM_INLINE inline bool clamped(const Image& img, Play st, const uint32_t* c, uint32_t n, float f) noexcept {
  const float first = img.first_frame[c[0]], last = img.last_frame[c[0]];
  if (!(f > first)) {
    for (uint32_t k = 0; k < n; ++k) set_direct(slot(st, c[k]), img.first_value[c[k]], -kInf, next_above(first));
    return true;
  }
  if (f >= last) {
    for (uint32_t k = 0; k < n; ++k) set_direct(slot(st, c[k]), img.last_value[c[k]], last, kInf);
    return true;
  }
  return false;
}

// Whether stream ks can move forward to f within its record; if so it has (a few keys forward
// in playback). `follow`: streams (a track's y and z) that move with it, one value each.
KEYANIM_INLINE inline bool forward(KeyStream& ks, float f, KeyStream* const* follow, uint32_t followers) noexcept {
  bool ok = f >= static_cast<float>(ks.k[1]) && ks.block >= 0;  // forward, in a record
  while (ok && static_cast<float>(ks.k[2]) <= f) {
    ok = advance_stream(ks);
    for (uint32_t k = 0; ok && k < followers; ++k) follow_stream(*follow[k], ks);
  }
  return ok;
}

// Step one of a refresh for curve i alone: false (and the state set) when f is outside its
// keys, where it is clamped; else its stream is on f's segment (forward, or a seek), and the
// operands are left to the batch (step two).
KEYANIM_INLINE inline bool position_curve(const Image& img, Play st, uint32_t i, float f) noexcept {
  if (clamped(img, st, &i, 1, f)) return false;
  if (!forward(st.streams[i], f, nullptr, 0)) seek_stream(img, i, f, st.streams[i]);
  return true;
}

// The same for quaternion track t, curves c = {t, T + t, 2T + t}: one range check and one walk
// of the key frames for the three (their streams were positioned together, and stay so).
KEYANIM_INLINE inline bool position_track(const Image& img, Play st, const uint32_t (&c)[3], float f) noexcept {
  if (clamped(img, st, c, 3, f)) return false;
  KeyStream* const follow[2] = {&st.streams[c[1]], &st.streams[c[2]]};
  if (!forward(st.streams[c[0]], f, follow, 2))
    for (uint32_t k = 0; k < 3; ++k) seek_stream(img, c[k], f, st.streams[c[k]]);
  return true;
}

// A refreshed curve's segment: its key frames, Appendix A's operands, and whether the
// polynomial gives exactly the key's value at K_j (`exact`, below).
struct Segments {
  alignas(16) float k0[kRefreshCurves], k1[kRefreshCurves], p0[kRefreshCurves], d[kRefreshCurves],
      m0[kRefreshCurves], m1[kRefreshCurves];
  uint8_t exact[kRefreshCurves];
};

// Step two of a refresh, four curves at once (`curve`: their indices, streams positioned; the
// results to seg from entry j): the operands of each one's segment, as Appendix A computes them
// (the same operations in every lane as cardinal.h's scalar ones, so the same bits: tests
// compare with the sampler). Key frames are exact in binary32 (below 2^24), so u from them
// equals the sampler's (both round f - K_j once); lengths are rounded once from the integer
// differences. At f == K_j the polynomial gives p0 + (+-0) ... = p0 exactly, as Appendix A's
// v_j, when the operands are finite and p0 is not -0 (-0 + +0 is +0): `exact`.
KEYANIM_INLINE inline void operands4(const Image& img, Play st, const uint32_t* curve, Segments& seg,
                                     uint32_t j) noexcept {
  I4 k[4];
  F4 p[4];
  for (int r = 0; r < 4; ++r) {
    const KeyStream& ks = st.streams[curve[r]];
    k[r] = I4::load(ks.k), p[r] = F4::load(ks.v);
  }
  transpose(k[0], k[1], k[2], k[3]);
  transpose(p[0], p[1], p[2], p[3]);
  const F4 k0 = to_float(k[1]), k1 = to_float(k[2]), len = to_float(k[2] - k[1]);
  const bool adjusted = img.rule == TangentRule::step_adjusted;
  const F4 a0 = adjusted ? tangent_scale(len, to_float(k[1] - k[0])) : F4(1.0f);
  const F4 a1 = adjusted ? tangent_scale(len, to_float(k[3] - k[2])) : F4(1.0f);
  const float* s = img.curve_s.data();
  const F4 sv = F4::set(s[curve[0]], s[curve[1]], s[curve[2]], s[curve[3]]);
  const Operands<F4> o = cardinal_operands(p[0], p[1], p[2], p[3], sv, a0, a1);
  // x - x is +0 exactly when x is finite.
  const F4 zero(0.0f);
  const uint32_t finite = sign_bits(cmp_eq(o.d - o.d, zero)) & sign_bits(cmp_eq(o.m0 - o.m0, zero)) &
                          sign_bits(cmp_eq(o.m1 - o.m1, zero));
  const uint32_t exact = finite & ~(sign_bits(cmp_eq(o.p0, zero)) & sign_bits(o.p0));
  k0.store(seg.k0 + j), k1.store(seg.k1 + j), o.p0.store(seg.p0 + j), o.d.store(seg.d + j);
  o.m0.store(seg.m0 + j), o.m1.store(seg.m1 + j);
  const uint32_t bytes = (exact * 0x00204081u) & 0x01010101u;  // bit l to byte l (l < 4)
  std::memcpy(seg.exact + j, &bytes, sizeof bytes);
}

// Curve i's state from entry j of seg. `exact` for every curve sharing the state's range (a
// track's three): the range [K_j, K_j+1) then; else K_j is a direct state of its own (f ==
// K_j), or the range starts just above it.
KEYANIM_INLINE inline void set_segment(const Image& img, Play st, uint32_t i, float f, const Segments& seg,
                                       uint32_t j, bool exact) noexcept {
  const Slot at = slot(st, i);
  SegmentLanes& g = at.g;
  const uint32_t l = at.l;
  const float k0 = seg.k0[j], k1 = seg.k1[j];
  g.k0[l] = k0, g.k1[l] = k1, g.p0[l] = seg.p0[j], g.d[l] = seg.d[j], g.m0[l] = seg.m0[j], g.m1[l] = seg.m1[j];
  g.linear[l] = img.curve_linear[i];
  if (exact) [[likely]] {
    g.lo[l] = k0, g.hi[l] = k1, g.direct[l] = 0u;
  } else if (f == k0) {
    g.lo[l] = k0, g.hi[l] = next_above(k0), g.direct[l] = ~0u, g.value[l] = seg.p0[j];
  } else {
    g.lo[l] = next_above(k0), g.hi[l] = k1, g.direct[l] = 0u;
  }
}

// Refreshes the curves whose segment f left (`stale`, count of them; a quaternion track by its
// x, t < T): each one's stream first (a track's three together), then the operands of those
// inside their keys four at a time, then their states (a track's three with one range: exact
// only if all three are).
KEYANIM_INLINE inline void refresh(const Image& img, Play st, const uint32_t* stale, uint32_t count,
                                   float f) noexcept {
  const uint32_t T = img.quat_tracks;
  uint32_t inside[kRefreshCurves];
  uint32_t m = 0;
  for (uint32_t j = 0; j < count; ++j) {
    const uint32_t i = stale[j];
    if (i < T) {
      const uint32_t c[3] = {i, T + i, 2 * T + i};
      if (position_track(img, st, c, f)) inside[m] = c[0], inside[m + 1] = c[1], inside[m + 2] = c[2], m += 3;
    } else if (position_curve(img, st, i, f)) {
      inside[m++] = i;
    }
  }
  if (m == 0) return;
  for (uint32_t j = m; j < ((m + 3) & ~3u); ++j) inside[j] = inside[m - 1];  // padding lanes, not stored
  Segments seg;
  for (uint32_t j = 0; j < m; j += 4) operands4(img, st, inside + j, seg, j);
  for (uint32_t j = 0; j < m;) {
    if (inside[j] < T) {
      const bool exact = seg.exact[j] & seg.exact[j + 1] & seg.exact[j + 2];
      for (uint32_t k = 0; k < 3; ++k) set_segment(img, st, inside[j + k], f, seg, j + k, exact);
      j += 3;
    } else {
      set_segment(img, st, inside[j], f, seg, j, seg.exact[j]);
      ++j;
    }
  }
}

// The values at f of the lanes of one V (F4: 4, F8: 8) of group g from lane l, to `result`.
template <class V>
KEYANIM_INLINE inline void evaluate_lanes(const SegmentLanes& g, const V& f, uint32_t l, float* result) noexcept {
  const V u = segment_u(f, V::load(g.k0 + l), V::load(g.k1 + l));
  const Operands<V> o{V::load(g.p0 + l), V::load(g.d + l), V::load(g.m0 + l), V::load(g.m1 + l)};
  const V v = select(V::load_mask(g.linear + l), linear_value(o.p0, o.d, u), hermite(o, u));
  select(V::load_mask(g.direct + l), V::load(g.value + l), v).store(result + l);
}

// Lanes [i, i + 4) of the curves whose range is checked, [first, end), with a bit for each
// lane outside it: the curves there whose state f left.
KEYANIM_INLINE inline uint32_t stale_lanes(Play st, const F4& f, uint32_t i, uint32_t first,
                                           uint32_t end) noexcept {
  const SegmentLanes& g = st.lanes[i >> 3];
  uint32_t bits = outside(f, F4::load(g.lo + (i & 7)), F4::load(g.hi + (i & 7)));
  if (i < first) bits &= ~((1u << (first - i)) - 1);
  if (end - i < 4) bits &= (1u << (end - i)) - 1;
  return bits;
}

// Which curves left their segment, 4 lanes at a time, refreshed in batches: quaternion tracks
// by their x (curves [0, T): their y's and z's share its range), then the curves [3T, n).
KEYANIM_INLINE inline void refresh_stale(const Image& img, Play st, float f) noexcept {
  const uint32_t n = static_cast<uint32_t>(img.curves.size()), T = img.quat_tracks;
  const F4 fv(f);
  uint32_t stale[kRefreshBatch + 3];
  uint32_t count = 0;
  const uint32_t ranges[2][2] = {{0, T}, {3 * T, n}};
  for (const auto& r : ranges) {
    for (uint32_t i = r[0] & ~3u; i < r[1]; i += 4) {
      for (uint32_t bits = stale_lanes(st, fv, i, r[0], r[1]); bits != 0; bits &= bits - 1)
        stale[count++] = i + static_cast<uint32_t>(__builtin_ctz(bits));
      if (count >= kRefreshBatch) refresh(img, st, stale, count, f), count = 0;
    }
  }
  refresh(img, st, stale, count, f);
}

// The quaternion tracks' rotations from their curves' values (curves t, T + t, 2T + t of
// track t: contiguous x's, y's, z's), 8 or 4 tracks a register, to out[node].rotation.
template <bool kWide>
KEYANIM_INLINE inline void track_rotations(const Image& img, const float* result, Transform* out) noexcept {
  const uint32_t T = img.quat_tracks;
  uint32_t t = 0;
#if KEYANIM_WIDE_LANES
  if constexpr (kWide) {
    for (; t + 4 < T; t += 8)
      store_quat_rotations(img, t, std::min(8u, T - t), F8::load(result + t), F8::load(result + T + t),
                           F8::load(result + 2 * T + t), 0, out);
  }
#endif
  for (; t < T; t += 4)
    store_quat_rotations(img, t, std::min(4u, T - t), F4::load(result + t), F4::load(result + T + t),
                         F4::load(result + 2 * T + t), 0, out);
}

template <bool kWide>
KEYANIM_INLINE inline void playback_impl(const Image& img, Cursor::State& st, float f, float* out,
                                         Transform* tracks) noexcept {
  refresh_stale(img, Play{st.lanes.data(), st.streams.data()}, f);
  // Every group's lanes, padding included (it holds direct states).
  float* result = st.results.data();
#if KEYANIM_WIDE_LANES
  if constexpr (kWide) {
    const F8 f8(f);
    for (size_t g = 0; g < st.lanes.size(); ++g) evaluate_lanes(st.lanes[g], f8, 0, result + 8 * g);
  } else
#endif
  {
    const F4 f4(f);
    for (size_t g = 0; g < st.lanes.size(); ++g)
      evaluate_lanes(st.lanes[g], f4, 0, result + 8 * g), evaluate_lanes(st.lanes[g], f4, 4, result + 8 * g);
  }
  const uint32_t n = static_cast<uint32_t>(img.curves.size());
  uint32_t c = 0;
  if (tracks != nullptr) {
    track_rotations<kWide>(img, result, tracks);
    c = 3 * img.quat_tracks;
  }
  const uint32_t* channel = img.curve_channel.data();
  for (; c < n; ++c) out[channel[c]] = result[c];
  for (uint32_t k : img.fixed_channels) out[k] = img.fixed_value[k];
}

// One copy per CPU level (internal/cpu.h), 8 lanes at v3.
KEYANIM_V3_TARGET void playback_v3(const Image& img, Cursor::State& st, float f, float* out, Transform* tracks) noexcept {
  playback_impl<KEYANIM_WIDE_LANES != 0>(img, st, f, out, tracks);
}
void playback_plain(const Image& img, Cursor::State& st, float f, float* out, Transform* tracks) noexcept {
  playback_impl<false>(img, st, f, out, tracks);
}

}  // namespace

void sample_playback(const Image& img, Cursor::State& st, float f, float* out, Transform* tracks) noexcept {
  cpu_level() == CpuLevel::v3 ? playback_v3(img, st, f, out, tracks) : playback_plain(img, st, f, out, tracks);
}

}  // namespace internal
}  // namespace keyanim
