// Cursor: playback state. Each curve keeps its current segment's operands (so a position
// inside the same segments costs only the polynomial) and a stream over its record (so the
// next segment costs one key).
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
// Stale curves refreshed together: enough for a few SIMD batches of operands, few enough to
// stay in registers' reach (a multiple of 4).
constexpr uint32_t kRefreshBatch = 32;

// Curve i's state: its group of lanes and its lane there.
struct Slot {
  SegmentLanes& g;
  uint32_t l;
};
KEYANIM_INLINE inline Slot slot(Cursor::State& st, uint32_t i) noexcept { return {st.lanes[i >> 3], i & 7}; }

// A state where curve i's value is `value` for lo <= f < hi.
KEYANIM_INLINE inline void set_direct(Slot s, float value, float lo, float hi) noexcept {
  SegmentLanes& g = s.g;
  const uint32_t l = s.l;
  g.lo[l] = lo, g.hi[l] = hi, g.value[l] = value;
  g.k0[l] = 0.0f, g.k1[l] = 1.0f, g.p0[l] = g.d[l] = g.m0[l] = g.m1[l] = 0.0f;
  g.linear[l] = 0u, g.direct[l] = ~0u;
}

// Curve i's keys around f, step one of a refresh: false (and the state set) when f is outside
// its keys, where it is clamped; else its stream is on f's segment (a few keys forward in
// playback, a seek otherwise) and the operands are left to the batch (step two).
KEYANIM_INLINE inline bool position_stream(const Image& img, Cursor::State& st, uint32_t i, float f) noexcept {
  const float first = img.first_frame[i], last = img.last_frame[i];
  if (!(f > first)) {
    set_direct(slot(st, i), img.first_value[i], -kInf, next_above(first));
    return false;
  }
  if (f >= last) {
    set_direct(slot(st, i), img.last_value[i], last, kInf);
    return false;
  }
  KeyStream& ks = st.streams[i];
  bool ok = f >= static_cast<float>(ks.k[1]) && ks.block >= 0;  // forward, in a record
  while (ok && static_cast<float>(ks.k[2]) <= f) ok = advance_stream(ks);
  if (!ok) seek_stream(img, i, f, ks);
  return true;
}

// Curve i's state from its segment's key frames and Appendix A's operands. At f == K_j the
// polynomial gives p0 + (+-0) ... = p0 exactly, as Appendix A's v_j, when the operands are
// finite and p0 is not -0 (-0 + +0 is +0): `exact_at_key`; else K_j is a direct state of its own.
KEYANIM_INLINE inline void set_segment(const Image& img, Cursor::State& st, uint32_t i, float f, float k0,
                                       float k1, const Operands<float>& o, bool exact_at_key) noexcept {
  const Slot at = slot(st, i);
  SegmentLanes& g = at.g;
  const uint32_t l = at.l;
  g.k0[l] = k0, g.k1[l] = k1, g.p0[l] = o.p0, g.d[l] = o.d, g.m0[l] = o.m0, g.m1[l] = o.m1;
  g.linear[l] = img.curve_linear[i];
  if (exact_at_key) [[likely]] {
    g.lo[l] = k0, g.hi[l] = k1, g.direct[l] = 0u;
  } else if (f == k0) {
    g.lo[l] = k0, g.hi[l] = next_above(k0), g.direct[l] = ~0u, g.value[l] = o.p0;
  } else {
    g.lo[l] = next_above(k0), g.hi[l] = k1, g.direct[l] = 0u;
  }
}

// Step two of a refresh, four curves at once (`curve`: their indices, streams positioned):
// the operands of each one's segment, as Appendix A computes them (the same operations in
// every lane as cardinal.h's scalar ones, so the same bits: tests compare with the sampler).
// Key frames are exact in binary32 (below 2^24), so u from them equals the sampler's (both
// round f - K_j once); lengths are rounded once from the integer differences.
KEYANIM_INLINE inline void set_segments(const Image& img, Cursor::State& st, const uint32_t* curve, uint32_t lanes,
                                        float f) noexcept {
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
  // set_segment's exact_at_key, lane by lane: x - x is +0 exactly when x is finite.
  const F4 zero(0.0f);
  const uint32_t finite = sign_bits(cmp_eq(o.d - o.d, zero)) & sign_bits(cmp_eq(o.m0 - o.m0, zero)) &
                          sign_bits(cmp_eq(o.m1 - o.m1, zero));
  const uint32_t exact = finite & ~(sign_bits(cmp_eq(o.p0, zero)) & sign_bits(o.p0));
  alignas(16) float out[6][4];
  k0.store(out[0]), k1.store(out[1]), o.p0.store(out[2]), o.d.store(out[3]), o.m0.store(out[4]), o.m1.store(out[5]);
  for (uint32_t l = 0; l < lanes; ++l)
    set_segment(img, st, curve[l], f, out[0][l], out[1][l], {out[2][l], out[3][l], out[4][l], out[5][l]},
                (exact >> l) & 1);
}

