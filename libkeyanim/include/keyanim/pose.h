// Engine-ready poses: a rotation quaternion and a translation per node.
#pragma once
#include <cstdint>

namespace keyanim {

// One node's transform. 32 bytes, so that an array of them is 16-byte aligned throughout.
// rotation is a unit quaternion (x, y, z, w) in that order; translation is in the file's length
// units. As a matrix acting on column vectors: p' = R(rotation) p + translation.
struct Transform {
  float rotation[4] = {0.0f, 0.0f, 0.0f, 1.0f};
  float translation[3] = {0.0f, 0.0f, 0.0f};
  float reserved = 0.0f;  // always 0 (padding)
};

// How position channels on a node combine with its OFFSET. BVH readers disagree: Blender
// replaces the OFFSET component by the channel's value, three.js adds the value to it. Choose
// the one your BVH source meant (on files without such channels they agree).
enum class PositionReading : uint8_t {
  replace = 0,  // translation component = channel value (Blender; keyanim's default)
  add = 1,      // translation component = OFFSET component + channel value (three.js)
};

}  // namespace keyanim
