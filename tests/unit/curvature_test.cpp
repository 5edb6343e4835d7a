// Key selection without an error bound: curvature feature points (keyanim/offline/curvature.h)
// on curves whose corners are known, and the uniform and manual key lists (keyframes.h).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "corpus_files.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/curvature.h"
#include "keyanim/offline/keyframes.h"

namespace {

using keyanim::offline::curvature_keys;
using keyanim::offline::CurvatureParams;

std::vector<uint32_t> interior(const std::vector<uint32_t>& keys) {
  if (keys.size() <= 2) return {};
  return {keys.begin() + 1, keys.end() - 1};
}

double distance_to_nearest(double f, const std::vector<double>& targets) {
  double best = INFINITY;
  for (const double t : targets) best = std::min(best, std::abs(f - t));
  return best;
}

// Every interior key is within `tol` frames of a target and every target has a key that close.
void check_keys_at(const std::vector<uint32_t>& keys, size_t frames, const std::vector<double>& targets,
                   double tol) {
  REQUIRE(keys.size() >= 2);
  CHECK(keys.front() == 0);
  CHECK(keys.back() == frames - 1);
  std::vector<double> got;
  for (const uint32_t k : interior(keys)) got.push_back(k);
  for (const double k : got) {
    CAPTURE(k);
    CHECK(distance_to_nearest(k, targets) <= tol);
  }
  for (const double t : targets) {
    CAPTURE(t);
    CHECK(distance_to_nearest(t, got) <= tol);
  }
}

std::vector<double> triangle_wave(size_t frames, int half_period, double amplitude) {
  std::vector<double> y(frames);
  for (size_t f = 0; f < frames; ++f) {
    const int m = int(f % size_t(2 * half_period));
    y[f] = amplitude * (m <= half_period ? m : 2 * half_period - m) / half_period;
  }
  return y;
}

// Method.md section 3: unwrap an Euler angle channel (independent of the library's unwrapping).
std::vector<double> unwrap_degrees(std::vector<double> y) {
  for (size_t f = 1; f < y.size(); ++f) {
    const double d = y[f] - y[f - 1];
    y[f] = y[f - 1] + d - 360.0 * std::round(d / 360.0);
  }
  return y;
}

}  // namespace

