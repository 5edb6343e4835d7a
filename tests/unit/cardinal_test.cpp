// keyanim/cardinal.h against an independent double-precision evaluation written here from the
// matrix form of method.md section 3, and against values computed by hand.
#include <doctest/doctest.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <vector>

#include "keyanim/cardinal.h"

namespace {

using keyanim::Interpolation;
using keyanim::TangentRule;

struct Keys {
  std::vector<uint32_t> frames;
  std::vector<float> values;
  uint32_t n() const { return static_cast<uint32_t>(frames.size()); }
};

// method.md section 3, the four-basis form in P_{j-1}..P_{j+2}, end points duplicated. Uniform
// rule only: the basis has no spacing in it.
double ref_matrix(const Keys& k, uint32_t j, double u, double s) {
  const uint32_t n = k.n();
  const double pm = k.values[j == 0 ? 0 : j - 1];
  const double p0 = k.values[j];
  const double p1 = k.values[j + 1];
  const double p2 = k.values[j + 2 < n ? j + 2 : n - 1];
  const double u2 = u * u, u3 = u2 * u;
  return (-s * u3 + 2 * s * u2 - s * u) * pm + ((2 - s) * u3 + (s - 3) * u2 + 1) * p0 +
         ((s - 2) * u3 + (3 - 2 * s) * u2 + s * u) * p1 + (s * u3 - s * u2) * p2;
}

// Hermite form with Kochanek-Bartels step-size scaling, written from the text of method.md
// (scale 2 n_out / (n_in + n_out) where the key starts the segment, 2 n_in / (n_in + n_out)
// where it ends one; an end key has no second segment and keeps its tangent).
double ref_step_adjusted(const Keys& k, uint32_t j, double u, double s) {
  const uint32_t n = k.n();
  auto val = [&](int64_t i) { return double(k.values[size_t(i < 0 ? 0 : i >= n ? n - 1 : i)]); };
  auto len = [&](int64_t a) { return double(k.frames[size_t(a + 1)]) - double(k.frames[size_t(a)]); };
  const int64_t jj = j;
  double m0 = s * (val(jj + 1) - val(jj - 1));
  double m1 = s * (val(jj + 2) - val(jj));
  if (j > 0) m0 *= 2 * len(jj) / (len(jj - 1) + len(jj));                   // key j starts segment j
  if (j + 2 < n) m1 *= 2 * len(jj) / (len(jj) + len(jj + 1));               // key j+1 ends it
  const double u2 = u * u, u3 = u2 * u;
  return (2 * u3 - 3 * u2 + 1) * val(jj) + (-2 * u3 + 3 * u2) * val(jj + 1) +
         (u3 - 2 * u2 + u) * m0 + (u3 - u2) * m1;
}

// A whole channel in double: clamp, find the segment by a linear scan, evaluate.
template <class Segment>
double ref_channel(const Keys& k, double f, Segment seg) {
  if (f <= k.frames.front()) return k.values.front();
  if (f >= k.frames.back()) return k.values.back();
  uint32_t j = 0;
  while (k.frames[j + 1] <= f) ++j;
  const double u = (f - k.frames[j]) / (double(k.frames[j + 1]) - k.frames[j]);
  return seg(j, u);
}

float eval(const Keys& k, float f, float s, TangentRule rule,
           Interpolation interp = Interpolation::cardinal) {
  return keyanim::eval_channel(k.frames.data(), k.values.data(), k.n(), f, interp, s, rule);
}

// float against double: a few ulps of the largest magnitude involved.
double tolerance(const Keys& k) {
  double m = 1.0;
  for (const float v : k.values) m = std::max(m, double(std::abs(v)));
  return 16.0 * FLT_EPSILON * m;
}

const Keys kUniformKeys{{0, 8, 16, 24, 32, 40, 48}, {0.5f, 3.25f, -1.75f, 10.0f, 9.5f, -4.0f, 2.0f}};
const Keys kUnevenKeys{{0, 2, 10, 13, 30, 31, 40}, {1.0f, -2.5f, 4.0f, 4.5f, -7.0f, 0.25f, 3.0f}};
const float kTensions[] = {-0.5f, 0.0f, 0.5f, 1.0f};

}  // namespace

