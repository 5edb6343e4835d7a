// Cursor: playback state. Each curve keeps its current segment's operands (so a position
// inside the same segments costs only the polynomial) and a stream over its record (so the
// next segment costs one key).
#include <algorithm>
#include <cmath>
#include <limits>
#include <new>

#include "internal/cpu.h"
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
    // Rounded up to whole SIMD lanes (8: the AVX2 copy's); an empty range (lo = +inf) makes
    // every curve refresh.
    const size_t n = (img.curves.size() + 7) & ~size_t(7);
    for (auto* v : {&st->hi, &st->k0, &st->p0, &st->d, &st->m0, &st->m1, &st->value, &st->result}) v->assign(n, 0.0f);
    st->lo.assign(n, std::numeric_limits<float>::infinity());
    st->k1.assign(n, 1.0f);
    st->linear.assign(n, 0u);
    st->direct.assign(n, ~0u);
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

// A state where curve i's value is `value` for lo <= f < hi.
void set_direct(Cursor::State& st, uint32_t i, float value, float lo, float hi) noexcept {
  st.lo[i] = lo, st.hi[i] = hi, st.value[i] = value;
  st.k0[i] = 0.0f, st.k1[i] = 1.0f, st.p0[i] = st.d[i] = st.m0[i] = st.m1[i] = 0.0f;
  st.linear[i] = 0u, st.direct[i] = ~0u;
}

// Curve i's state at f: clamped outside its keys; inside, its segment from the stream (a few
// keys forward in playback, a seek otherwise) with the operands of Appendix A.
void refresh(const Image& img, Cursor::State& st, uint32_t i, float f) noexcept {
  const float first = img.first_frame[i], last = img.last_frame[i];
  if (!(f > first)) return set_direct(st, i, img.first_value[i], -kInf, std::nextafter(first, kInf));
  if (f >= last) return set_direct(st, i, img.last_value[i], last, kInf);
  KeyStream& ks = st.streams[i];
  bool ok = f >= static_cast<float>(ks.k[1]) && ks.block >= 0;  // forward, in a record
  while (ok && static_cast<float>(ks.k[2]) <= f) ok = advance_stream(ks);
  if (!ok) seek_stream(img, i, f, ks);
  // Key frames are exact in binary32 (below 2^24), so u from them equals the sampler's (both
  // round f - K_j once); lengths are rounded once from the integer differences.
  const int32_t* k = ks.k;
  const float k0 = static_cast<float>(k[1]), k1 = static_cast<float>(k[2]);
  const float len = static_cast<float>(k[2] - k[1]);
  const bool adjusted = img.rule == TangentRule::step_adjusted;
  const float a0 = adjusted ? tangent_scale(len, static_cast<float>(k[1] - k[0])) : 1.0f;
  const float a1 = adjusted ? tangent_scale(len, static_cast<float>(k[3] - k[2])) : 1.0f;
  const Operands<float> o = cardinal_operands(ks.v[0], ks.v[1], ks.v[2], ks.v[3], img.curve_s[i], a0, a1);
  st.k0[i] = k0, st.k1[i] = k1, st.p0[i] = o.p0, st.d[i] = o.d, st.m0[i] = o.m0, st.m1[i] = o.m1;
  st.value[i] = o.p0;
  st.linear[i] = img.curve_linear[i];
  // At f == K_j the polynomial gives p0 + (+-0) ... = p0 exactly, as Appendix A's v_j, when the
  // operands are finite and p0 is not -0 (-0 + +0 is +0); else K_j is a direct state of its own.
  const bool exact_at_key = std::isfinite(o.d) && std::isfinite(o.m0) && std::isfinite(o.m1) &&
                            !(o.p0 == 0.0f && std::signbit(o.p0));
  if (exact_at_key) {
    st.lo[i] = k0, st.hi[i] = k1, st.direct[i] = 0u;
  } else if (f == k0) {
    st.lo[i] = k0, st.hi[i] = std::nextafter(k0, kInf), st.direct[i] = ~0u;
  } else {
    st.lo[i] = std::nextafter(k0, kInf), st.hi[i] = k1, st.direct[i] = 0u;
  }
}

// Every state's value at f, for the lanes of one V (F4: 4, F8: 8) from i.
template <class V>
KEYANIM_INLINE inline void evaluate_states(Cursor::State& st, const V& f, uint32_t i) noexcept {
  const V u = segment_u(f, V::load(&st.k0[i]), V::load(&st.k1[i]));
  const Operands<V> o{V::load(&st.p0[i]), V::load(&st.d[i]), V::load(&st.m0[i]), V::load(&st.m1[i])};
  const V v = select(V::load_mask(&st.linear[i]), linear_value(o.p0, o.d, u), hermite(o, u));
  select(V::load_mask(&st.direct[i]), V::load(&st.value[i]), v).store(&st.result[i]);
}

template <bool kWide>
KEYANIM_INLINE inline void playback_impl(const Image& img, Cursor::State& st, float f, float* out) noexcept {
  const uint32_t n = static_cast<uint32_t>(img.curves.size());
  const F4 fv(f);
  // Which curves left their segment, 4 at a time.
  for (uint32_t i = 0; i < n; i += 4) {
    uint32_t stale = outside(fv, F4::load(&st.lo[i]), F4::load(&st.hi[i]));
    for (; stale != 0; stale &= stale - 1) {
      const uint32_t c = i + static_cast<uint32_t>(__builtin_ctz(stale));
      if (c < n) refresh(img, st, c, f);
    }
  }
  uint32_t i = 0;
#if KEYANIM_WIDE_LANES
  if constexpr (kWide) {  // the states are padded to 8 lanes (Cursor::prepare)
    const F8 f8(f);
    for (; i < n; i += 8) evaluate_states(st, f8, i);
  }
#endif
  for (; i < n; i += 4) evaluate_states(st, fv, i);
  const uint32_t* channel = img.curve_channel.data();
  for (uint32_t c = 0; c < n; ++c) out[channel[c]] = st.result[c];
  for (uint32_t c : img.fixed_channels) out[c] = img.fixed_value[c];
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