TEST_SUITE("curvature") {

TEST_CASE("triangle wave gives a key at every apex and none on the ramps") {
  // Apexes (peaks and troughs) every 20 frames.
  const std::vector<double> y = triangle_wave(201, 20, 10.0);
  const std::vector<uint32_t> keys = curvature_keys(y);
  std::vector<double> apexes;
  for (int f = 20; f < 200; f += 20) apexes.push_back(f);
  check_keys_at(keys, y.size(), apexes, 2.0);
  CHECK(keys.size() == apexes.size() + 2);
}

TEST_CASE("asymmetric triangle wave with long ramps") {
  // Rises 100 frames, falls 200, rises 100...: apexes at 100, 300, 500, 700, 900.
  std::vector<double> y(1001);
  for (size_t f = 0; f < y.size(); ++f) {
    const int m = int(f % 400);
    y[f] = m <= 100 ? m * 0.3 : m <= 300 ? 30.0 - (m - 100) * 0.3 : -30.0 + (m - 300) * 0.3;
  }
  check_keys_at(curvature_keys(y), y.size(), {100, 300, 500, 700, 900}, 2.0);
}

TEST_CASE("ramp with a kink gives one key at the kink") {
  // Flat, then rising from frame 60. In the square box the smoothed corner's curvature peaks at
  // 58.15 (the flat side is less steep; found by sampling the curvature of the erf-smoothed kink
  // analytically in a separate script).
  std::vector<double> y(151);
  for (size_t f = 0; f < y.size(); ++f) y[f] = f < 60 ? 0.0 : (double(f) - 60.0) * 0.5;
  const std::vector<uint32_t> keys = curvature_keys(y);
  REQUIRE(keys.size() == 3);
  CHECK(std::abs(keys[1] - 58.15) <= 1.5);
  CHECK(std::abs(double(keys[1]) - 60.0) <= 2.0);
}

TEST_CASE("a step gives the two corners of its smoothed edge") {
  // A step between frames 99 and 100 is a vertical edge of height F - 1 in the square box.
  // Smoothed by the sigma-3 Gaussian, y' = 199 phi((f - 99.5) / 3) / 3; the curvature of that
  // curve peaks at 91.31 and 107.69 (sampled analytically in a separate script).
  std::vector<double> y(200);
  for (size_t f = 0; f < y.size(); ++f) y[f] = f < 100 ? 1.0 : 3.0;
  const std::vector<uint32_t> keys = curvature_keys(y);
  REQUIRE(keys.size() == 4);
  CHECK(std::abs(keys[1] - 91.31) <= 2.0);
  CHECK(std::abs(keys[2] - 107.69) <= 2.0);
}

TEST_CASE("a flat kink is rejected by the angle test unless T_angle allows it") {
  // Slopes 0.8 then 1.2 and a range of exactly F - 1: the square box is the identity, and the
  // arms turn by atan(1.2) - atan(0.8) = 11.5 degrees, an angle of 168.5 between them.
  std::vector<double> y(201);
  for (size_t f = 0; f < y.size(); ++f) y[f] = f <= 100 ? 0.8 * double(f) : 80.0 + 1.2 * (double(f) - 100.0);
  CHECK(curvature_keys(y) == std::vector<uint32_t>{0, 200});  // 168.5 > 162
  CurvatureParams wide;
  wide.t_angle = 175.0;  // 168.5 < 175: a corner now
  const std::vector<uint32_t> keys = curvature_keys(y, wide);
  REQUIRE(keys.size() == 3);
  CHECK(std::abs(double(keys[1]) - 100.0) <= 2.0);
}

TEST_CASE("sine gives keys at its extrema") {
  // Period 200: extrema at 50, 150, 250, 350, 450, where the curvature peaks.
  std::vector<double> y(501);
  for (size_t f = 0; f < y.size(); ++f) y[f] = std::sin(2.0 * std::numbers::pi * double(f) / 200.0);
  check_keys_at(curvature_keys(y), y.size(), {50, 150, 250, 350, 450}, 2.0);
}

TEST_CASE("long sine with a small ripple keeps the extrema and ignores the ripple") {
  // sin(0.01 f) has its extrema at (pi/2 + k pi) / 0.01 = 157.08, 471.24, ...; the ripple (0.1%
  // of the amplitude, period 4.8 frames) is a trivial detail the detector must not mark.
  std::vector<double> y(5000);
  for (size_t f = 0; f < y.size(); ++f) y[f] = std::sin(0.01 * double(f)) + 0.001 * std::sin(1.3 * double(f));
  std::vector<double> extrema;
  for (int k = 0;; ++k) {
    const double e = (std::numbers::pi / 2 + k * std::numbers::pi) / 0.01;
    if (e >= 4999) break;
    extrema.push_back(e);
  }
  check_keys_at(curvature_keys(y), y.size(), extrema, 2.0);
}

TEST_CASE("keys do not depend on the signal's scale offset or direction") {
  // The square box removes scale and offset; the curvature's absolute value removes the sign;
  // the detector is symmetric in time, so a reversed signal gives mirrored keys. (The extrema
  // sit on whole frames: a peak halfway between two frames would be a tie that rounding breaks.)
  std::vector<double> tri = triangle_wave(201, 20, 10.0);
  tri[37] += 3.0;  // a bump to make it asymmetric in time
  std::vector<double> sine(501);
  for (size_t f = 0; f < sine.size(); ++f) sine[f] = std::sin(2.0 * std::numbers::pi * double(f) / 160.0);
  for (const std::vector<double>* y : {&tri, &sine}) {
    const std::vector<uint32_t> keys = curvature_keys(*y);
    std::vector<double> affine(y->size()), negated(y->size()), reversed(y->rbegin(), y->rend());
    for (size_t f = 0; f < y->size(); ++f) {
      affine[f] = 4.0 * (*y)[f] + 250.0;
      negated[f] = -(*y)[f];
    }
    CHECK(curvature_keys(affine) == keys);
    CHECK(curvature_keys(negated) == keys);
    std::vector<uint32_t> mirrored;
    for (auto it = keys.rbegin(); it != keys.rend(); ++it) mirrored.push_back(uint32_t(y->size() - 1) - *it);
    CHECK(curvature_keys(reversed) == mirrored);
  }
}

TEST_CASE("constant signals give just the end frames") {
  CHECK(curvature_keys(std::vector<double>(300, 4.25)) == std::vector<uint32_t>{0, 299});
  std::vector<double> zeros(50, 0.0);
  zeros[7] = -0.0;  // equal to +0: still constant
  CHECK(curvature_keys(zeros) == std::vector<uint32_t>{0, 49});
}

TEST_CASE("signals not longer than the kernel give just the end frames") {
  // W = 12 for sigma = 3 (exp(-144/18) = 3.4e-4 > 1e-4 > exp(-169/18) = 8.3e-5).
  CHECK(curvature_keys(std::vector<double>{}).empty());
  CHECK(curvature_keys(std::vector<double>{3.0}) == std::vector<uint32_t>{0});
  CHECK(curvature_keys(std::vector<double>{3.0, -1.0}) == std::vector<uint32_t>{0, 1});
  const std::vector<double> tri12 = triangle_wave(12, 3, 1.0);  // apexes at 3, 6, 9
  CHECK(curvature_keys(tri12) == std::vector<uint32_t>{0, 11});
  // One frame longer than W: the detector runs (a V with its apex in the middle).
  std::vector<double> v(13);
  for (size_t f = 0; f < v.size(); ++f) v[f] = std::abs(double(f) - 6.0);
  const std::vector<uint32_t> keys = curvature_keys(v);
  CHECK(keys.front() == 0);
  CHECK(keys.back() == 12);
  CHECK(std::find(keys.begin(), keys.end(), 6u) != keys.end());
}

TEST_CASE("parameters change the result as documented") {
  std::vector<double> y(501);
  for (size_t f = 0; f < y.size(); ++f) y[f] = std::sin(2.0 * std::numbers::pi * double(f) / 200.0);
  CurvatureParams strict;
  strict.c = 1e6;  // no maximum is a million times its region's mean
  CHECK(curvature_keys(y, strict) == std::vector<uint32_t>{0, 500});
  CurvatureParams flat;
  flat.t_angle = 0.0;  // every pair of arms is wider than 0 degrees
  CHECK(curvature_keys(y, flat) == std::vector<uint32_t>{0, 500});
  CurvatureParams bad;
  bad.sigma = 0.0;
  CHECK(curvature_keys(y, bad) == std::vector<uint32_t>{0, 500});
  std::vector<double> with_nan = y;
  with_nan[100] = NAN;
  CHECK(curvature_keys(with_nan) == std::vector<uint32_t>{0, 500});
}

TEST_CASE("keys are sorted unique in range on a long noisy signal") {
  std::vector<double> y(5000);
  uint32_t state = 12345;
  for (double& v : y) {
    state = state * 1664525u + 1013904223u;
    v = double(state >> 8) / double(1u << 24);
  }
  const std::vector<uint32_t> keys = curvature_keys(y);
  REQUIRE(keys.size() >= 2);
  CHECK(keys.front() == 0);
  CHECK(keys.back() == 4999);
  CHECK(std::adjacent_find(keys.begin(), keys.end(), [](uint32_t a, uint32_t b) { return a >= b; }) ==
        keys.end());
}

TEST_CASE("corpus clip CMU 01_03: the shoulder Z rotation keys land on turning points") {
  const std::filesystem::path path = keyanim::test::corpus_dir() / "cmu" / "assimp__01_03.bvh";
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    KEYANIM_SKIP_CORPUS_TEST(path.string());
    return;
  }
  const keyanim::offline::Motion motion = keyanim::offline::read_bvh_file(path.string());
  // In CMU skeletons "RightShoulder" is the clavicle (unused in this clip: all zeros) and
  // "RightArm" the upper arm, whose rotation is the shoulder joint's.
  auto z_rotation = [&](const std::string& joint) -> std::vector<double> {
    for (const keyanim::Joint& j : motion.skeleton.joints) {
      if (j.name != joint) continue;
      for (size_t i = 0; i < j.channels.size(); ++i)
        if (j.channels[i] == keyanim::ChannelType::z_rotation) return motion.channel(j.first_channel + uint32_t(i));
    }
    return {};
  };
  const std::vector<double> clavicle = z_rotation("RightShoulder");
  REQUIRE(clavicle.size() == motion.frame_count);
  CHECK(curvature_keys(clavicle) == std::vector<uint32_t>{0, motion.frame_count - 1});

  const std::vector<double> y = unwrap_degrees(z_rotation("RightArm"));
  REQUIRE(y.size() == motion.frame_count);
  const std::vector<uint32_t> keys = curvature_keys(y);
  const auto n = long(y.size());
  MESSAGE("RightArm Zrotation: " << keys.size() << " keys over " << n << " frames");

  // Turning-point evidence, independent of the detector: a 7-frame moving average (not the
  // detector's Gaussian) whose first difference changes sign at frame f (a local extremum), or
  // whose |second difference| at f is in the top 10% of the channel (a sharp slope change).
  std::vector<double> avg(size_t(n), 0.0);
  for (long f = 0; f < n; ++f) {
    double sum = 0.0;
    int count = 0;
    for (long g = std::max(0L, f - 3); g <= std::min(n - 1, f + 3); ++g, ++count) sum += y[size_t(g)];
    avg[size_t(f)] = sum / count;
  }
  std::vector<double> d2(size_t(n), 0.0);
  for (long f = 1; f + 1 < n; ++f) d2[size_t(f)] = std::abs(avg[size_t(f + 1)] - 2 * avg[size_t(f)] + avg[size_t(f - 1)]);
  std::vector<double> sorted = d2;
  std::sort(sorted.begin(), sorted.end());
  const double sharp = sorted[size_t(0.9 * double(n))];
  std::vector<bool> turning(size_t(n), false);
  for (long f = 1; f + 1 < n; ++f) {
    const double before = avg[size_t(f)] - avg[size_t(f - 1)], after = avg[size_t(f + 1)] - avg[size_t(f)];
    turning[size_t(f)] = before * after <= 0.0 || d2[size_t(f)] >= sharp;
  }
  auto near_turning = [&](long f) {
    for (long g = std::max(0L, f - 3); g <= std::min(n - 1, f + 3); ++g)
      if (turning[size_t(g)]) return true;
    return false;
  };
  const std::vector<uint32_t> inner = interior(keys);
  REQUIRE(inner.size() >= 20);
  size_t hits = 0;
  for (const uint32_t k : inner) hits += near_turning(long(k));
  size_t base = 0;
  for (long f = 0; f < n; ++f) base += near_turning(f);
  const double key_rate = double(hits) / double(inner.size()), base_rate = double(base) / double(n);
  MESSAGE("keys near a turning point: " << hits << "/" << inner.size() << "; any frame: " << base_rate);
  // Measured 0.985 against 0.60 for an arbitrary frame; keys moved by 4 frames score 0.79 and by
  // 12 frames 0.71, so this tells turning points from elsewhere.
  CHECK(key_rate >= 0.95);
  CHECK(base_rate <= 0.75);  // the evidence is not everywhere, or the check would prove nothing
}

