#include "offline/channel_fit.h"

#include <algorithm>
#include <cmath>
#include <optional>

namespace keyanim::offline {
CurveFit::CurveFit(const std::vector<double>& y, Interpolation interp, float s, TangentRule rule)
    : y_(&y), interp_(interp), s_(s), rule_(rule) {}

void CurveFit::reset(const std::vector<uint32_t>& keys, const std::vector<double>& tol, double step) {
  tol_ = &tol;
  step_ = step;
  const size_t n = y_->size();
  prev_.assign(n, kNone), next_.assign(n, kNone), is_key_.assign(n, 0);
  q_.assign(n, 0), v_.assign(n, 0.0f), seg_ratio_.assign(n, 0.0), seg_arg_.assign(n, 0);
  first_ = keys.empty() ? kNone : keys.front();
  count_ = keys.size();
  recent_.clear();
  prune_all_ = true;
  for (size_t i = 0; i < keys.size(); ++i) {
    const uint32_t f = keys[i];
    is_key_[f] = 1;
    prev_[f] = i > 0 ? keys[i - 1] : kNone;
    next_[f] = i + 1 < keys.size() ? keys[i + 1] : kNone;
    quantize(f);
  }
  measure_all();
}

void CurveFit::retarget(const std::vector<double>& tol, double step, const std::vector<uint32_t>* changed) {
  tol_ = &tol;
  if (step != step_ || !changed) {
    if (step != step_) {
      step_ = step;
      for (uint32_t f = first_; f != kNone; f = next_[f]) quantize(f);
    }
    measure_all();
    return;
  }
  uint32_t last = kNone;  // changed frames are sorted: measure each segment once
  for (uint32_t f : *changed) {
    uint32_t s = f;
    while (s != 0 && !is_key_[s]) --s;
    if (s == f && is_key_[f] && f != first_) s = prev_[f];  // a key's tolerance bounds its neighbours' fits
    if (s == last || next_[s] == kNone) continue;
    measure(s);
    last = s;
  }
}

void CurveFit::quantize(uint32_t f) {
  q_[f] = std::llround((*y_)[f] / step_);
  v_[f] = dequantize(q_[f], step_);
}

void CurveFit::measure_all() {
  heap_ = {};
  for (uint32_t f = first_; f != kNone && next_[f] != kNone; f = next_[f]) measure(f);
}

void CurveFit::measure(uint32_t start, bool push) {
  // The decoder's arithmetic on the (up to) four keys around the segment [start, end]: the
  // same end-point duplication as eval_segment applies where the list ends.
  const uint32_t end = next_[start];
  uint32_t frames[4];
  float values[4];
  uint32_t n = 0, j = 0;
  if (prev_[start] != kNone) frames[n] = prev_[start], values[n++] = v_[prev_[start]], j = 1;
  frames[n] = start, values[n++] = v_[start];
  frames[n] = end, values[n++] = v_[end];
  if (next_[end] != kNone) frames[n] = next_[end], values[n++] = v_[next_[end]];
  const SegmentOperands ops = segment_operands(frames, values, n, j, interp_, s_, rule_);
  double worst = 0.0;
  uint32_t arg = start + 1;
  for (uint32_t f = start + 1; f < end; ++f) {
    const float v = eval_operands(ops, segment_u(start, end, float(f)));
    const double r = std::fabs(double(v) - (*y_)[f]) / (*tol_)[f];
    if (r > worst) worst = r, arg = f;
  }
  seg_ratio_[start] = worst, seg_arg_[start] = arg;
  if (push && worst > 1.0) heap_.push({worst, start, end});
}

void CurveFit::link(uint32_t f, uint32_t a, uint32_t b) {
  is_key_[f] = 1, prev_[f] = a, next_[f] = b, next_[a] = f, prev_[b] = f;
  ++count_;
}

void CurveFit::unlink(uint32_t f) {
  const uint32_t a = prev_[f], b = next_[f];
  next_[a] = b, prev_[b] = a, is_key_[f] = 0, prev_[f] = next_[f] = kNone;
  --count_;
}

void CurveFit::refine() {
  while (!heap_.empty()) {
    const Entry e = heap_.top();
    heap_.pop();
    if (!is_key_[e.start] || next_[e.start] != e.end || seg_ratio_[e.start] != e.ratio) continue;  // stale
    if (e.ratio <= 1.0) continue;
    // A new key changes the four segments whose window holds it: [p, a], [a, f], [f, b], [b, c].
    const uint32_t a = e.start, b = e.end, f = seg_arg_[a];
    quantize(f);
    link(f, a, b);
    recent_.push_back(f);
    if (prev_[a] != kNone) measure(prev_[a]);
    measure(a), measure(f);
    if (next_[b] != kNone) measure(b);
  }
}

void CurveFit::prune() {
  if (first_ == kNone) return;
  if (prune_all_) {
    for (uint32_t f = next_[first_]; f != kNone && next_[f] != kNone;) {
      const uint32_t b = next_[f];
      try_remove(f);
      f = b;
    }
    prune_all_ = false;
  } else {
    // Only keys near the new ones can have become unnecessary.
    for (uint32_t f : recent_) {
      if (!is_key_[f]) continue;
      const uint32_t a = prev_[f], b = next_[f];
      for (uint32_t g : {a, f, b})
        if (g != kNone && is_key_[g] && g != first_ && next_[g] != kNone) try_remove(g);
    }
  }
  recent_.clear();
}

// Removes interior key f if every segment it affects stays within tolerance without it.
bool CurveFit::try_remove(uint32_t f) {
  // Without f, the segments starting at p = prev(a), a and b change; f's own disappears.
  const uint32_t a = prev_[f], b = next_[f], p = prev_[a];
  const uint32_t starts[4] = {p, a, f, b};
  double ratios[4];
  uint32_t args[4];
  for (int t = 0; t < 4; ++t)
    if (starts[t] != kNone) ratios[t] = seg_ratio_[starts[t]], args[t] = seg_arg_[starts[t]];
  unlink(f);
  bool ok = true;
  for (uint32_t s : {p, a, b}) {
    if (!ok || s == kNone || next_[s] == kNone) continue;
    measure(s, false);  // on success every ratio is <= 1: nothing for the heap
    ok = seg_ratio_[s] <= 1.0;
  }
  if (ok) return true;
  link(f, a, b);
  for (int t = 0; t < 4; ++t)
    if (starts[t] != kNone) seg_ratio_[starts[t]] = ratios[t], seg_arg_[starts[t]] = args[t];
  return false;
}

float CurveFit::best_s() const {
  double num = 0.0, den = 0.0;
  for (uint32_t a = first_; a != kNone && next_[a] != kNone; a = next_[a]) {
    const uint32_t b = next_[a], pm = prev_[a] != kNone ? prev_[a] : a, c = next_[b] != kNone ? next_[b] : b;
    const double p0 = v_[a], p1 = v_[b], vm = v_[pm], p2 = v_[c];
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
      num += slope * ((*y_)[f] - base);
      den += slope * slope;
    }
  }
  if (!(den > 0.0)) return s_;
  return float(std::clamp(num / den, 0.0, 1.0));
}

