// A pose's quaternion tracks (version 5: a quaternion node whose three curves are block curves,
// spec 9.3), from their records straight to their rotations, 4 or 8 tracks per register.
// Internal to the runtime; Clip::sample_local calls it for a whole pose.
#pragma once
#include "keyanim/pose.h"
#include "runtime/image.h"

namespace keyanim::internal {

// The rotations at frame position f (not NaN) of img's quaternion tracks (its quaternion nodes
// 0 .. quat_tracks - 1) into out[node].rotation, out holding a whole pose. The same bits as
// sampling their curves and building each rotation from the values (pose.cpp).
void quat_track_rotations(const Image& img, float f, Transform* out) noexcept;

}  // namespace keyanim::internal
