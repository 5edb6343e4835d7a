// Cardinal-spline evaluation: the one piece of arithmetic that the encoder (when it verifies
// its error) and every decoder must compute identically. spec/FORMAT.md, appendix A, is the
// normative text; this is the reference implementation. Header-only so that the encoder and the
// runtime compile the very same expression.
#pragma once
#include <cstdint>

namespace keyanim {

// How a tangent is scaled at a key whose two neighbouring segments differ in length.
// Stored in .kanim files: append-only.
enum class TangentRule : uint8_t {
  uniform = 0,        // the method's rule: m_j = s (P_{j+1} - P_{j-1}) whatever the spacing
  step_adjusted = 1,  // Kochanek-Bartels: scale by 2 n_out / (n_in + n_out) (or n_in)
};

// Interpolation between the keys of one channel. Stored in .kanim files: append-only.
enum class Interpolation : uint8_t {
  cardinal = 0,
  linear = 1,
};

// s = (1 - T) / 2 for tension T. T = 0 is Catmull-Rom (s = 0.5), T = 1 gives flat tangents.
inline float tension_to_s(float tension) noexcept { return (1.0f - tension) * 0.5f; }
inline float s_to_tension(float s) noexcept { return 1.0f - 2.0f * s; }

// What a segment's value depends on besides u: its start value, rise and end tangents.
struct SegmentOperands {
  float p0 = 0.0f;
  float d = 0.0f;   // p1 - p0
  float m0 = 0.0f;  // tangents (cardinal only)
  float m1 = 0.0f;
  bool linear = false;
};

// Operands of segment j (between keys j and j+1, 0 <= j < n-1) of a channel whose n >= 2 keys
// sit at strictly increasing frames `frames` with values `values`. End points are duplicated:
// P_{-1} = P_0 and P_n = P_{n-1}.
inline SegmentOperands segment_operands(const uint32_t* frames, const float* values, uint32_t n, uint32_t j,
                                        Interpolation interp, float s, TangentRule rule) noexcept {
  SegmentOperands o;
  const float p0 = values[j];
  const float p1 = values[j + 1];
  o.p0 = p0;
  o.d = p1 - p0;
  o.linear = interp == Interpolation::linear;
  if (o.linear) return o;
  const float pm = values[j > 0 ? j - 1 : 0];
  const float p2 = values[j + 2 < n ? j + 2 : n - 1];
  float a0 = 1.0f;  // tangent scale at key j (outgoing)
  float a1 = 1.0f;  // tangent scale at key j+1 (incoming)
  if (rule == TangentRule::step_adjusted) {
    const float len = static_cast<float>(frames[j + 1] - frames[j]);
    if (j > 0) {
      const float len_in = static_cast<float>(frames[j] - frames[j - 1]);
      a0 = 2.0f * len / (len_in + len);
    }
    if (j + 2 < n) {
      const float len_out = static_cast<float>(frames[j + 2] - frames[j + 1]);
      a1 = 2.0f * len / (len + len_out);
    }
  }
  o.m0 = s * a0 * (p1 - pm);
  o.m1 = s * a1 * (p2 - p0);
  return o;
}

// The segment's value at local parameter u in [0, 1].
inline float eval_operands(const SegmentOperands& o, float u) noexcept {
  if (o.linear) return o.p0 + u * o.d;
  const float u2 = u * u;
  const float u3 = u2 * u;
  const float h01 = -2.0f * u3 + 3.0f * u2;
  const float h10 = u3 - 2.0f * u2 + u;
  const float h11 = u3 - u2;
  // h00 = 1 - h01 folded in: equal keys with zero tangents give exactly the key value.
  return o.p0 + h01 * o.d + h10 * o.m0 + h11 * o.m1;
}

// Value of segment j at local parameter u in [0, 1].
inline float eval_segment(const uint32_t* frames, const float* values, uint32_t n, uint32_t j,
                          float u, Interpolation interp, float s, TangentRule rule) noexcept {
  return eval_operands(segment_operands(frames, values, n, j, interp, s, rule), u);
}

// Local parameter of frame position f in the segment from key frame k0 to k1 (binary32).
inline float segment_u(uint32_t k0, uint32_t k1, float f) noexcept {
  const float a = static_cast<float>(k0);
  return (f - a) / (static_cast<float>(k1) - a);
}

// Segment containing frame position f (keys frames[0..n-1], n >= 2, f clamped by the caller
// to [frames[0], frames[n-1]]): the largest j < n-1 with frames[j] <= f. Binary search.
inline uint32_t find_segment(const uint32_t* frames, uint32_t n, float f) noexcept {
  uint32_t lo = 0, hi = n - 1;  // invariant: frames[lo] <= f, and the answer is < hi
  while (hi - lo > 1) {
    const uint32_t mid = (lo + hi) / 2;
    if (static_cast<float>(frames[mid]) <= f) lo = mid; else hi = mid;
  }
  return lo;
}

// Value of a whole channel at frame position f. n = 0 means the channel is all zeros; n = 1 a
// constant. Outside [frames[0], frames[n-1]] the curve is clamped; exactly at a key it returns
// the key's value.
inline float eval_channel(const uint32_t* frames, const float* values, uint32_t n, float f,
                          Interpolation interp, float s, TangentRule rule) noexcept {
  if (n == 0) return 0.0f;
  if (n == 1 || !(f > static_cast<float>(frames[0]))) return values[0];
  if (f >= static_cast<float>(frames[n - 1])) return values[n - 1];
  const uint32_t j = find_segment(frames, n, f);
  if (f == static_cast<float>(frames[j])) return values[j];
  return eval_segment(frames, values, n, j, segment_u(frames[j], frames[j + 1], f), interp, s, rule);
}

}  // namespace keyanim

namespace keyanim {
// A stored key's value: the quantized integer times the channel's step, computed in binary64
// and rounded once to binary32.
inline float dequantize(int64_t q, double step) noexcept {
  return static_cast<float>(static_cast<double>(q) * step);
}
}  // namespace keyanim
