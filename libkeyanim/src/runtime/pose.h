// Engine-ready poses from channel values: Euler angles to quaternions (vectorized sine and
// cosine), translations, and forward kinematics. Internal to the runtime.
#pragma once
#include <cstdint>

#include "keyanim/pose.h"
#include "runtime/image.h"

namespace keyanim::internal {

// Local transforms of nodes [first, last) from the values of their channels (columns
// skeleton.joints[first].first_channel onward, in order): out[i - first] for node i. With
// `tracks_done`, the quaternion tracks' rotations are left as they are (quat_track_rotations
// writes them).
void local_transforms(const Image& img, uint32_t first, uint32_t last, const float* values, PositionReading reading,
                      Transform* out, bool tracks_done = false) noexcept;

// Asks for the cache lines local_transforms reads (the rig's pose tables) and writes (the
// whole pose `out`, `nodes` transforms) of a whole pose, before the channels are sampled: a
// cold pose's misses then overlap the sampling instead of coming one after another.
void prefetch_pose_tables(const Image& img, Transform* out, uint32_t nodes) noexcept;

// Turns local transforms of every node (out[i] for node i) into model-space ones, in place.
void compose_model(const Image& img, Transform* out) noexcept;

}  // namespace keyanim::internal
