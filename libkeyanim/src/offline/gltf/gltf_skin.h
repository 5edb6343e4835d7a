// The glTF export's skin: every node (joints and End Sites) is a joint of one skin, so that
// importers build an armature (Blender) or a THREE.Skeleton of Bones (three.js) instead of
// empties. glTF binds a skin through a mesh node, so the skin comes with the smallest mesh that
// draws the skeleton: one bone-shaped solid per segment (see make_skin).
#pragma once
#include <cstdint>
#include <vector>

#include "keyanim/skeleton.h"

namespace keyanim::offline::gltf {

struct Skin {
  // Per node, column-major 4x4 as glTF stores it: the inverse of the node's rest world matrix
  // (rest pose: translation = OFFSET, no rotation, so a translation by minus the rest position).
  std::vector<float> inverse_binds;
  // The mesh, in the rest pose's world space: 3 floats per vertex, the one node each vertex
  // follows with weight 1, and triangles (3 vertex indices each). Empty when no segment has a
  // length, or without GltfOptions::bone_mesh: then the skin is written without a mesh (glTF
  // allows it; Blender and three.js still build their bones from it).
  std::vector<float> positions;
  std::vector<uint32_t> joints;
  std::vector<uint32_t> indices;
  bool empty() const noexcept { return inverse_binds.empty(); }
  bool has_mesh() const noexcept { return !positions.empty(); }
};

// For each node n with a parent p and a non-zero OFFSET, a triangular bipyramid from p's rest
// position to n's, as thin as Blender's octahedral bones (ring of 3 vertices at 10% of the
// length, radius 10% of it): the tip follows n and the rest follows p, so the drawn bone joins
// the two joints in every pose, whatever n's translation does.
Skin make_skin(const Skeleton& skeleton);

}  // namespace keyanim::offline::gltf
