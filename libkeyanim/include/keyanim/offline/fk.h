// Forward kinematics: the ground truth for every error keyanim reports.
//
// Rules (spec/FORMAT.md states the same): a node's local rotation is the product of its Euler
// channels in the order its CHANNELS line lists them (intrinsic), R = R_1 * R_2 * R_3, angles in
// degrees. Its local translation is its OFFSET, except that each position channel it has
// replaces the matching OFFSET component (PositionReading::replace, as Blender reads BVH; the
// default) or is added to it (PositionReading::add, as three.js does). World: p = p_parent +
// R_parent_world * t_local, R_world = R_parent_world * R_local. A root (parent -1) starts from
// the identity at the origin; an End Site has no channels, so its translation is its OFFSET.
//
// Elementary rotations are the right-handed ones: Rx(a) = [1 0 0; 0 c -s; 0 s c],
// Ry(a) = [c 0 s; 0 1 0; -s 0 c], Rz(a) = [c -s 0; s c 0; 0 0 1].
// Sine and cosine are computed after reducing the angle to the nearest multiple of 90 degrees,
// so multiples of 90 are exact and an angle and the same angle +-360 give the same pose; the
// reduced angle goes through fdlibm's kernels (within 1 ulp), not the platform's libm, so FK
// gives the same bits on every platform.
//
// Nodes must be stored parents first (parent < own index) and first_channel must be assigned
// (Skeleton::assign_channel_columns); a node whose parent index is not smaller than its own is
// treated as a root rather than read out of bounds.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "keyanim/offline/motion.h"
#include "keyanim/pose.h"
#include "keyanim/rotation.h"

namespace keyanim::offline {

using Vec3 = std::array<double, 3>;
using Mat3 = std::array<double, 9>;  // row-major
using Quat = std::array<double, 4>;  // x, y, z, w (glTF's and keyanim::Transform's order)

// A clip's quaternion nodes (spec section 4.7), for FK of its stored values (the encoder's
// verification): such a node's rotation channels hold x, y, z of its rotation relative to its
// reference, and its rotation is keyanim/rotation.h's stored_rotation in binary64, not the
// product of Euler angles. Per node, the index of its QuatNode (-1: Euler channels); per
// QuatNode, its reference widened to binary64, its node and the column of its x.
struct QuatForms {
  std::vector<int32_t> of_node;
  std::vector<std::array<double, 4>> reference;
  std::vector<uint32_t> node, column;
  QuatForms() = default;
  // `nodes` follow section 4.7 (increasing, each quaternion_capable); channel columns assigned.
  QuatForms(const Skeleton& skeleton, const std::vector<QuatNode>& nodes);
  bool empty() const noexcept { return reference.empty(); }
};

// Rotation matrix of one joint from its channel values (frame row), Euler order as listed.
Mat3 local_rotation(const Joint& joint, const double* frame_row);
// The same rotation as a unit quaternion, q = q_1 q_2 q_3 over the channels in order (the
// identity for a node without rotation channels), with the sines and cosines FK uses.
Quat local_quaternion(const Joint& joint, const double* frame_row);
// Rotation by `degrees` about axis 0, 1 or 2 (x, y, z): (sin(a/2) axis, cos(a/2)).
Quat axis_quaternion(int axis, double degrees);
// a * b (Hamilton product): b applied first.
Quat quat_multiply(const Quat& a, const Quat& b) noexcept;

// World positions of every node (joints and End Sites) for one frame row of values.
// `out` is resized to skeleton.joints.size(). Allocates nothing once `out` and a per-thread
// scratch buffer have reached the skeleton's size.
void world_positions(const Skeleton& skeleton, const double* frame_row, std::vector<Vec3>& out,
                     PositionReading reading = PositionReading::replace);

// The same for the nodes j with nodes[j] != 0 only, a set that must hold every ancestor of
// its members (positions of the other nodes are left as they were): for callers that know
// which nodes moved.
void world_positions(const Skeleton& skeleton, const double* frame_row, const uint8_t* nodes, std::vector<Vec3>& out,
                     PositionReading reading = PositionReading::replace);
// Two frames at once (two lanes of SIMD where the machine has them), bit for bit what two
// calls of the above give; `nodes` may be null (every node).
void world_positions(const Skeleton& skeleton, const double* row_a, const double* row_b, const uint8_t* nodes,
                     std::vector<Vec3>& out_a, std::vector<Vec3>& out_b,
                     PositionReading reading = PositionReading::replace);
// Four points per node for two frame rows: node j's world position at out[4 j], then at
// out[4 j + 1 + a] the point `distance` along column a of its world rotation (for an End Site,
// or with distance 0, copies of its position), each computed as p + distance * R[.][a] from
// what world_pose gives, bit for bit.
// With add_a and add_b (`reading` replace), the points under the add reading too, bit for bit a
// second call with it: the rotations are computed once for both.
// With `quats`, rows of a clip's stored values (QuatForms).
void world_points(const Skeleton& skeleton, const double* row_a, const double* row_b, const uint8_t* nodes,
                  PositionReading reading, double distance, std::vector<Vec3>& out_a, std::vector<Vec3>& out_b,
                  std::vector<Vec3>* add_a = nullptr, std::vector<Vec3>* add_b = nullptr,
                  const QuatForms* quats = nullptr);
// Four frame rows at once, into out[0..4) (and out_add, as above): bit for bit what the above
// gives for rows 0 and 1, then 2 and 3; in four AVX lanes on x86-64-v3 machines
// (internal/cpu.h; KEYANIM_CPU caps it).
void world_points(const Skeleton& skeleton, const std::array<const double*, 4>& rows, const uint8_t* nodes,
                  PositionReading reading, double distance, std::array<std::vector<Vec3>, 4>& out,
                  std::array<std::vector<Vec3>, 4>* out_add = nullptr, const QuatForms* quats = nullptr);

// The same, with the sine and cosine of every rotation channel given (sin_cos_deg of the
// row's value, at the channel's column): for callers that re-pose frames in which few values
// change. Bit-identical to the plain call (replace reading).
void world_positions(const Skeleton& skeleton, const double* frame_row, const double* sines,
                     const double* cosines, std::vector<Vec3>& out);
// sin and cos of an angle in degrees, exactly as FK computes them.
void sin_cos_deg(double deg, double& s, double& c) noexcept;
// World positions and world rotations (R_world of each node; an End Site's is its parent's).
// With `quats`, the row is a clip's stored values (QuatForms).
void world_pose(const Skeleton& skeleton, const double* frame_row, std::vector<Vec3>& positions,
                std::vector<Mat3>& rotations, PositionReading reading = PositionReading::replace,
                const QuatForms* quats = nullptr);

// World positions for every frame: result[f * node_count + j]. Throws Error (invalid_argument)
// if the values do not fill frames x channels or the channel columns are not consistent.
std::vector<Vec3> world_positions_all(const Motion& motion, PositionReading reading = PositionReading::replace);

// True when a node other than a root has position channels: then the two readings of them
// (PositionReading) pose the skeleton differently.
bool has_position_channels_below_root(const Skeleton& skeleton) noexcept;

// True when every node's channels lie inside a frame row (first_channel + channel count <=
// channel_count()). FK of a skeleton for which this is false would read past the row.
bool channel_columns_consistent(const Skeleton& skeleton) noexcept;

// Largest side of the bounding box of the rest pose built from OFFSETs alone (End Sites
// included). Tolerances given in percent are relative to this.
double skeleton_size(const Skeleton& skeleton);

}  // namespace keyanim::offline
