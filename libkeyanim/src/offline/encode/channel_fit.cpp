#include "offline/encode/channel_fit.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>

namespace keyanim::offline {

int64_t quantize(double y, double step) noexcept {
  const double x = y / step;
  // std::llround without the libm call where the integer conversion is exact: truncate, then
  // round the (exactly computed) fraction half away from zero.
  if (!(std::fabs(x) < 9.0e18)) return std::llround(x);
  const int64_t t = static_cast<int64_t>(x);
  const double frac = x - static_cast<double>(t);
  return frac >= 0.5 ? t + 1 : frac <= -0.5 ? t - 1 : t;
}

namespace {

// The decoder's value of a key: the signal quantized with `step`.
float key_value(double y, double step) noexcept { return dequantize(quantize(y, step), step); }

constexpr uint32_t kShortSegment = 8;  // shorter segments skip the vectorized loop

// worst_ratio (below) of a segment longer than kShortSegment: chunks the compiler turns into
// vector instructions, the same operations on every frame (segment_u with its constants
// hoisted), then the first frame with the largest ratio. Frames are below 2^31, so converting
// them as signed gives the same floats.
[[gnu::noinline]] double worst_ratio_long(const double* y, const Tolerance& tol, const SegmentOperands& ops,
                                          uint32_t start, uint32_t end, uint32_t& arg) {
  double worst = 0.0;
  arg = start + 1;
  constexpr uint32_t kChunk = 64;
  double r[kChunk];
  const float a = static_cast<float>(start);
  const float len = static_cast<float>(end) - a;
  for (uint32_t c0 = start + 1; c0 < end; c0 += kChunk) {
    const uint32_t m = std::min(kChunk, end - c0);
    const double* yc = y + c0;
    const float* factor = tol.factor + c0;
    const int32_t first = static_cast<int32_t>(c0);
    for (uint32_t i = 0; i < m; ++i) {
      const float v = eval_operands(ops, (static_cast<float>(first + static_cast<int32_t>(i)) - a) / len);
      r[i] = std::fabs(double(v) - yc[i]) / (tol.base * double(factor[i]));
    }
    for (uint32_t i = 0; i < m; ++i)
      if (r[i] > worst) worst = r[i], arg = c0 + i;
  }
  return worst;
}

// The largest |error| / tolerance over the frames strictly inside [start, end] of the segment
// `ops`, and the first frame that has it (start + 1 if none is above 0). Most segments of a
// dense channel are a few frames long: their loop is inlined where it is called (Bandai
// walk_normal_001: 94,000 segments measured, 2 to 3 frames each).
[[gnu::always_inline]] inline double worst_ratio(const double* y, const Tolerance& tol, const SegmentOperands& ops,
                                                 uint32_t start, uint32_t end, uint32_t& arg) {
  if (end - start > kShortSegment) return worst_ratio_long(y, tol, ops, start, end, arg);
  double worst = 0.0;
  arg = start + 1;
  for (uint32_t f = start + 1; f < end; ++f) {
    const float v = eval_operands(ops, segment_u(start, end, float(f)));
    const double r = std::fabs(double(v) - y[f]) / tol.at(f);
    if (r > worst) worst = r, arg = f;
  }
  return worst;
}

// A quaternion node's error at frame f (QuatCurve): the chord between its relative rotation
// y[0..3][f] and the decoded one, x, y, z as evaluated (binary32) with w rebuilt and the whole
// normalized in binary64 (keyanim/rotation.h's arithmetic: the reference turns both alike).
[[gnu::always_inline]] inline double quat_chord(const std::array<const double*, 4>& y, uint32_t f, float x, float yy,
                                                float z) {
  const double dx = x, dy = yy, dz = z;
  const double n2 = (dx * dx + dy * dy) + dz * dz;
  const double w = n2 < 1.0 ? std::sqrt(1.0 - n2) : 0.0;
  const double scale = n2 > 1.0 ? 1.0 / std::sqrt(n2) : 1.0;  // (x, y, z, 0) normalized
  const double ex = dx * scale - y[0][f], ey = dy * scale - y[1][f], ez = dz * scale - y[2][f], ew = w - y[3][f];
  return std::sqrt(ex * ex + ey * ey + ez * ez + ew * ew);
}

// worst_ratio for a quaternion node's segment: the largest chord / tolerance over the frames
// strictly inside [start, end], and the first frame that has it.
double worst_chord(const std::array<const double*, 4>& y, const Tolerance& tol, const SegmentOperands* ops,
                   uint32_t start, uint32_t end, uint32_t& arg) {
  double worst = 0.0;
  arg = start + 1;
  for (uint32_t f = start + 1; f < end; ++f) {
    const float u = segment_u(start, end, float(f));
    const double r = quat_chord(y, f, eval_operands(ops[0], u), eval_operands(ops[1], u), eval_operands(ops[2], u)) /
                     tol.at(f);
    if (r > worst) worst = r, arg = f;
  }
  return worst;
}

// The worst ratio of a segment of `Kind` (ops: one per curve).
template <class Kind>
[[gnu::always_inline]] inline double segment_worst(const std::array<const double*, Kind::kSignals>& y, const Tolerance& tol,
                                                   const SegmentOperands* ops, uint32_t start, uint32_t end,
                                                   uint32_t& arg) {
  if constexpr (Kind::kCurves == 1) return worst_ratio(y[0], tol, ops[0], start, end, arg);
  else return worst_chord(y, tol, ops, start, end, arg);
}

// The segments a refit re-measures after its tolerances tightened at `changed` frames
// (sorted): visit(i) for each segment [keys[i], keys[i + 1]] that holds one of them, or that
// ends at one (a key's tolerance bounds the fit of the segment before it), once each, in
// order, while visit returns true. Returns false if a visit did.
template <class Visit>
bool for_each_changed_segment(const std::vector<uint32_t>& keys, const std::vector<uint32_t>& changed, Visit visit) {
  size_t last = SIZE_MAX;
  for (const uint32_t f : changed) {
    size_t i = size_t(std::upper_bound(keys.begin(), keys.end(), f) - keys.begin());  // keys[i - 1] <= f
    if (i == 0) continue;  // before the first key: no segment
    --i;
    if (keys[i] == f && i > 0) --i;
    if (i == last || i + 1 == keys.size()) continue;
    last = i;
    if (!visit(i)) return false;
  }
  return true;
}

}  // namespace

void FitScratch::prepare(size_t frames, uint32_t curves) {
  for (uint32_t k = 0; k < curves; ++k)
    if (v[k].size() != frames) v[k].assign(frames, 0.0f);
  if (prev.size() == frames) return;
  prev.assign(frames, CurveFit::kNone), next.assign(frames, CurveFit::kNone), is_key.assign(frames, 0);
  seg_ratio.assign(frames, 0.0), seg_arg.assign(frames, 0);
}

template <class Kind>
CurveFitT<Kind>::CurveFitT(Signals y, uint32_t frames, Interpolation interp, float s, TangentRule rule,
                           FitScratch& scratch)
    : y_(y), interp_(interp), s_(s), rule_(rule), w_(scratch) {
  w_.prepare(frames, kCurves);
}

template <class Kind>
CurveFitT<Kind>::~CurveFitT() {
  // Unlinking as we go leaves every frame as prepare() made it.
  for (uint32_t f = first_; f != kNone;) {
    const uint32_t next = w_.next[f];
    w_.prev[f] = w_.next[f] = kNone, w_.is_key[f] = 0;
    f = next;
  }
}

template <class Kind>
void CurveFitT<Kind>::link_keys(const std::vector<uint32_t>& keys) {
  first_ = keys.empty() ? kNone : keys.front();
  count_ = keys.size();
  for (size_t i = 0; i < keys.size(); ++i) {
    const uint32_t f = keys[i];
    w_.is_key[f] = 1;
    w_.prev[f] = i > 0 ? keys[i - 1] : kNone;
    w_.next[f] = i + 1 < keys.size() ? keys[i + 1] : kNone;
    quantize_at(f);
  }
}

template <class Kind>
void CurveFitT<Kind>::reset(const std::vector<uint32_t>& keys, Tolerance tol, double step) {
  tol_ = tol;
  step_ = step;
  recent_.clear();
  prune_all_ = true;
  link_keys(keys);
  measure_all();
}

template <class Kind>
void CurveFitT<Kind>::resume(const std::vector<uint32_t>& keys, Tolerance tol, double step, double previous_step,
                      const std::vector<uint32_t>* changed) {
  tol_ = tol;
  step_ = step;
  recent_.clear();
  prune_all_ = false;
  link_keys(keys);  // quantized at the current step: a changed step requantizes every key
  if (step != previous_step || !changed) return measure_all();
  // Every other segment was within its (unchanged) tolerance when the last fit ended.
  all_measured_ = false;  // the scratch holds other fits' ratios for them
  for_each_changed_segment(keys, *changed, [&](size_t i) {
    measure(keys[i]);
    return true;
  });
}

template <class Kind>
void CurveFitT<Kind>::quantize_at(uint32_t f) {
  for (uint32_t k = 0; k < kCurves; ++k) w_.v[k][f] = key_value(y_[k][f], step_);
}

template <class Kind>
void CurveFitT<Kind>::measure_all() {
  heap_ = {};
  all_measured_ = true;
  for (uint32_t f = first_; f != kNone && w_.next[f] != kNone; f = w_.next[f]) measure(f);
}

template <class Kind>
void CurveFitT<Kind>::measure(uint32_t start, bool push) {
  // The decoder's arithmetic on the (up to) four keys around the segment [start, end]: the
  // same end-point duplication as eval_segment applies where the list ends.
  const uint32_t end = w_.next[start], p = w_.prev[start], n = w_.next[end];
  SegmentOperands ops[kCurves];
  for (uint32_t k = 0; k < kCurves; ++k) {
    const std::vector<float>& v = w_.v[k];
    const Key before{p, p != kNone ? v[p] : 0.0f}, after{n, n != kNone ? v[n] : 0.0f};
    ops[k] = window_operands(p != kNone ? &before : nullptr, {start, v[start]}, {end, v[end]},
                             n != kNone ? &after : nullptr, interp_, s_, rule_);
  }
  uint32_t arg = 0;
  const double worst = segment_worst<Kind>(y_, tol_, ops, start, end, arg);
  w_.seg_ratio[start] = worst, w_.seg_arg[start] = arg;
  if (push && worst > 1.0) heap_.push({worst, start, end});
}

template <class Kind>
void CurveFitT<Kind>::link(uint32_t f, uint32_t a, uint32_t b) {
  w_.is_key[f] = 1, w_.prev[f] = a, w_.next[f] = b, w_.next[a] = f, w_.prev[b] = f;
  ++count_;
}

template <class Kind>
void CurveFitT<Kind>::unlink(uint32_t f) {
  const uint32_t a = w_.prev[f], b = w_.next[f];
  w_.next[a] = b, w_.prev[b] = a, w_.is_key[f] = 0, w_.prev[f] = w_.next[f] = kNone;
  --count_;
}

template <class Kind>
void CurveFitT<Kind>::refine() {
  while (!heap_.empty()) {
    const Entry e = heap_.top();
    heap_.pop();
    if (!w_.is_key[e.start] || w_.next[e.start] != e.end || w_.seg_ratio[e.start] != e.ratio) continue;  // stale
    if (e.ratio <= 1.0) continue;
    // A new key changes the four segments whose window holds it: [p, a], [a, f], [f, b], [b, c].
    const uint32_t a = e.start, b = e.end, f = w_.seg_arg[a];
    quantize_at(f);
    link(f, a, b);
    recent_.push_back(f);
    if (w_.prev[a] != kNone) measure_neighbour(w_.prev[a]);
    measure(a), measure(f);
    if (w_.next[b] != kNone) measure_neighbour(b);
  }
}

template <class Kind>
void CurveFitT<Kind>::measure_neighbour(uint32_t start) {
  if (!neighbours_stand()) return measure(start);
  if (w_.seg_ratio[start] > 1.0) heap_.push({w_.seg_ratio[start], start, w_.next[start]});  // as measure() would
}

template <class Kind>
void CurveFitT<Kind>::prune() {
  if (first_ == kNone) return;
  if (prune_all_) {
    for (uint32_t f = w_.next[first_]; f != kNone && w_.next[f] != kNone;) {
      const uint32_t b = w_.next[f];
      try_remove(f);
      f = b;
    }
    prune_all_ = false;
  } else {
    // Only keys near the new ones can have become unnecessary.
    for (uint32_t f : recent_) {
      if (!w_.is_key[f]) continue;
      const uint32_t a = w_.prev[f], b = w_.next[f];
      for (uint32_t g : {a, f, b})
        if (g != kNone && w_.is_key[g] && g != first_ && w_.next[g] != kNone) try_remove(g);
    }
  }
  recent_.clear();
}

// Removes interior key f if every segment it affects stays within tolerance without it.
template <class Kind>
bool CurveFitT<Kind>::try_remove(uint32_t f) {
  // Without f, the segments starting at p = prev(a), a and b change; f's own disappears.
  const uint32_t a = w_.prev[f], b = w_.next[f], p = w_.prev[a];
  const uint32_t starts[4] = {p, a, f, b};
  double ratios[4];
  uint32_t args[4];
  for (int t = 0; t < 4; ++t)
    if (starts[t] != kNone) ratios[t] = w_.seg_ratio[starts[t]], args[t] = w_.seg_arg[starts[t]];
  unlink(f);
  bool ok = true;
  for (uint32_t s : {p, a, b}) {
    if (!ok || s == kNone || w_.next[s] == kNone) continue;
    if (s == a || !neighbours_stand()) measure(s, false);  // on success every ratio is <= 1: nothing for the heap
    ok = w_.seg_ratio[s] <= 1.0;
  }
  if (ok) return true;
  link(f, a, b);
  for (int t = 0; t < 4; ++t)
    if (starts[t] != kNone) w_.seg_ratio[starts[t]] = ratios[t], w_.seg_arg[starts[t]] = args[t];
  return false;
}

template <class Kind>
float CurveFitT<Kind>::best_s() const requires(Kind::kCurves == 1) {
  double num = 0.0, den = 0.0;
  const auto& next = w_.next;
  const auto& prev = w_.prev;
  const auto& val = w_.v[0];
  const double* y = y_[0];
  for (uint32_t a = first_; a != kNone && next[a] != kNone; a = next[a]) {
    const uint32_t b = next[a], pm = prev[a] != kNone ? prev[a] : a, c = next[b] != kNone ? next[b] : b;
    const double p0 = val[a], p1 = val[b], vm = val[pm], p2 = val[c];
    double a0 = 1.0, a1 = 1.0;
    const double len = b - a;
    if (rule_ == TangentRule::step_adjusted) {
      if (pm != a) a0 = 2.0 * len / (a - pm + len);
      if (c != b) a1 = 2.0 * len / (len + c - b);
    }
    for (uint32_t f = a + 1; f < b; ++f) {
      const double u = (f - a) / len, u2 = u * u, u3 = u2 * u;
      const double base = (2 * u3 - 3 * u2 + 1) * p0 + (-2 * u3 + 3 * u2) * p1;
      const double slope = (u3 - 2 * u2 + u) * a0 * (p1 - vm) + (u3 - u2) * a1 * (p2 - p0);
      num += slope * (y[f] - base);
      den += slope * slope;
    }
  }
  if (!(den > 0.0)) return s_;
  return float(std::clamp(num / den, 0.0, 1.0));
}

template <class Kind>
std::vector<uint32_t> CurveFitT<Kind>::take_keys() {
  std::vector<uint32_t> out(count_);
  size_t i = 0;
  for (uint32_t f = first_; f != kNone; ++i) {
    const uint32_t next = w_.next[f];
    out[i] = f;
    w_.prev[f] = w_.next[f] = kNone, w_.is_key[f] = 0;
    f = next;
  }
  first_ = kNone, count_ = 0;
  return out;
}

template class CurveFitT<ChannelCurve>;
template class CurveFitT<QuatCurve>;

namespace {

std::vector<uint32_t> end_keys(size_t frames) {
  if (frames == 0) return {};
  if (frames == 1) return {0};
  return {0, uint32_t(frames - 1)};
}

EncodedChannel channel_at(const double* y, Interpolation interp, float tension, double step,
                          const std::vector<uint32_t>& keys) {
  EncodedChannel ch;
  ch.interp = interp;
  ch.tension = tension;
  ch.step = step;
  ch.q.resize(keys.size());
  for (size_t i = 0; i < keys.size(); ++i) ch.q[i] = quantize(y[keys[i]], step);
  ch.frames = keys;
  return ch;
}

// A fit's result at `keys`: the channel, or a quaternion node's three.
template <class Kind>
typename CurveFitter<Kind>::Result result_at(const typename CurveFitT<Kind>::Signals& y, Interpolation interp,
                                             float tension, double step, const std::vector<uint32_t>& keys) {
  if constexpr (Kind::kCurves == 1) {
    return channel_at(y[0], interp, tension, step, keys);
  } else {
    return {channel_at(y[0], interp, tension, step, keys), channel_at(y[1], interp, tension, step, keys),
            channel_at(y[2], interp, tension, step, keys)};
  }
}

}  // namespace

std::optional<EncodedChannel> constant_channel(const double* y, uint32_t frames, double lo, double hi,
                                               Tolerance tol, double step) {
  // The largest power of two up to the step before the step: one key pays nothing for a finer
  // step, and steps that repeat from channel to channel make CHAN compress (a 173-joint
  // one-frame clip: 1.2 KB of steps become 0.2 KB). A channel without keys stores it too (its
  // step means nothing); no key at all is tried first.
  const double power_of_two = std::ldexp(1.0, std::ilogb(step));
  auto within = [&](float v) {
    uint32_t f = 0;
    while (f < frames && std::fabs(double(v) - y[f]) <= tol.at(f)) ++f;
    return f == frames;
  };
  EncodedChannel ch;
  ch.step = power_of_two;
  if (within(0.0f)) return ch;
  for (const double s : {power_of_two, step}) {
    const int64_t q = quantize(0.5 * (lo + hi), s);
    if (!within(dequantize(q, s))) continue;
    if (q != 0) ch.frames = {0}, ch.q = {q}, ch.step = s;
    return ch;
  }
  return std::nullopt;
}

std::optional<std::array<EncodedChannel, 3>> constant_quat(const QuatFit::Signals& y, uint32_t frames,
                                                           const double* lo, const double* hi, Tolerance tol,
                                                           double step) {
  // As constant_channel: no key (the reference itself) first, then one key at each curve's
  // middle, with the largest power of two up to the step, then the step. The three curves
  // share their key frames: all have the key, or none.
  const double power_of_two = std::ldexp(1.0, std::ilogb(step));
  auto within = [&](const float (&v)[3]) {
    uint32_t f = 0;
    while (f < frames && quat_chord(y, f, v[0], v[1], v[2]) <= tol.at(f)) ++f;
    return f == frames;
  };
  std::array<EncodedChannel, 3> out;
  for (EncodedChannel& ch : out) ch.step = power_of_two;
  if (within({0.0f, 0.0f, 0.0f})) return out;
  for (const double s : {power_of_two, step}) {
    int64_t q[3];
    float v[3];
    for (int k = 0; k < 3; ++k) q[k] = quantize(0.5 * (lo[k] + hi[k]), s), v[k] = dequantize(q[k], s);
    if (!within(v)) continue;
    for (int k = 0; k < 3; ++k) out[size_t(k)].frames = {0}, out[size_t(k)].q = {q[k]}, out[size_t(k)].step = s;
    return out;
  }
  return std::nullopt;
}

EncodedChannel fit_channel_at_keys(const std::vector<double>& y, const std::vector<uint32_t>& keys, Tolerance tol,
                                   double step, const ChannelFitOptions& opt, FitScratch& scratch) {
  const uint32_t n = uint32_t(y.size());
  if (n > 0) {
    const auto [lo, hi] = std::minmax_element(y.begin(), y.end());
    if (auto c = constant_channel(y.data(), n, *lo, *hi, tol, step)) return *c;
  }
  const Interpolation interp = opt.force_linear ? Interpolation::linear : Interpolation::cardinal;
  float tension = opt.tension;
  if (opt.fit_tension && !opt.force_linear) {
    CurveFit curve({y.data()}, n, interp, tension_to_s(opt.tension), opt.rule, scratch);
    curve.reset(keys, tol, step);
    tension = s_to_tension(curve.best_s());
  }
  return channel_at(y.data(), interp, tension, step, keys);
}

std::array<EncodedChannel, 3> fit_quat_at_keys(const std::vector<uint32_t>& keys, Tolerance tol, double step,
                                               const ChannelFitOptions& opt, FitScratch& scratch) {
  const QuatFit::Signals y = scratch.signals<QuatCurve>();
  const uint32_t n = uint32_t(scratch.q[0].size());
  if (n > 0) {
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
      const auto [a, b] = std::minmax_element(scratch.q[size_t(k)].begin(), scratch.q[size_t(k)].end());
      lo[k] = *a, hi[k] = *b;
    }
    if (auto c = constant_quat(y, n, lo, hi, tol, step)) return *c;
  }
  // No tension is fitted for three curves at once: the given one.
  const Interpolation interp = opt.force_linear ? Interpolation::linear : Interpolation::cardinal;
  return result_at<QuatCurve>(y, interp, opt.tension, step, keys);
}

