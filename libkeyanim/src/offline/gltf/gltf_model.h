// The glTF export's in-memory asset, shared by its parts (keyanim/offline/gltf.h):
//   gltf_curves.cpp  clip channels as curves, translations mapped exactly
//   gltf_player.cpp  what a glTF player computes from the asset, and its forward kinematics
//   gltf_verify.cpp  the clip's forward kinematics against the player's, per point and frame
//   gltf_fit.cpp     keys fitted within the world-space tolerance (rotations; translations for
//                    LINEAR-only output)
//   gltf_skin.cpp    the skin: inverse bind matrices, the mesh drawn as the bones
//   gltf_buffer.cpp  the packed buffer, its views and accessors
//   gltf_writer.cpp  the JSON and the GLB container
//   gltf_export.cpp  export_gltf: options, the frame window, putting it together
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "keyanim/clip.h"
#include "gltf_skin.h"
#include "keyanim/offline/fk.h"

namespace keyanim::offline::gltf {

enum class Interp : uint8_t { linear, cubic };

// One animation sampler, as stored: times in seconds and values, both float32.
struct Sampler {
  Interp interp = Interp::linear;
  int components = 3;         // 3: translation, 4: rotation (x, y, z, w as glTF orders them)
  std::vector<float> times;
  std::vector<float> values;  // linear: times.size() * components; cubic: 3 times that, per key
                              // in-tangent, value, out-tangent (tangents per second)
  size_t key_count() const noexcept { return times.size(); }
  bool operator==(const Sampler&) const = default;
};

struct NodeAnimation {
  std::optional<Sampler> translation;
  std::optional<Sampler> rotation;
};

// Source frames [first, last] of the clip, played from time 0.
struct Window {
  uint32_t first = 0;
  uint32_t last = 0;
  double frame_time = 0.0;
  uint32_t frames() const noexcept { return last - first + 1; }
  // The player's time of source frame f (f >= first), in binary64 as a player computes it.
  double time(uint32_t f) const noexcept { return double(f - first) * frame_time; }
};

struct Model {
  Skeleton skeleton;                 // nodes: joints and End Sites, parents first
  std::vector<NodeAnimation> nodes;  // per node; empty optionals keep the rest pose
  std::string animation_name;
  Skin skin;                         // empty: no skin, no mesh
  std::string extras_json;           // asset.extras, a JSON object (may be empty)
  std::string timing_json;           // the scene's and the animation's extras (may be empty)
};

// A quaternion in glTF's order: x, y, z, w.
using Quat = std::array<double, 4>;

}  // namespace keyanim::offline::gltf
