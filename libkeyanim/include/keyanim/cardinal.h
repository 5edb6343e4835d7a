// Cardinal-spline evaluation: the one piece of arithmetic that the encoder (when it verifies
// its error) and every decoder must compute identically. spec/FORMAT.md, appendix A, is the
// normative text. The building blocks below are templates over the number type, so that the
// scalar paths (float) and the SIMD paths of the runtime (4 or 8 channels at once) instantiate
// the very same expressions, operation for operation; the reference functions at the end
// (eval_channel and its parts) are written with them too. Header-only so that the encoder and
// the runtime compile the very same code (with -ffp-contract=off: no fused multiply-add).
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

// ---- Appendix A, piece by piece. T is float or a SIMD vector of floats with the same operators.

// Local parameter of position f in the segment from key frame k0 to k1.
template <class T>
inline T segment_u(T f, T k0, T k1) noexcept {
  return (f - k0) / (k1 - k0);
}

// Step-adjusted tangent scale of a segment of length len whose neighbour on the other side of
// the key has length other: a0 = 2 len / (len_in + len), a1 = 2 len / (len + len_out). (IEEE
// addition is commutative, so one expression serves both.) Equal lengths give exactly 1.
template <class T>
inline T tangent_scale(T len, T other) noexcept {
  return T(2.0f) * len / (len + other);
}

// What a segment's value depends on besides u: its start value, rise and end tangents.
template <class T>
struct Operands {
  T p0, d, m0, m1;
};

// Cardinal operands from the four keys around the segment (pm, p0, p1, p2), s and the tangent
// scales a0, a1 (1 with the uniform rule).
template <class T>
inline Operands<T> cardinal_operands(T pm, T p0, T p1, T p2, T s, T a0, T a1) noexcept {
  return {p0, p1 - p0, s * a0 * (p1 - pm), s * a1 * (p2 - p0)};
}

// The cardinal segment's value at u: h00 = 1 - h01 folded in, so that equal keys with zero
// tangents give exactly the key value.
template <class T>
inline T hermite(const Operands<T>& o, T u) noexcept {
  const T u2 = u * u;
  const T u3 = u2 * u;
  const T h01 = T(-2.0f) * u3 + T(3.0f) * u2;
  const T h10 = u3 - T(2.0f) * u2 + u;
  const T h11 = u3 - u2;
  return o.p0 + h01 * o.d + h10 * o.m0 + h11 * o.m1;
}

// The linear segment's value at u.
template <class T>
inline T linear_value(T p0, T d, T u) noexcept {
  return p0 + u * d;
}

// ---- Reference evaluation over a channel's key arrays (tests, the encoder, tools).

// Operands of segment j (between keys j and j+1, 0 <= j < n-1) of a channel whose n >= 2 keys
// sit at strictly increasing frames `frames` with values `values`. End points are duplicated:
// P_{-1} = P_0 and P_n = P_{n-1}, and the tangent scale at the first and last key is 1.
struct SegmentOperands {
  Operands<float> o{};
  bool linear = false;
};

// A key of a segment's window (the segment's two keys and the one on either side of them).
struct WindowKey {
  uint32_t frame = 0;
  float value = 0.0f;
};

// Operands of the segment from key k0 to key k1, with the key before k0 (`before`) and after
// k1 (`after`) where the channel has them. A missing one (null, at the channel's ends) is an
// end point duplicated, as segment_operands does: its value is the nearer key's and its
// tangent scale 1.
inline SegmentOperands window_operands(const WindowKey* before, WindowKey k0, WindowKey k1, const WindowKey* after,
                                       Interpolation interp, float s, TangentRule rule) noexcept {
  SegmentOperands r;
  r.linear = interp == Interpolation::linear;
  if (r.linear) {
    r.o = {k0.value, k1.value - k0.value, 0.0f, 0.0f};
    return r;
  }
  const float pm = before ? before->value : k0.value;
  const float p2 = after ? after->value : k1.value;
  float a0 = 1.0f;
  float a1 = 1.0f;
  if (rule == TangentRule::step_adjusted) {
    const float len = static_cast<float>(k1.frame - k0.frame);
    if (before) a0 = tangent_scale(len, static_cast<float>(k0.frame - before->frame));
    if (after) a1 = tangent_scale(len, static_cast<float>(after->frame - k1.frame));
  }
  r.o = cardinal_operands(pm, k0.value, k1.value, p2, s, a0, a1);
  return r;
}

inline SegmentOperands segment_operands(const uint32_t* frames, const float* values, uint32_t n, uint32_t j,
                                        Interpolation interp, float s, TangentRule rule) noexcept {
  const WindowKey before{j > 0 ? frames[j - 1] : 0u, j > 0 ? values[j - 1] : 0.0f};
  const WindowKey after{j + 2 < n ? frames[j + 2] : 0u, j + 2 < n ? values[j + 2] : 0.0f};
  return window_operands(j > 0 ? &before : nullptr, {frames[j], values[j]}, {frames[j + 1], values[j + 1]},
                         j + 2 < n ? &after : nullptr, interp, s, rule);
}

// The segment's value at local parameter u in [0, 1].
inline float eval_operands(const SegmentOperands& s, float u) noexcept {
  return s.linear ? linear_value(s.o.p0, s.o.d, u) : hermite(s.o, u);
}

// Value of segment j at local parameter u in [0, 1].
inline float eval_segment(const uint32_t* frames, const float* values, uint32_t n, uint32_t j, float u,
                          Interpolation interp, float s, TangentRule rule) noexcept {
  return eval_operands(segment_operands(frames, values, n, j, interp, s, rule), u);
}

// Local parameter of frame position f in the segment from key frame k0 to k1 (binary32).
inline float segment_u(uint32_t k0, uint32_t k1, float f) noexcept {
  return segment_u(f, static_cast<float>(k0), static_cast<float>(k1));
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

// Value of a whole channel at frame position f (Appendix A). n = 0 means the channel is all
// zeros; n = 1 a constant. Outside [frames[0], frames[n-1]] the curve is clamped; exactly at a
// key it returns the key's value.
inline float eval_channel(const uint32_t* frames, const float* values, uint32_t n, float f,
                          Interpolation interp, float s, TangentRule rule) noexcept {
  if (n == 0) return 0.0f;
  if (n == 1 || !(f > static_cast<float>(frames[0]))) return values[0];
  if (f >= static_cast<float>(frames[n - 1])) return values[n - 1];
  const uint32_t j = find_segment(frames, n, f);
  if (f == static_cast<float>(frames[j])) return values[j];
  return eval_operands(segment_operands(frames, values, n, j, interp, s, rule), segment_u(frames[j], frames[j + 1], f));
}

// A stored key's value: the quantized integer times the channel's step, computed in binary64
// and rounded once to binary32.
inline float dequantize(int64_t q, double step) noexcept {
  return static_cast<float>(static_cast<double>(q) * step);
}

}  // namespace keyanim