template <class Kind>
typename CurveFitter<Kind>::Result CurveFitter<Kind>::fit(Tolerance tol, double step,
                                                          const std::vector<uint32_t>* changed, FitScratch& scratch) {
  constexpr uint32_t kCurves = Kind::kCurves;
  const typename CurveFitT<Kind>::Signals y = scratch.signals<Kind>();
  const uint32_t n = uint32_t(kCurves == 1 ? scratch.y.size() : scratch.q[0].size());
  if (!have_extent_ && n > 0) {
    for (uint32_t k = 0; k < kCurves; ++k) {
      const auto [lo, hi] = std::minmax_element(y[k], y[k] + n);
      lo_[k] = *lo, hi_[k] = *hi;
    }
    have_extent_ = true;
  }
  fitted_ = false;
  if constexpr (kCurves == 1) {
    if (auto c = constant_channel(y[0], n, lo_[0], hi_[0], tol, step)) return *c;
  } else {
    if (auto c = constant_quat(y, n, lo_, hi_, tol, step)) return *c;
  }
  if (candidates_.empty()) {
    const std::vector<uint32_t> ends = end_keys(n);
    auto add = [&](Interpolation interp, float tension, float* best_s = nullptr) {
      CurveFitT<Kind> c(y, n, interp, tension_to_s(tension), opt_.rule, scratch);
      c.reset(ends, tol, step);
      c.refine();
      c.prune();
      if constexpr (kCurves == 1) {
        if (best_s) *best_s = c.best_s();
      }
      candidates_.push_back({interp, tension, step, c.take_keys()});
    };
    if (opt_.force_linear) {
      add(Interpolation::linear, opt_.tension);
    } else {
      // A fitted tension is kept only if it is cheaper (keep_fewest). Not for three curves at
      // once.
      const bool fit_tension = opt_.fit_tension && kCurves == 1;
      float s = 0.0f;
      add(Interpolation::cardinal, opt_.tension, fit_tension ? &s : nullptr);
      if (fit_tension) add(Interpolation::cardinal, s_to_tension(s));
      if (opt_.allow_linear) add(Interpolation::linear, opt_.tension);
    }
  } else {
    for (Candidate& c : candidates_) {
      CurveFitT<Kind> f(y, n, c.interp, tension_to_s(c.tension), opt_.rule, scratch);
      f.resume(c.keys, tol, step, c.step, changed);
      f.refine();
      f.prune();
      c.keys = f.take_keys();
      c.step = step;
    }
  }
  keep_fewest();
  fitted_ = true;
  const Candidate& b = candidates_.front();  // the first of a tie, as before any was dropped
  return result_at<Kind>(y, b.interp, b.tension, b.step, b.keys);
}

