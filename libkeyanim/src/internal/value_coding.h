// How KVAL predicts a key's quantized value from the keys before it (spec/FORMAT.md 4.5),
// shared by the writer and the loader so that the two compute the very same integers.
#pragma once
#include <cstdint>

namespace keyanim::internal {

enum class ValueCoding : uint8_t {
  delta = 0,        // q_i - q_{i-1}
  extrapolate = 1,  // q_i - (q_{i-1} + the previous delta scaled to this key's gap)
};
inline constexpr uint8_t kMaxValueCoding = 1;

// Extrapolation is used only where its integers are small enough for int64 arithmetic.
inline constexpr int64_t kMaxExtrapolatedDelta = int64_t(1) << 40;  // |d| below this
inline constexpr uint32_t kMaxExtrapolatedGap = 1u << 16;           // both gaps below this
inline constexpr uint64_t kMaxAbsResidual = uint64_t(1) << 57;      // |residual| bound

// floor(a / b) for b > 0.
inline int64_t floor_div(int64_t a, int64_t b) noexcept {
  const int64_t q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}

// The delta expected between key i-1 (frame gap g1 after key i-2's gap g0) and key i:
// d = q_{i-1} - q_{i-2} scaled by g1 / g0 and rounded half up, i.e.
// floor((2 d g1 + g0) / (2 g0)); just d when the operands are out of range. |d| < 2^40 and
// g0, g1 < 2^16 keep 2 d g1 + g0 below 2^58.
inline int64_t extrapolated_delta(int64_t d, uint32_t g0, uint32_t g1) noexcept {
  if (d <= -kMaxExtrapolatedDelta || d >= kMaxExtrapolatedDelta || g0 >= kMaxExtrapolatedGap ||
      g1 >= kMaxExtrapolatedGap || g0 == 0)
    return d;
  // Exact shortcuts of the formula below for the usual gaps (a division costs tens of cycles):
  // equal gaps give floor(d + 1/2) = d, and g0 = 1 gives floor(d g1 + 1/2) = d g1.
  if (g0 == g1) return d;
  if (g0 == 1) return d * int64_t(g1);
  return floor_div(2 * d * int64_t(g1) + int64_t(g0), 2 * int64_t(g0));
}

// The prediction of q_i for key i of a channel with key frames k, from q_{i-1} (q1) and
// q_{i-2} (q2) (each ignored where it does not exist); the residual in KVAL is q_i minus this.
inline int64_t predict_q(ValueCoding coding, const uint32_t* k, uint32_t i, int64_t q1, int64_t q2) noexcept {
  if (i == 0) return 0;
  if (coding == ValueCoding::delta || i == 1) return q1;
  return q1 + extrapolated_delta(q1 - q2, k[i - 1] - k[i - 2], k[i] - k[i - 1]);
}

}  // namespace keyanim::internal