TEST_SUITE("cardinal") {

TEST_CASE("tension maps to s as (1 - T) / 2") {
  CHECK(keyanim::tension_to_s(0.0f) == 0.5f);
  CHECK(keyanim::tension_to_s(1.0f) == 0.0f);
  CHECK(keyanim::tension_to_s(-0.5f) == 0.75f);
  CHECK(keyanim::tension_to_s(0.5f) == 0.25f);
  CHECK(keyanim::s_to_tension(0.75f) == -0.5f);
}

TEST_CASE("uniform rule matches the matrix form for several tensions") {
  const Keys& k = kUniformKeys;
  for (const float t : kTensions) {
    CAPTURE(t);
    const float s = keyanim::tension_to_s(t);
    for (float f = 0.0f; f <= 48.0f; f += 0.125f) {
      CAPTURE(f);
      const double ref = ref_channel(k, f, [&](uint32_t j, double u) { return ref_matrix(k, j, u, s); });
      CHECK(std::abs(eval(k, f, s, TangentRule::uniform) - ref) <= tolerance(k));
    }
    // eval_segment directly, at every segment and a spread of u (uneven keys: the uniform rule
    // ignores spacing, so the matrix form still applies).
    for (uint32_t j = 0; j + 1 < kUnevenKeys.n(); ++j) {
      for (int i = 0; i <= 16; ++i) {
        const float u = float(i) / 16.0f;
        const float got = keyanim::eval_segment(kUnevenKeys.frames.data(), kUnevenKeys.values.data(),
                                                kUnevenKeys.n(), j, u, Interpolation::cardinal, s,
                                                TangentRule::uniform);
        CHECK(std::abs(got - ref_matrix(kUnevenKeys, j, u, s)) <= tolerance(kUnevenKeys));
      }
    }
  }
}

TEST_CASE("step-adjusted rule matches its Hermite reference on uneven keys") {
  const Keys& k = kUnevenKeys;
  for (const float t : kTensions) {
    CAPTURE(t);
    const float s = keyanim::tension_to_s(t);
    for (float f = 0.0f; f <= 40.0f; f += 0.125f) {
      CAPTURE(f);
      const double ref = ref_channel(k, f, [&](uint32_t j, double u) { return ref_step_adjusted(k, j, u, s); });
      CHECK(std::abs(eval(k, f, s, TangentRule::step_adjusted) - ref) <= tolerance(k));
    }
  }
}

TEST_CASE("step-adjusted rule equals the uniform rule on evenly spaced keys") {
  const Keys& k = kUniformKeys;
  for (const float t : kTensions) {
    const float s = keyanim::tension_to_s(t);
    for (float f = -1.0f; f <= 49.0f; f += 0.0625f) {
      CAPTURE(f);
      // The scale factors are exactly 2 n / 2n = 1, so this is bit-exact, not just close.
      CHECK(eval(k, f, s, TangentRule::step_adjusted) == eval(k, f, s, TangentRule::uniform));
    }
  }
}

TEST_CASE("step-adjusted velocity is continuous across a key where the uniform rule's jumps") {
  // Key 1 at frame 4 has 4 frames before it and 16 after: velocity ratio 16/4 with the uniform rule.
  const Keys k{{0, 4, 20, 24}, {0.0f, 2.0f, 5.0f, 1.0f}};
  const float key = 4.0f, h = 1.0f / 32.0f;
  auto velocity = [&](TangentRule rule, float dir) {
    // Second-order one-sided difference, in value units per frame.
    const float s = keyanim::tension_to_s(0.0f);
    const double q0 = eval(k, key, s, rule), q1 = eval(k, key + dir * h, s, rule),
                 q2 = eval(k, key + 2 * dir * h, s, rule);
    return dir * (-3 * q0 + 4 * q1 - q2) / (2 * double(h));
  };
  const double adj_left = velocity(TangentRule::step_adjusted, -1), adj_right = velocity(TangentRule::step_adjusted, 1);
  const double uni_left = velocity(TangentRule::uniform, -1), uni_right = velocity(TangentRule::uniform, 1);
  // Hand: m = s (P2 - P0) = 2.5 per segment; uniform: 2.5 / 4 on the left, 2.5 / 16 on the right;
  // adjusted: 2.5 * 2 / 20 = 0.25 on both sides.
  CHECK(adj_left == doctest::Approx(0.25).epsilon(1e-3));
  CHECK(adj_right == doctest::Approx(0.25).epsilon(1e-3));
  CHECK(uni_left == doctest::Approx(2.5 / 4).epsilon(1e-3));
  CHECK(uni_right == doctest::Approx(2.5 / 16).epsilon(1e-3));
  CHECK(uni_left / uni_right == doctest::Approx(16.0 / 4.0).epsilon(1e-3));
}

TEST_CASE("sampling exactly at a key returns the key value bit-exactly") {
  for (const Keys* k : {&kUniformKeys, &kUnevenKeys}) {
    for (const float t : kTensions) {
      for (const TangentRule rule : {TangentRule::uniform, TangentRule::step_adjusted}) {
        for (const Interpolation interp : {Interpolation::cardinal, Interpolation::linear}) {
          for (uint32_t i = 0; i < k->n(); ++i) {
            CAPTURE(i);
            CHECK(eval(*k, float(k->frames[i]), keyanim::tension_to_s(t), rule, interp) == k->values[i]);
          }
        }
      }
    }
  }
}

TEST_CASE("no keys gives zero and one key gives a constant") {
  CHECK(keyanim::eval_channel(nullptr, nullptr, 0, 3.5f, Interpolation::cardinal, 0.5f,
                              TangentRule::uniform) == 0.0f);
  const uint32_t frame = 7;
  const float value = -2.75f;
  for (const float f : {-10.0f, 0.0f, 7.0f, 7.5f, 1e6f}) {
    CHECK(keyanim::eval_channel(&frame, &value, 1, f, Interpolation::cardinal, 0.5f,
                                TangentRule::step_adjusted) == value);
  }
}

TEST_CASE("two keys follow the hand-computed curve") {
  // With P_{-1} = P_0 and P_2 = P_1 both tangents are s (P1 - P0), so
  // Q(u) = P0 + (P1 - P0) (3u^2 - 2u^3 + s (2u^3 - 3u^2 + u)).
  // At u = 1/4: 3u^2 - 2u^3 = 0.15625 and 2u^3 - 3u^2 + u = 0.09375. P0 = 1, P1 = 3:
  //   T = 1 (s = 0):     1 + 2 * 0.15625                   = 1.3125
  //   T = 0.5 (s = 1/4): 1 + 2 * (0.15625 + 0.0234375)     = 1.359375
  //   T = 0 (s = 1/2):   1 + 2 * (0.15625 + 0.046875)      = 1.40625
  //   T = -1 (s = 1):    1 + 2 * 0.25                      = 1.5 (a straight line)
  const Keys k{{0, 10}, {1.0f, 3.0f}};
  for (const TangentRule rule : {TangentRule::uniform, TangentRule::step_adjusted}) {
    CHECK(eval(k, 2.5f, keyanim::tension_to_s(1.0f), rule) == doctest::Approx(1.3125).epsilon(1e-6));
    CHECK(eval(k, 2.5f, keyanim::tension_to_s(0.5f), rule) == doctest::Approx(1.359375).epsilon(1e-6));
    CHECK(eval(k, 2.5f, keyanim::tension_to_s(0.0f), rule) == doctest::Approx(1.40625).epsilon(1e-6));
    CHECK(eval(k, 2.5f, keyanim::tension_to_s(-1.0f), rule) == doctest::Approx(1.5).epsilon(1e-6));
    // Mid-segment the curve is symmetric: 2 whatever s is (3/4 - 1/4 = 1/2, and the s term is 0).
    for (const float t : kTensions)
      CHECK(eval(k, 5.0f, keyanim::tension_to_s(t), rule) == doctest::Approx(2.0).epsilon(1e-6));
  }
}

TEST_CASE("sampling outside the keys clamps to the end values") {
  const Keys& k = kUnevenKeys;
  for (const float t : kTensions) {
    const float s = keyanim::tension_to_s(t);
    for (const TangentRule rule : {TangentRule::uniform, TangentRule::step_adjusted}) {
      CHECK(eval(k, -0.001f, s, rule) == k.values.front());
      CHECK(eval(k, -1e9f, s, rule) == k.values.front());
      CHECK(eval(k, 40.001f, s, rule) == k.values.back());
      CHECK(eval(k, 1e9f, s, rule) == k.values.back());
      CHECK(eval(k, INFINITY, s, rule) == k.values.back());
      CHECK(eval(k, -INFINITY, s, rule) == k.values.front());
    }
  }
}

TEST_CASE("a run of equal keys stays exactly constant between them") {
  // Keys 1..4 are equal, so segment 2 (keys 2 and 3, frames 9 to 12) has P_1 = P_2 = P_3 = P_4 and
  // both tangents exactly zero; the whole channel is a constant in the second example, every
  // segment included (the duplicated end points make the end tangents zero too). The curve is
  // then h00 P + h01 P, and h00 + h01 = 1: exact arithmetic must give P back, bit for bit.
  const Keys run{{0, 3, 9, 12, 20, 25}, {-1.0f, 2.5f, 2.5f, 2.5f, 2.5f, 7.0f}};
  const Keys flat{{0, 5, 11}, {0.3f, 0.3f, 0.3f}};
  struct Case {
    const Keys* keys;
    float from, to, value;
  };
  for (const Case& c : {Case{&run, 9.0f, 12.0f, 2.5f}, Case{&flat, 0.0f, 11.0f, 0.3f}}) {
    CAPTURE(c.value);
    size_t samples = 0, off = 0;
    float first_off_frame = -1.0f, first_off_value = 0.0f;
    for (const float t : kTensions) {
      for (const TangentRule rule : {TangentRule::uniform, TangentRule::step_adjusted}) {
        for (float f = c.from; f <= c.to; f += 1.0f / 64.0f, ++samples) {
          const float v = eval(*c.keys, f, keyanim::tension_to_s(t), rule);
          if (v == c.value) continue;
          if (off++ == 0) first_off_frame = f, first_off_value = v;
        }
      }
    }
    CAPTURE(samples);
    CAPTURE(first_off_frame);
    CAPTURE(first_off_value);
    CHECK(off == 0);
  }
}

TEST_CASE("linear interpolation ignores tension and tangent rule") {
  const Keys& k = kUnevenKeys;
  for (float f = 0.0f; f <= 40.0f; f += 0.25f) {
    CAPTURE(f);
    uint32_t j = 0;
    while (j + 2 < k.n() && double(k.frames[j + 1]) <= f) ++j;
    const double u = (f - double(k.frames[j])) / (double(k.frames[j + 1]) - k.frames[j]);
    const double ref = k.values[j] + u * (double(k.values[j + 1]) - k.values[j]);
    for (const float t : kTensions)
      for (const TangentRule rule : {TangentRule::uniform, TangentRule::step_adjusted})
        CHECK(std::abs(eval(k, f, keyanim::tension_to_s(t), rule, Interpolation::linear) - ref) <= tolerance(k));
  }
}

TEST_CASE("tension 1 gives zero tangents") {
  // Hermite with m = 0: Q = h00 P_j + h01 P_{j+1}, whatever the neighbours and the spacing.
  const Keys& k = kUnevenKeys;
  for (const TangentRule rule : {TangentRule::uniform, TangentRule::step_adjusted}) {
    for (float f = 0.0f; f <= 40.0f; f += 0.25f) {
      CAPTURE(f);
      const double ref = ref_channel(k, f, [&](uint32_t j, double u) {
        return (2 * u * u * u - 3 * u * u + 1) * k.values[j] + (-2 * u * u * u + 3 * u * u) * k.values[j + 1];
      });
      CHECK(std::abs(eval(k, f, keyanim::tension_to_s(1.0f), rule) - ref) <= tolerance(k));
    }
  }
}

TEST_CASE("find_segment at keys and between them") {
  const uint32_t frames[] = {0, 3, 7, 10};
  CHECK(keyanim::find_segment(frames, 4, 0.0f) == 0);
  CHECK(keyanim::find_segment(frames, 4, 2.999f) == 0);
  CHECK(keyanim::find_segment(frames, 4, 3.0f) == 1);  // a key starts its own segment
  CHECK(keyanim::find_segment(frames, 4, 6.5f) == 1);
  CHECK(keyanim::find_segment(frames, 4, 7.0f) == 2);
  CHECK(keyanim::find_segment(frames, 4, 9.999f) == 2);
  CHECK(keyanim::find_segment(frames, 4, 10.0f) == 2);  // the last key ends the last segment
  const uint32_t two[] = {5, 6};
  CHECK(keyanim::find_segment(two, 2, 5.0f) == 0);
  CHECK(keyanim::find_segment(two, 2, 6.0f) == 0);
  // Against a linear scan on many keys.
  std::vector<uint32_t> many;
  for (uint32_t i = 0; i < 100; ++i) many.push_back(i * i + i);
  for (float f = 0.0f; f <= float(many.back()); f += 0.5f) {
    uint32_t j = 0;
    while (j + 2 < many.size() && float(many[j + 1]) <= f) ++j;
    CHECK(keyanim::find_segment(many.data(), uint32_t(many.size()), f) == j);
  }
}

}  // TEST_SUITE