template <class Kind>
bool CurveFitter<Kind>::holds(Tolerance tol, double step, const std::vector<uint32_t>& changed,
                              const typename CurveFitT<Kind>::Signals& y) const {
  if (!fitted_) return false;
  for (const Candidate& c : candidates_)
    if (c.step != step || !segments_within(c, y, tol, changed)) return false;
  return true;
}

// The segments CurveFitT::resume re-measures, with measure()'s arithmetic.
template <class Kind>
bool CurveFitter<Kind>::segments_within(const Candidate& c, const typename CurveFitT<Kind>::Signals& y, Tolerance tol,
                                        const std::vector<uint32_t>& changed) const {
  const std::vector<uint32_t>& k = c.keys;
  const float s = tension_to_s(c.tension);
  return for_each_changed_segment(k, changed, [&](size_t i) {
    SegmentOperands ops[Kind::kCurves];
    for (uint32_t m = 0; m < Kind::kCurves; ++m) {
      const double* ym = y[m];
      const Key a{k[i], key_value(ym[k[i]], c.step)}, b{k[i + 1], key_value(ym[k[i + 1]], c.step)};
      const Key before = i > 0 ? Key{k[i - 1], key_value(ym[k[i - 1]], c.step)} : Key{};
      const Key after = i + 2 < k.size() ? Key{k[i + 2], key_value(ym[k[i + 2]], c.step)} : Key{};
      ops[m] = window_operands(i > 0 ? &before : nullptr, a, b, i + 2 < k.size() ? &after : nullptr, c.interp, s,
                               opt_.rule);
    }
    uint32_t arg = 0;
    return segment_worst<Kind>(y, tol, ops, k[i], k[i + 1], arg) <= 1.0;
  });
}

template <class Kind>
void CurveFitter<Kind>::keep_fewest() {
  size_t fewest = candidates_.front().keys.size();
  for (const Candidate& c : candidates_) fewest = std::min(fewest, c.keys.size());
  std::erase_if(candidates_, [&](const Candidate& c) { return c.keys.size() > fewest; });
}

template class CurveFitter<ChannelCurve>;
template class CurveFitter<QuatCurve>;

}  // namespace keyanim::offline
