// Cursor: playback state. Each curve keeps its current segment's operands (so a position
// inside the same segments costs only the polynomial) and a stream over its record (so the
// next segment costs one key).
#include <algorithm>
#include <limits>
#include <new>

#include "internal/simd.h"
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
    // Rounded up to whole SIMD lanes; an empty range (lo = +inf) makes every curve refresh.
    const size_t n = (img.curves.size() + 3) & ~size_t(3);
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

void store(Cursor::State& st, uint32_t i, const Segment& s) noexcept {
  st.lo[i] = s.lo, st.hi[i] = s.hi, st.k0[i] = s.k0, st.k1[i] = s.k1;
  st.p0[i] = s.o.p0, st.d[i] = s.o.d, st.m0[i] = s.o.m0, st.m1[i] = s.o.m1, st.value[i] = s.value;
  st.linear[i] = s.linear ? ~0u : 0u;
  st.direct[i] = s.direct ? ~0u : 0u;
}

// Curve i's segment at f: a few keys forward on its stream in playback, a seek otherwise.
void refresh(const Image& img, Cursor::State& st, uint32_t i, float f) noexcept {
  Segment s;
  if (clamped_segment(img, i, f, s)) return store(st, i, s);
  KeyStream& ks = st.streams[i];
  bool ok = f >= static_cast<float>(ks.k[1]) && ks.block >= 0;  // forward, in a record
  while (ok && static_cast<float>(ks.k[2]) <= f) ok = advance_stream(ks);
  if (!ok) seek_stream(img, i, f, ks);
  stream_segment(img, i, ks, f, s);
  store(st, i, s);
}

}  // namespace

void sample_playback(const Image& img, Cursor::State& st, float f, float* out) noexcept {
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
  for (uint32_t i = 0; i < n; i += 4) {
    const F4 u = segment_u(fv, F4::load(&st.k0[i]), F4::load(&st.k1[i]));
    const Operands<F4> o{F4::load(&st.p0[i]), F4::load(&st.d[i]), F4::load(&st.m0[i]), F4::load(&st.m1[i])};
    const F4 v = select(F4::load_mask(&st.linear[i]), linear_value(o.p0, o.d, u), hermite(o, u));
    select(F4::load_mask(&st.direct[i]), F4::load(&st.value[i]), v).store(&st.result[i]);
  }
  for (uint32_t i = 0; i < n; ++i) out[img.curves[i].channel] = st.result[i];
  for (uint32_t c : img.fixed_channels) out[c] = img.fixed_value[c];
}

}  // namespace internal
}  // namespace keyanim