TEST_CASE("uniform_keys every N frames plus the last") {
  using keyanim::offline::uniform_keys;
  CHECK(uniform_keys(0, 5).empty());
  CHECK(uniform_keys(1, 5) == std::vector<uint32_t>{0});
  CHECK(uniform_keys(2, 5) == std::vector<uint32_t>{0, 1});
  CHECK(uniform_keys(11, 5) == std::vector<uint32_t>{0, 5, 10});
  CHECK(uniform_keys(12, 5) == std::vector<uint32_t>{0, 5, 10, 11});
  CHECK(uniform_keys(4, 1) == std::vector<uint32_t>{0, 1, 2, 3});
  CHECK(uniform_keys(7, 100) == std::vector<uint32_t>{0, 6});
  // Near the top of uint32: no wrap-around.
  const std::vector<uint32_t> big = uniform_keys(0xFFFFFFFFu, 0x80000000u);
  CHECK(big == std::vector<uint32_t>{0, 0x80000000u, 0xFFFFFFFEu});
}

TEST_CASE("manual_keys sorts dedupes and adds the ends") {
  using keyanim::offline::manual_keys;
  CHECK(manual_keys({30, 5, 30, 12, 5}, 100) == std::vector<uint32_t>{0, 5, 12, 30, 99});
  CHECK(manual_keys({}, 10) == std::vector<uint32_t>{0, 9});
  CHECK(manual_keys({0, 9}, 10) == std::vector<uint32_t>{0, 9});
  CHECK(manual_keys({0}, 1) == std::vector<uint32_t>{0});
  CHECK(manual_keys({}, 0).empty());
}

TEST_CASE("manual_keys rejects frames out of range and names them") {
  using keyanim::offline::manual_keys;
  try {
    manual_keys({4, 100, 7}, 100);
    FAIL("accepted");
  } catch (const keyanim::offline::Error& e) {
    CHECK(e.kind() == keyanim::offline::ErrorKind::invalid_argument);
    CHECK(e.message().find("100") != std::string::npos);
    CHECK(e.message().find("[0, 99]") != std::string::npos);
  }
  CHECK_THROWS_WITH_AS(manual_keys({0}, 0), "key frame 0 given, but the motion has no frames",
                       keyanim::offline::Error);
}

}  // TEST_SUITE
