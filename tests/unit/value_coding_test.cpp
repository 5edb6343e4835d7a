// KVAL's extrapolation (spec 4.5) against the exact rational rounding, computed independently
// in 128-bit integers: round half up of d * g1 / g0, inside the bounds; d itself outside.
#include <doctest/doctest.h>

#include <cstdint>
#include <random>

#include "internal/value_coding.h"

namespace {

__extension__ typedef __int128 i128;  // GCC and Clang; the library itself needs only int64

int64_t reference(int64_t d, uint32_t g0, uint32_t g1) {
  if (d <= -(int64_t(1) << 40) || d >= (int64_t(1) << 40) || g0 >= 65536 || g1 >= 65536) return d;
  // Smallest n with n > d g1 / g0 - 1/2, i.e. floor(d g1 / g0 + 1/2), from the exact product.
  const i128 num = i128(d) * g1;
  i128 q = num / g0;
  if (num % g0 != 0 && num < 0) --q;  // floor
  const i128 rem = num - q * g0;  // 0 <= rem < g0
  if (2 * rem >= g0) ++q;             // halves go up
  return int64_t(q);
}

}  // namespace

TEST_CASE("extrapolated delta is d * g1 / g0 rounded half up, within its bounds") {
  using keyanim::internal::extrapolated_delta;
  CHECK(extrapolated_delta(3, 2, 1) == 2);     // 1.5 -> 2
  CHECK(extrapolated_delta(-3, 2, 1) == -1);   // -1.5 -> -1
  CHECK(extrapolated_delta(-5, 3, 1) == -2);   // -1.67 -> -2
  CHECK(extrapolated_delta(7, 1, 3) == 21);
  CHECK(extrapolated_delta(0, 5, 9) == 0);
  CHECK(extrapolated_delta((int64_t(1) << 40) - 1, 1, 65535) == ((int64_t(1) << 40) - 1) * 65535);
  CHECK(extrapolated_delta(int64_t(1) << 40, 1, 2) == int64_t(1) << 40);  // out of range: d
  CHECK(extrapolated_delta(10, 65536, 1) == 10);
  CHECK(extrapolated_delta(10, 1, 65536) == 10);
  std::mt19937_64 rng(11);
  for (int i = 0; i < 200000; ++i) {
    const int shift = 1 + int(rng() % 42);  // magnitudes below 2^1 .. 2^42: both sides of 2^40
    const int64_t d = int64_t(rng() >> (64 - shift)) * (rng() & 1 ? -1 : 1);
    const uint32_t g0 = 1 + uint32_t(rng() % (i % 3 ? 9 : 70000)), g1 = 1 + uint32_t(rng() % (i % 5 ? 9 : 70000));
    REQUIRE(extrapolated_delta(d, g0, g1) == reference(d, g0, g1));
  }
}

TEST_CASE("predictions use only earlier keys") {
  using keyanim::internal::predict_q;
  using keyanim::internal::ValueCoding;
  const uint32_t k[4] = {0, 2, 3, 7};
  CHECK(predict_q(ValueCoding::extrapolate, k, 0, 99, 98) == 0);
  CHECK(predict_q(ValueCoding::extrapolate, k, 1, 10, 0) == 10);
  CHECK(predict_q(ValueCoding::delta, k, 2, 16, 10) == 16);
  CHECK(predict_q(ValueCoding::extrapolate, k, 2, 16, 10) == 19);  // 16 + 6 * 1 / 2
  CHECK(predict_q(ValueCoding::extrapolate, k, 3, 19, 16) == 31);  // 19 + 3 * 4 / 1
}
