// Fitting one channel: the quantizer, the fits' guarantee checked with the runtime's own
// evaluation, refits that continue from the keys, and the scratch a fit leaves behind.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "offline/encode/channel_fit.h"

using namespace keyanim;
using namespace keyanim::offline;

namespace {

// Largest |decoded - y| / tol over the frames, decoding with eval_channel (cardinal.h).
double worst_ratio(const EncodedChannel& ch, const std::vector<double>& y, Tolerance tol, TangentRule rule) {
  std::vector<float> v;
  for (int64_t q : ch.q) v.push_back(dequantize(q, ch.step));
  double worst = 0.0;
  for (uint32_t f = 0; f < y.size(); ++f) {
    const float d = eval_channel(ch.frames.data(), v.data(), uint32_t(v.size()), float(f), ch.interp,
                                 tension_to_s(ch.tension), rule);
    worst = std::max(worst, std::fabs(double(d) - y[f]) / tol.at(f));
  }
  return worst;
}

std::vector<double> wavy(uint32_t frames, double phase) {
  std::vector<double> y(frames);
  for (uint32_t f = 0; f < frames; ++f) y[f] = 30.0 * std::sin(0.03 * f + phase) + 4.0 * std::sin(0.31 * f);
  return y;
}

bool scratch_clean(const FitScratch& s) {
  for (size_t f = 0; f < s.prev.size(); ++f)
    if (s.prev[f] != CurveFit::kNone || s.next[f] != CurveFit::kNone || s.is_key[f]) return false;
  return true;
}

}  // namespace

