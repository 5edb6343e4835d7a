// Half-angle sine and cosine (internal/trig.h): the scalar path and the SSE2 path (groups of
// four) give the same bits for every angle, the huge and non-finite ones included (where the
// quadrant no longer fits an int32: fuzz/corpus/c_api/crash-huge-angle-quadrant.bin once
// reached an out-of-range conversion there), and are accurate for motion-capture angles. The
// eight-wide path (the AVX2 copies, internal/simd8.h) rebuilds cvtps2dq's rounding in generic
// vector code: checked against the instruction itself on edges and a million random floats.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "internal/next_float.h"
#include "internal/trig.h"

namespace {

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

std::vector<float> test_angles() {
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<float> angles = {0.0f, -0.0f, 90.0f, -180.0f, 359.5f, 12345.678f, -1e6f, 3.8e11f, 3.9e11f, 4e11f,
                               -5.19874e11f, 1e20f, -3e38f, inf, -inf, std::numeric_limits<float>::quiet_NaN()};
  for (float a = 1.0f; a < 1e38f; a *= 7.3f) angles.insert(angles.end(), {a, -a});
  while (angles.size() % 8 != 0) angles.push_back(1.0f);
  return angles;
}

}  // namespace

TEST_CASE("half_sincos_deg: scalar and four-wide paths agree bit for bit, huge angles included") {
  const std::vector<float> angles = test_angles();
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

#if KEYANIM_WIDE_LANES
TEST_CASE("half_sincos_deg: the eight-wide path gives the scalar path's bits") {
  const std::vector<float> angles = test_angles();
  for (size_t i = 0; i < angles.size(); i += 8) {
    keyanim::internal::F8 s, c;
    keyanim::internal::half_sincos_deg(keyanim::internal::F8::load(&angles[i]), s, c);
    float s8[8], c8[8];
    s.store(s8), c.store(c8);
    for (size_t l = 0; l < 8; ++l) {
      float s1, c1;
      keyanim::internal::half_sincos_deg(angles[i + l], s1, c1);
      INFO("angle ", angles[i + l]);
      CHECK(same_bits(s1, s8[l]));
      CHECK(same_bits(c1, c8[l]));
    }
  }
}

TEST_CASE("round_to_int32 is cvtps2dq: edges, ties and a million random floats") {
  std::vector<float> x = {0.0f, -0.0f, 0.5f, -0.5f, 1.5f, -1.5f, 2.5f, -2.5f, 4194304.5f, -4194304.5f,
                          4194305.5f, -4194305.5f, 8388607.5f, -8388607.5f, 8388608.0f, 8388609.0f, -8388609.0f,
                          2147483520.0f, -2147483648.0f, 2147483648.0f, -2147483904.0f, 3e38f, -3e38f,
                          std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                          std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::denorm_min()};
  std::mt19937 rng(12345);
  for (int i = 0; i < 1000000; ++i) {
    const uint32_t bits = static_cast<uint32_t>(rng());
    float f;
    std::memcpy(&f, &bits, sizeof f);
    x.push_back(f);
  }
  while (x.size() % 8 != 0) x.push_back(1.0f);
  size_t differ = 0;
  for (size_t i = 0; i < x.size(); i += 8) {
    keyanim::internal::V8f v;
    std::memcpy(&v, &x[i], sizeof v);
    const keyanim::internal::V8i q = keyanim::internal::round_to_int32(v);
    int32_t got[8], want[8];
    std::memcpy(got, &q, sizeof got);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(want), _mm_cvtps_epi32(_mm_loadu_ps(&x[i])));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(want + 4), _mm_cvtps_epi32(_mm_loadu_ps(&x[i + 4])));
    for (size_t l = 0; l < 8; ++l) differ += got[l] != want[l];
  }
  CHECK(differ == 0);
}
#endif

TEST_CASE("next_above is std::nextafter towards +infinity for finite values") {
  std::vector<float> xs = {0.0f, -0.0f, 1.0f, -1.0f, 63.0f, 64.0f, 16777215.0f, -16777216.0f,
                           std::numeric_limits<float>::denorm_min(), -std::numeric_limits<float>::denorm_min(),
                           std::numeric_limits<float>::min(), -std::numeric_limits<float>::min(),
                           std::numeric_limits<float>::max(), -std::numeric_limits<float>::max()};
  std::mt19937 rng(5);
  std::uniform_int_distribution<uint32_t> bits;
  while (xs.size() < 100000) {
    const uint32_t b = bits(rng);
    float x;
    std::memcpy(&x, &b, sizeof x);
    if (std::isfinite(x)) xs.push_back(x);
  }
  for (float x : xs) {
    const float want = std::nextafter(x, std::numeric_limits<float>::infinity());
    REQUIRE(same_bits(keyanim::internal::next_above(x), want));
  }
}