EncodedChannel CurveFit::result(float tension) const {
  EncodedChannel ch;
  ch.interp = interp_;
  ch.tension = tension;
  ch.step = step_;
  for (uint32_t f = first_; f != kNone; f = next_[f]) ch.frames.push_back(f), ch.q.push_back(q_[f]);
  return ch;
}

namespace {

std::vector<uint32_t> end_keys(size_t frames) {
  if (frames == 0) return {};
  if (frames == 1) return {0};
  return {0, uint32_t(frames - 1)};
}

}  // namespace

std::optional<EncodedChannel> constant_channel(const std::vector<double>& y, const std::vector<double>& tol,
                                               double step) {
  EncodedChannel ch;
  ch.step = step;
  if (y.empty()) return ch;
  const auto [lo, hi] = std::minmax_element(y.begin(), y.end());
  const int64_t q = std::llround(0.5 * (*lo + *hi) / step);
  const float v = dequantize(q, step);
  for (size_t f = 0; f < y.size(); ++f)
    if (!(std::fabs(double(v) - y[f]) <= tol[f])) return std::nullopt;
  if (q != 0) ch.frames = {0}, ch.q = {q};
  return ch;
}

EncodedChannel fit_channel_at_keys(const std::vector<double>& y, const std::vector<uint32_t>& keys,
                                   const std::vector<double>& tol, double step, const ChannelFitOptions& opt) {
  if (auto c = constant_channel(y, tol, step)) return *c;
  const Interpolation interp = opt.force_linear ? Interpolation::linear : Interpolation::cardinal;
  CurveFit curve(y, interp, tension_to_s(opt.tension), opt.rule);
  curve.reset(keys, tol, step);
  if (!opt.fit_tension || opt.force_linear) return curve.result(opt.tension);
  const float t = s_to_tension(curve.best_s());
  CurveFit fitted(y, interp, tension_to_s(t), opt.rule);
  fitted.reset(keys, tol, step);
  return fitted.result(t);
}

ChannelFitter::ChannelFitter(const std::vector<double>& y, const ChannelFitOptions& options)
    : y_(&y), opt_(options) {}

EncodedChannel ChannelFitter::fit(const std::vector<double>& tol, double step, const std::vector<uint32_t>* changed) {
  if (auto c = constant_channel(*y_, tol, step)) return *c;
  if (candidates_.empty()) {
    const std::vector<uint32_t> ends = end_keys(y_->size());
    auto add = [&](Interpolation interp, float tension) {
      candidates_.emplace_back(*y_, interp, tension_to_s(tension), opt_.rule);
      tensions_.push_back(tension);
      CurveFit& c = candidates_.back();
      c.reset(ends, tol, step);
      c.refine();
      c.prune();
    };
    if (opt_.force_linear) {
      add(Interpolation::linear, opt_.tension);
    } else {
      add(Interpolation::cardinal, opt_.tension);
      // A fitted tension is kept only if it ends up cheaper (checked at every fit below).
      if (opt_.fit_tension) add(Interpolation::cardinal, s_to_tension(candidates_[0].best_s()));
      if (opt_.allow_linear) add(Interpolation::linear, opt_.tension);
    }
  } else {
    for (CurveFit& c : candidates_) {
      c.retarget(tol, step, changed);
      c.refine();
      c.prune();
    }
  }
  size_t best = 0;
  for (size_t i = 1; i < candidates_.size(); ++i)
    if (candidates_[i].key_count() < candidates_[best].key_count()) best = i;
  return candidates_[best].result(tensions_[best]);
}

}  // namespace keyanim::offline
