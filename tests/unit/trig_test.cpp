// Half-angle sine and cosine (internal/trig.h): the scalar path and the SSE2 path (groups of
// four) give the same bits for every angle, the huge and non-finite ones included (where the
// quadrant no longer fits an int32: fuzz/corpus/c_api/crash-huge-angle-quadrant.bin once
// reached an out-of-range conversion there), and are accurate for motion-capture angles.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "internal/trig.h"

namespace {

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

TEST_CASE("half_sincos_deg: scalar and four-wide paths agree bit for bit, huge angles included") {
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<float> angles = {0.0f, -0.0f, 90.0f, -180.0f, 359.5f, 12345.678f, -1e6f, 3.8e11f, 3.9e11f, 4e11f,
                               -5.19874e11f, 1e20f, -3e38f, inf, -inf, std::numeric_limits<float>::quiet_NaN()};
  for (float a = 1.0f; a < 1e38f; a *= 7.3f) angles.insert(angles.end(), {a, -a});
  while (angles.size() % 4 != 0) angles.push_back(1.0f);
  std::vector<float> s4(angles.size()), c4(angles.size());
  for (size_t i = 0; i < angles.size(); i += 4) {
    keyanim::internal::F4 s, c;
    keyanim::internal::half_sincos_deg(keyanim::internal::F4::load(&angles[i]), s, c);
    s.store(&s4[i]), c.store(&c4[i]);
  }
  for (size_t i = 0; i < angles.size(); ++i) {
    float s1, c1;
    keyanim::internal::half_sincos_deg(angles[i], s1, c1);
    INFO("angle ", angles[i]);
    CHECK(same_bits(s1, s4[i]));
    CHECK(same_bits(c1, c4[i]));
  }
}

TEST_CASE("half_sincos_deg: within a few ulps of sin and cos for |angle| <= 1e6 degrees") {
  for (float a = -1e6f; a <= 1e6f; a += 997.13f) {
    float s, c;
    keyanim::internal::half_sincos_deg(a, s, c);
    const double h = double(a) * 0.5 * M_PI / 180.0;
    CHECK(std::fabs(s - std::sin(h)) < 2e-7);
    CHECK(std::fabs(c - std::cos(h)) < 2e-7);
  }
}
