// Sampling the runtime image (image.h): any set of channels at any frame position, exactly as
// Appendix A of spec/FORMAT.md computes them. Internal to the runtime; Clip and Cursor call it.
#pragma once
#include <cstdint>

#include "keyanim/cardinal.h"
#include "runtime/image.h"

namespace keyanim::internal {

// Every channel at frame position f (not NaN): out[c] for c < channel count.
void sample_all(const Image& img, float f, float* out) noexcept;
// The listed channels (each < channel count): out[i] for channels[i].
void sample_listed(const Image& img, float f, const uint32_t* channels, uint32_t count, float* out) noexcept;

// The channels first .. first + count - 1 (each < channel count): out[i] for channel first + i.
void sample_range(const Image& img, float f, uint32_t first, uint32_t count, float* out) noexcept;

// One curve's segment around f, prepared for playback: while lo <= f < hi the curve's value is
// `value` if `direct`, else the segment polynomial at segment_u(f, k0, k1) (hermite, or
// linear_value when `linear`). Computed with the same building blocks as sample_all, so the
// values are identical.
struct Segment {
  float lo = 0.0f, hi = 0.0f;
  float k0 = 0.0f, k1 = 1.0f;
  Operands<float> o{};
  float value = 0.0f;
  bool direct = true;
  bool linear = false;
};
void locate_segment(const Image& img, uint32_t curve, float f, Segment& out) noexcept;

}  // namespace keyanim::internal
