// Sampling the runtime image (image.h): any set of channels at any frame position, exactly as
// Appendix A of spec/FORMAT.md computes them. Internal to the runtime; Clip and Cursor call it.
#pragma once
#include <cstdint>

#include "keyanim/cardinal.h"
#include "runtime/image.h"

namespace keyanim::internal {

// Every channel at frame position f (not NaN): out[c] for c < channel count.
void sample_all(const Image& img, float f, float* out) noexcept;
// The same but the quaternion tracks' channels, left as they were: for a pose, which takes
// those tracks' rotations from quat_track_rotations (quat_tracks.h).
void sample_all_but_quat_tracks(const Image& img, float f, float* out) noexcept;
// The listed channels (each < channel count): out[i] for channels[i].
void sample_listed(const Image& img, float f, const uint32_t* channels, uint32_t count, float* out) noexcept;

// The channels first .. first + count - 1 (each < channel count): out[i] for channel first + i.
void sample_range(const Image& img, float f, uint32_t first, uint32_t count, float* out) noexcept;

}  // namespace keyanim::internal
