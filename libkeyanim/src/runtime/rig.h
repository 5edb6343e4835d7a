// A rig: the skeleton of a loaded clip and the pose tables built from it. Every clip of one
// character has the same one, so clips loaded through one RigCache (keyanim/clip.h) share a
// single Rig instead of holding a copy each. Internal to the runtime.
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "internal/format.h"
#include "keyanim/skeleton.h"

namespace keyanim::internal {

// Nodes whose rotation is their Euler channels, grouped by the axes of those channels in order
// (Z X Y for most BVH joints, none for End Sites), so that 4 or 8 nodes of a group become
// quaternions in one register per component, one step per channel (pose.cpp).
struct EulerGroups {
  struct Group {
    uint32_t node_first, node_count;  // its nodes: node[node_first ..), in increasing order
    uint32_t column_first;            // step k's columns: column[column_first + k * node_count ..)
    uint32_t steps;                   // rotation channels per node (<= kMaxNodeChannels)
    uint8_t axis[kMaxNodeChannels];   // their axes in composition order: 0 X, 1 Y, 2 Z
  };
  std::vector<Group> groups;
  std::vector<uint32_t> node, column;
  size_t bytes() const noexcept;
};
// The groups of `skeleton`'s nodes, but those whose `skip` entry is set (none when null).
EulerGroups euler_groups(const Skeleton& skeleton, const std::vector<uint8_t>* skip = nullptr);

struct Rig {
  Skeleton skeleton;
  uint64_t hash = 0;  // rig_hash(skeleton)
  // Poses (pose.cpp). node_offset: 4 per node, its OFFSET in binary32 and a 0 (Transform's
  // translation and reserved, one copy). Rotations: every node's Euler channels (a clip that
  // stores some nodes as quaternions has its own groups: Image::euler). Positions: every
  // position channel, in node order.
  struct Move {
    uint32_t node, column;
    uint32_t axis;  // 0 X, 1 Y, 2 Z
  };
  std::vector<float> node_offset;
  EulerGroups euler;
  std::vector<Move> moves;

  // The Euler groups of the nodes that a set of quaternion nodes (version 5) leaves, made once
  // per set and shared by the rig's clips (a character's clips store the same joints as
  // quaternions): plan_rotations. At most kMaxQuatPlans sets; a clip of another makes its own.
  static constexpr size_t kMaxQuatPlans = 16;
  struct QuatPlan {
    std::vector<uint32_t> quat_nodes;  // increasing
    std::shared_ptr<const EulerGroups> euler;
  };
  mutable std::mutex plans_mutex;
  mutable std::vector<QuatPlan> plans;

  size_t bytes() const noexcept;  // everything the rig holds, itself included
};

// 64-bit FNV-1a of what makes two skeletons one rig: per node its name, parent, OFFSET bits,
// End Site flag and channel list, in node order. Equal skeletons have equal hashes; clips are
// shared only after a full comparison (same_rig), so a collision costs memory, never a pose.
uint64_t rig_hash(const Skeleton& skeleton) noexcept;
bool same_rig(const Skeleton& a, const Skeleton& b) noexcept;

// The rig of `skeleton`: its pose tables built, its arrays shrunk to size.
std::shared_ptr<const Rig> make_rig(Skeleton&& skeleton);

}  // namespace keyanim::internal