// Refreshes the curves whose segment f left (`stale`, count of them): each one's stream
// first, then the operands of those inside their keys four at a time.
KEYANIM_INLINE inline void refresh(const Image& img, Cursor::State& st, const uint32_t* stale, uint32_t count,
                                   float f) noexcept {
  uint32_t inside[kRefreshBatch + 8];
  uint32_t m = 0;
  for (uint32_t j = 0; j < count; ++j)
    if (position_stream(img, st, stale[j], f)) inside[m++] = stale[j];
  if (m == 0) return;
  for (uint32_t j = m; j < ((m + 3) & ~3u); ++j) inside[j] = inside[m - 1];  // padding lanes, not stored
  for (uint32_t j = 0; j < m; j += 4) set_segments(img, st, inside + j, std::min(4u, m - j), f);
}

// The values at f of the lanes of one V (F4: 4, F8: 8) of group g from lane l.
template <class V>
KEYANIM_INLINE inline void evaluate_lanes(SegmentLanes& g, const V& f, uint32_t l) noexcept {
  const V u = segment_u(f, V::load(g.k0 + l), V::load(g.k1 + l));
  const Operands<V> o{V::load(g.p0 + l), V::load(g.d + l), V::load(g.m0 + l), V::load(g.m1 + l)};
  const V v = select(V::load_mask(g.linear + l), linear_value(o.p0, o.d, u), hermite(o, u));
  select(V::load_mask(g.direct + l), V::load(g.value + l), v).store(g.result + l);
}

template <bool kWide>
KEYANIM_INLINE inline void playback_impl(const Image& img, Cursor::State& st, float f, float* out) noexcept {
  const uint32_t n = static_cast<uint32_t>(img.curves.size());
  const F4 fv(f);
  // Which curves left their segment, 4 at a time, refreshed in batches.
  uint32_t stale[kRefreshBatch + 8];
  uint32_t count = 0;
  for (uint32_t i = 0; i < n; i += 4) {
    const SegmentLanes& g = st.lanes[i >> 3];
    for (uint32_t bits = outside(fv, F4::load(g.lo + (i & 7)), F4::load(g.hi + (i & 7))); bits != 0; bits &= bits - 1)
      stale[count++] = i + static_cast<uint32_t>(__builtin_ctz(bits));
    if (count >= kRefreshBatch || i + 4 >= n) {
      while (count > 0 && stale[count - 1] >= n) --count;  // the padding lanes past the last curve
      refresh(img, st, stale, count, f);
      count = 0;
    }
  }
  // Every group's lanes, padding included (it holds direct states).
#if KEYANIM_WIDE_LANES
  if constexpr (kWide) {
    const F8 f8(f);
    for (SegmentLanes& g : st.lanes) evaluate_lanes(g, f8, 0);
  } else
#endif
  {
    for (SegmentLanes& g : st.lanes) evaluate_lanes(g, fv, 0), evaluate_lanes(g, fv, 4);
  }
  const uint32_t* channel = img.curve_channel.data();
  const SegmentLanes* g = st.lanes.data();
  uint32_t c = 0;
  for (; c + 8 <= n; c += 8, ++g)
    for (uint32_t l = 0; l < 8; ++l) out[channel[c + l]] = g->result[l];
  for (uint32_t l = 0; c < n; ++c, ++l) out[channel[c]] = g->result[l];
  for (uint32_t k : img.fixed_channels) out[k] = img.fixed_value[k];
}

// One copy per CPU level (internal/cpu.h), 8 lanes at v3.
KEYANIM_V3_TARGET void playback_v3(const Image& img, Cursor::State& st, float f, float* out) noexcept {
  playback_impl<KEYANIM_WIDE_LANES != 0>(img, st, f, out);
}
void playback_plain(const Image& img, Cursor::State& st, float f, float* out) noexcept {
  playback_impl<false>(img, st, f, out);
}

}  // namespace

void sample_playback(const Image& img, Cursor::State& st, float f, float* out) noexcept {
  cpu_level() == CpuLevel::v3 ? playback_v3(img, st, f, out) : playback_plain(img, st, f, out);
}

}  // namespace internal
}  // namespace keyanim