TEST_SUITE("channel_fit") {
  TEST_CASE("quantize is std::llround of y / step") {
    std::mt19937_64 rng(3);
    const double specials[] = {0.5, -0.5, 1.5, -2.5, 0.49999999999999994, -0.49999999999999994,
                               4503599627370495.5, 9007199254740993.0, 1e18, -1e18, 0.0, -0.0, 1e-300};
    for (double x : specials) CHECK(quantize(x, 1.0) == std::llround(x));
    int wrong = 0;
    for (int i = 0; i < 1000000; ++i) {
      uint64_t bits = rng();
      double x;
      std::memcpy(&x, &bits, sizeof x);
      if (!std::isfinite(x) || std::fabs(x) > 1e18) x = double(int64_t(rng() % 2000001) - 1000000) + 0.5;
      const double step = 0.001 * double(1 + rng() % 1000);
      wrong += quantize(x, step) != std::llround(x / step);
    }
    CHECK(wrong == 0);
  }

  TEST_CASE("a fit keeps every frame within its tolerance and leaves its scratch clean") {
    const std::vector<double> y = wavy(500, 0.3);
    std::vector<float> factor(500, 1.0f);
    for (uint32_t f = 200; f < 260; ++f) factor[f] = 0.1f;  // tighter in the middle
    const Tolerance tol{0.05, factor.data()};
    for (bool linear : {false, true}) {
      ChannelFitOptions opt;
      opt.force_linear = linear;
      ChannelFitter fitter(opt);
      FitScratch scratch;
      scratch.y = y;
      // The step the encoder would pick: within 1.5 of the smallest tolerance (0.005), so that a
      // key's own rounding stays inside its budget.
      const EncodedChannel ch = fitter.fit(tol, 0.075 / 16, nullptr, scratch);
      CHECK(ch.interp == (linear ? Interpolation::linear : Interpolation::cardinal));
      CHECK(worst_ratio(ch, y, tol, TangentRule::step_adjusted) <= 1.0);
      CHECK(ch.frames.size() > 2);
      CHECK(ch.frames.size() < 450);  // far fewer keys than frames
      CHECK(scratch_clean(scratch));
    }
  }

  TEST_CASE("a refit continues from its keys: knowing where budgets changed gives the same keys") {
    const std::vector<double> y = wavy(800, 1.1);
    std::vector<float> factor(800, 1.0f);
    const Tolerance tol{0.02, factor.data()};
    ChannelFitter a{ChannelFitOptions{}}, b{ChannelFitOptions{}};
    FitScratch scratch;
    scratch.y = y;
    const EncodedChannel first = a.fit(tol, 0.03, nullptr, scratch);
    CHECK(b.fit(tol, 0.03, nullptr, scratch).frames == first.frames);
    // Tighten a few frames, then refit: once told where, once not (every segment re-measured).
    std::vector<uint32_t> changed{100, 101, 102, 450, 451, 799};
    for (uint32_t f : changed) factor[f] = 0.8f;  // the step 0.03 stays within 1.5 of the tolerance
    const EncodedChannel told = a.fit(tol, 0.03, &changed, scratch);
    const EncodedChannel not_told = b.fit(tol, 0.03, nullptr, scratch);
    CHECK(told.frames == not_told.frames);
    CHECK(told.q == not_told.q);
    CHECK(worst_ratio(told, y, tol, TangentRule::step_adjusted) <= 1.0);
    CHECK(told.frames.size() >= first.frames.size());
    // Tighter still, with a smaller step: every key is requantized.
    for (uint32_t f : changed) factor[f] = 0.3f;
    const EncodedChannel finer = a.fit(tol, 0.0075, &changed, scratch);
    CHECK(finer.step == 0.0075);
    CHECK(worst_ratio(finer, y, tol, TangentRule::step_adjusted) <= 1.0);
    CHECK(scratch_clean(scratch));
  }

  TEST_CASE("holds() is true exactly when a refit would return the channel as it is") {
    const std::vector<double> y = wavy(800, 1.1);
    std::vector<float> factor(800, 1.0f);
    const Tolerance tol{0.02, factor.data()};
    ChannelFitter fitted{ChannelFitOptions{}};
    FitScratch scratch;
    scratch.y = y;
    const EncodedChannel first = fitted.fit(tol, 0.03, nullptr, scratch);
    // Random tightenings of a few frames, each on a copy of the fitter: holds() against what
    // the refit (the path it replaces) returns.
    std::mt19937 rng(11);
    int held = 0, refitted = 0;
    for (int trial = 0; trial < 300; ++trial) {
      std::vector<float> tighter(800, 1.0f);
      std::vector<uint32_t> changed;
      for (int k = 0; k < 3; ++k) changed.push_back(uint32_t(rng() % 800));
      std::sort(changed.begin(), changed.end());
      changed.erase(std::unique(changed.begin(), changed.end()), changed.end());
      for (uint32_t f : changed) tighter[f] = 0.2f + 0.8f * float(rng() % 1000) / 1000.0f;
      const Tolerance t{0.02, tighter.data()};
      ChannelFitter copy = fitted;
      const bool holds = copy.holds(t, 0.03, changed, y.data());
      const EncodedChannel again = copy.fit(t, 0.03, &changed, scratch);
      CHECK(holds == (again.frames == first.frames && again.q == first.q));
      (holds ? held : refitted) += 1;
      // At another step the keys are requantized: never held.
      CHECK_FALSE(fitted.holds(t, 0.015, changed, y.data()));
    }
    CHECK(held > 30);  // both answers occur
    CHECK(refitted > 30);
    CHECK(scratch_clean(scratch));
    // A constant channel is not a candidate: never held.
    ChannelFitter flat{ChannelFitOptions{}};
    scratch.y.assign(800, 0.001);
    flat.fit(tol, 0.03, nullptr, scratch);
    CHECK_FALSE(flat.holds(tol, 0.03, {5}, scratch.y.data()));
  }

  TEST_CASE("the first fit chooses the interpolation: later rounds refit only the winner") {
    // A smooth wave, where Cardinal needs far fewer keys, and a sawtooth of straight ramps with
    // corners off the frames, where linear does.
    std::vector<double> saw(600);
    for (uint32_t f = 0; f < saw.size(); ++f) saw[f] = 2.0 * std::fabs(std::fmod(f + 0.5, 37.0) - 18.5);
    const std::pair<std::vector<double>, Interpolation> cases[] = {{wavy(600, 0.7), Interpolation::cardinal},
                                                                    {saw, Interpolation::linear}};
    for (const auto& [y, winner] : cases) {
      std::vector<float> factor(600, 1.0f);
      const Tolerance tol{0.05, factor.data()};
      ChannelFitter fitter{ChannelFitOptions{}};
      FitScratch scratch;
      scratch.y = y;
      const EncodedChannel first = fitter.fit(tol, 0.0625, nullptr, scratch);
      CHECK(first.interp == winner);
      CHECK(fitter.candidate_count() == 1);
      // Tighter everywhere: the winner's keys are refined, and still within the tolerance.
      std::fill(factor.begin(), factor.end(), 0.5f);
      const EncodedChannel tighter = fitter.fit(tol, 0.03125, nullptr, scratch);
      CHECK(tighter.interp == winner);
      CHECK(tighter.frames.size() >= first.frames.size());
      CHECK(worst_ratio(tighter, y, tol, TangentRule::step_adjusted) <= 1.0);
      CHECK(fitter.candidate_count() == 1);
      CHECK(scratch_clean(scratch));
    }
  }

  TEST_CASE("constant channels cost one key, zero channels none") {
    std::vector<float> factor(50, 1.0f);
    const Tolerance tol{0.1, factor.data()};
    std::vector<double> y(50, 0.04);
    auto c = constant_channel(y.data(), 50, 0.04, 0.04, tol, 0.1);
    REQUIRE(c.has_value());
    CHECK(c->frames.empty());  // 0.04 rounds to the integer 0 at step 0.1, within 0.1
    CHECK(c->step == 0.0625);  // the largest power of two up to the step
    y.assign(50, 3.0);
    c = constant_channel(y.data(), 50, 3.0, 3.0, tol, 0.1);
    REQUIRE(c.has_value());
    CHECK(c->frames == std::vector<uint32_t>{0});
    CHECK(c->step == 0.0625);
    CHECK(c->q == std::vector<int64_t>{48});  // 3.0 exactly
    // Where the power of two misses the tolerance and the step does not, the step.
    std::vector<float> tight(50, 0.1f);  // tolerance 0.01
    y.assign(50, 0.3);
    c = constant_channel(y.data(), 50, 0.3, 0.3, {0.1, tight.data()}, 0.1);
    REQUIRE(c.has_value());
    CHECK(c->step == 0.1);  // 0.3 is 4.8 steps of 0.0625 (off by 0.0125), 3 of 0.1
    CHECK(c->q == std::vector<int64_t>{3});
    y[20] = 3.5;
    CHECK_FALSE(constant_channel(y.data(), 50, 3.0, 3.5, tol, 0.1).has_value());
    // Spread just under twice the tolerance: the midpoint is within at both extremes; just
    // over: no value is.
    for (const double spread : {0.19, 0.2002}) {
      CAPTURE(spread);
      y.assign(50, 1.0);
      y[30] = 1.0 + spread;
      c = constant_channel(y.data(), 50, 1.0, 1.0 + spread, tol, 0.001);
      CHECK(c.has_value() == (spread < 0.2));
      if (c) CHECK(std::fabs(dequantize(c->q[0], c->step) - (1.0 + 0.5 * spread)) < 0.001);
    }
  }

  TEST_CASE("fixed keys are kept as given") {
    const std::vector<double> y = wavy(100, 0.0);
    std::vector<float> factor(100, 1.0f);
    FitScratch scratch;
    const std::vector<uint32_t> keys{0, 10, 55, 99};
    const EncodedChannel ch = fit_channel_at_keys(y, keys, {0.01, factor.data()}, 0.01, ChannelFitOptions{}, scratch);
    CHECK(ch.frames == keys);
    for (size_t i = 0; i < keys.size(); ++i) CHECK(ch.q[i] == std::llround(y[keys[i]] / 0.01));
    ChannelFitOptions fit;
    fit.fit_tension = true;
    const EncodedChannel fitted = fit_channel_at_keys(y, keys, {0.01, factor.data()}, 0.01, fit, scratch);
    CHECK(fitted.frames == keys);
    CHECK(fitted.tension >= -1.0f);
    CHECK(fitted.tension <= 1.0f);
    CHECK(scratch_clean(scratch));
  }
}
