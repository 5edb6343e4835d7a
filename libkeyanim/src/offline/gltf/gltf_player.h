// What a glTF player computes from the exported asset: samplers evaluated as the glTF 2.0
// specification (appendix C, interpolation) says and three.js does, and the forward kinematics
// of the node hierarchy. The export checks its rotation fit on exactly this.
#pragma once
#include <vector>

#include "gltf_model.h"

namespace keyanim::offline::gltf {

// How a player interpolates LINEAR rotations. The specification says slerp; three.js switches
// to normalised lerp when the keys' dot product is at least 0.9995; Blender's importer
// interpolates the components and normalises (nlerp).
enum class QuatLerp : uint8_t { slerp, nlerp, threejs };
inline constexpr QuatLerp kQuatLerps[] = {QuatLerp::slerp, QuatLerp::nlerp, QuatLerp::threejs};

// One segment between keys at float times t0 < t1, evaluated at time t in [t0, t1]. For
// LINEAR only v0 and v1 are read; for CUBICSPLINE out0 is key 0's out-tangent and in1 key 1's
// in-tangent (per second). Rotations (components == 4) of a cubic are normalised.
void eval_segment(Interp interp, int components, QuatLerp lerp, const float* v0, const float* out0, const float* in1,
                  const float* v1, double t0, double t1, double t, double* out) noexcept;

// The sampler's value at time t (seconds): clamped to the first and last keys.
void eval_sampler(const Sampler& s, double t, QuatLerp lerp, double* out) noexcept;

// Rotation matrix (row-major) of a quaternion x, y, z, w as three.js composes it: a non-unit
// quaternion (float rounding) is used as it is, not normalised.
Mat3 quat_matrix(const double* q) noexcept;

// World positions and rotations of every node at time t. Nodes without a sampler keep their
// rest pose (translation = OFFSET, no rotation).
void play_pose(const Model& model, double t, QuatLerp lerp, std::vector<Vec3>& positions, std::vector<Mat3>& rotations);

}  // namespace keyanim::offline::gltf
