// Sampling the runtime image. Two passes over chunks of channels: a scalar pass reads each
// curve's record (image.h: read_window) and gathers the Appendix A operands, then a SIMD pass
// evaluates cardinal.h's building blocks 4 channels at a time. Both passes compute exactly
// Appendix A, so every value is bit-identical to eval_channel's (tests check every channel of
// every test vector and corpus clip).
#include "runtime/sampler.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "internal/simd.h"

namespace keyanim::internal {
namespace {

constexpr uint32_t kChunk = 32;  // a multiple of 4 (SIMD lanes)

// Pass one's output for a chunk, structure of arrays.
struct Batch {
  float k0[kChunk], k1[kChunk], len[kChunk], len_in[kChunk], len_out[kChunk];
  float pm[kChunk], p0[kChunk], p1[kChunk], p2[kChunk], s[kChunk];
  float direct_value[kChunk];
  uint32_t linear[kChunk];  // all ones: linear interpolation
  uint32_t direct[kChunk];  // all ones: the value is direct_value (clamped, at a key, fixed)

  void set_direct(uint32_t i, float v) noexcept {
    k0[i] = 0.0f, k1[i] = len[i] = len_in[i] = len_out[i] = 1.0f;
    pm[i] = p0[i] = p1[i] = p2[i] = s[i] = 0.0f;
    direct_value[i] = v;
    linear[i] = 0;
    direct[i] = ~0u;
  }
};

// Where position f falls: its block, and f relative to the block's start (exact: see below).
struct Position {
  float f;       // the position
  float rel;     // f - block start, exact (Sterbenz: the start is 0, or >= 64 and > f / 2)
  uint32_t block, t;
};

Position position(const Image& img, float f) noexcept {
  Position p;
  p.f = f;
  // Outside the clip every curve is clamped, whatever block is read; NaN never reaches here.
  const float end = static_cast<float>((img.block_count << kBlockShift) - 1);
  const float clamped = std::min(std::max(f, 0.0f), end);
  p.block = static_cast<uint32_t>(clamped) >> kBlockShift;
  const float start = static_cast<float>(p.block << kBlockShift);
  p.t = std::min(static_cast<uint32_t>(clamped - start), kBlockFrames - 1);
  p.rel = f - start;
  return p;
}

// Pass one for one curve: the case of Appendix A and the segment's operands.
template <bool kPopcnt>
[[gnu::always_inline]] inline void gather(const Image& img, uint32_t curve, const Position& at, Batch& b,
                                          uint32_t i) noexcept {
  const Curve& cv = img.curves[curve];
  Window w;
  read_window<kPopcnt>(img.record(at.block, curve), cv, at.t, w);
  // Values: q = q_base + stored, dequantized as Appendix A says (binary64 product, one rounding).
  float v[4];
  for (int k = 0; k < 4; ++k) v[k] = dequantize(cv.q_base + static_cast<int64_t>(w.value[k]), cv.step);
  b.pm[i] = v[0];
  b.p0[i] = v[1];
  b.p1[i] = v[2];
  b.p2[i] = v[3];
  // Frames relative to the block: exact integers; lengths rounded once from the integers.
  b.k0[i] = static_cast<float>(w.frame[1]);
  b.k1[i] = static_cast<float>(w.frame[2]);
  const float len = static_cast<float>(w.frame[2] - w.frame[1]);
  b.len[i] = len;
  // The uniform rule is the step-adjusted one with equal lengths (tangent_scale gives exactly 1).
  const bool adjusted = img.rule == TangentRule::step_adjusted;
  b.len_in[i] = adjusted ? static_cast<float>(w.frame[1] - w.frame[0]) : len;
  b.len_out[i] = adjusted ? static_cast<float>(w.frame[3] - w.frame[2]) : len;
  b.s[i] = cv.s;
  b.linear[i] = cv.linear ? ~0u : 0u;
  // Appendix A's cases: f <= K_0, f >= K_{n-1}, f == K_j.
  const bool before = !(at.f > cv.first_frame);
  const bool after = at.f >= cv.last_frame;
  const bool at_key = at.rel == b.k0[i];
  b.direct[i] = (before || after || at_key) ? ~0u : 0u;
  b.direct_value[i] = before ? cv.first_value : after ? cv.last_value : v[1];
}

// Pass two: Appendix A's segment value for a whole chunk, 4 lanes at a time.
void evaluate(const Batch& b, float rel, float* res) noexcept {
  const F4 f(rel);
  for (uint32_t i = 0; i < kChunk; i += 4) {
    const F4 k0 = F4::load(b.k0 + i), k1 = F4::load(b.k1 + i);
    const F4 u = segment_u(f, k0, k1);
    const F4 len = F4::load(b.len + i);
    const F4 a0 = tangent_scale(len, F4::load(b.len_in + i));
    const F4 a1 = tangent_scale(len, F4::load(b.len_out + i));
    const Operands<F4> o = cardinal_operands(F4::load(b.pm + i), F4::load(b.p0 + i), F4::load(b.p1 + i),
                                             F4::load(b.p2 + i), F4::load(b.s + i), a0, a1);
    const F4 value = select(b.linear + i, linear_value(o.p0, o.d, u), hermite(o, u));
    select(b.direct + i, F4::load(b.direct_value + i), value).store(res + i);
  }
}

// The listed channels (or all when `channels` is null) at f, out[i] for the i-th.
template <bool kPopcnt>
[[gnu::always_inline]] inline void sample_chunks(const Image& img, float f, const uint32_t* channels, uint32_t count,
                                                 float* out) noexcept {
  Batch b;
  float res[kChunk];
  const Position at = img.block_count ? position(img, f) : Position{f, f, 0, 0};
  for (uint32_t base = 0; base < count; base += kChunk) {
    const uint32_t m = std::min(kChunk, count - base);
    for (uint32_t i = 0; i < m; ++i) {
      const uint32_t c = channels[base + i];
      const uint32_t curve = img.curve_of[c];
      if (curve == kNoCurve)
        b.set_direct(i, img.fixed_value[c]);
      else
        gather<kPopcnt>(img, curve, at, b, i);
    }
    for (uint32_t i = m; i < kChunk; ++i) b.set_direct(i, 0.0f);
    evaluate(b, at.rel, res);
    std::memcpy(out + base, res, m * sizeof(float));
  }
}

// Every curve in order, written to its channel; the fixed channels separately.
template <bool kPopcnt>
[[gnu::always_inline]] inline void sample_curves(const Image& img, float f, float* out) noexcept {
  for (uint32_t c : img.fixed_channels) out[c] = img.fixed_value[c];
  const uint32_t count = static_cast<uint32_t>(img.curves.size());
  if (count == 0) return;
  Batch b;
  float res[kChunk];
  const Position at = position(img, f);
  for (uint32_t base = 0; base < count; base += kChunk) {
    const uint32_t m = std::min(kChunk, count - base);
    for (uint32_t i = 0; i < m; ++i) gather<kPopcnt>(img, base + i, at, b, i);
    for (uint32_t i = m; i < kChunk; ++i) b.set_direct(i, 0.0f);
    evaluate(b, at.rel, res);
    for (uint32_t i = 0; i < m; ++i) out[img.curves[base + i].channel] = res[i];
  }
}

// The popcnt instruction is not part of baseline x86-64: the same code is compiled twice and
// chosen once per process. Results are identical (integer operations).
#if defined(__x86_64__) && !defined(__POPCNT__)
#define KEYANIM_POPCNT_TARGET [[gnu::target("popcnt")]]
bool has_popcnt() noexcept {
  static const bool yes = __builtin_cpu_supports("popcnt");
  return yes;
}
#else
#define KEYANIM_POPCNT_TARGET
bool has_popcnt() noexcept { return true; }
#endif

KEYANIM_POPCNT_TARGET void all_popcnt(const Image& img, float f, float* out) noexcept {
  sample_curves<true>(img, f, out);
}
void all_plain(const Image& img, float f, float* out) noexcept { sample_curves<false>(img, f, out); }
KEYANIM_POPCNT_TARGET void listed_popcnt(const Image& img, float f, const uint32_t* ch, uint32_t n,
                                         float* out) noexcept {
  sample_chunks<true>(img, f, ch, n, out);
}
void listed_plain(const Image& img, float f, const uint32_t* ch, uint32_t n, float* out) noexcept {
  sample_chunks<false>(img, f, ch, n, out);
}

}  // namespace

void sample_all(const Image& img, float f, float* out) noexcept {
  has_popcnt() ? all_popcnt(img, f, out) : all_plain(img, f, out);
}

void sample_listed(const Image& img, float f, const uint32_t* channels, uint32_t count, float* out) noexcept {
  has_popcnt() ? listed_popcnt(img, f, channels, count, out) : listed_plain(img, f, channels, count, out);
}

void sample_range(const Image& img, float f, uint32_t first, uint32_t count, float* out) noexcept {
  uint32_t list[kChunk];
  for (uint32_t done = 0; done < count; done += kChunk) {
    const uint32_t m = std::min(kChunk, count - done);
    for (uint32_t i = 0; i < m; ++i) list[i] = first + done + i;
    sample_listed(img, f, list, m, out + done);
  }
}

void locate_segment(const Image& img, uint32_t curve, float f, Segment& s) noexcept {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  const Curve& cv = img.curves[curve];
  s = Segment{};
  if (!(f > cv.first_frame)) {  // clamped before the first key (f == K_0 included)
    s.lo = -kInf, s.hi = std::nextafter(cv.first_frame, kInf), s.value = cv.first_value;
    return;
  }
  if (f >= cv.last_frame) {
    s.lo = cv.last_frame, s.hi = kInf, s.value = cv.last_value;
    return;
  }
  Batch b;
  const Position at = position(img, f);
  gather<false>(img, curve, at, b, 0);  // one curve: popcount speed does not matter here
  const float start = static_cast<float>(at.block << kBlockShift);
  // Absolute key frames (exact: below 2^24), so that the segment serves positions in any block.
  const float k0 = b.k0[0] + start, k1 = b.k1[0] + start;
  s.k0 = k0, s.k1 = k1, s.hi = k1;
  s.linear = b.linear[0] != 0;
  const float a0 = tangent_scale(b.len[0], b.len_in[0]);
  const float a1 = tangent_scale(b.len[0], b.len_out[0]);
  s.o = cardinal_operands(b.pm[0], b.p0[0], b.p1[0], b.p2[0], b.s[0], a0, a1);
  // At f == K_j the polynomial gives p0 + (+-0) ... = p0 exactly, as Appendix A's v_j, when the
  // operands are finite and p0 is not -0 (-0 + +0 is +0); else K_j is a direct state of its own.
  const bool exact_at_key = std::isfinite(s.o.d) && std::isfinite(s.o.m0) && std::isfinite(s.o.m1) &&
                            !(s.o.p0 == 0.0f && std::signbit(s.o.p0));
  if (!exact_at_key && f == k0) {
    s.lo = k0, s.hi = std::nextafter(k0, kInf), s.value = s.o.p0;
    return;
  }
  s.lo = exact_at_key ? k0 : std::nextafter(k0, kInf);
  s.direct = false;
}

}  // namespace keyanim::internal
