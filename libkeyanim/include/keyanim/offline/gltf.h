// glTF 2.0 export of a loaded clip: one node per joint and End Site, one animation that a
// glTF player (three.js, Babylon.js, Godot, Unity glTFast, Unreal, Blender) plays as keyanim
// decodes the clip.
//
// The skeleton as tools recognise one: every node is a joint of one skin (End Sites are leaf
// bones, named "End Site of PARENT" when unnamed, as keyanim names them everywhere), with
// inverse bind matrices of the rest pose, so that Blender builds one armature and three.js
// THREE.Bones. glTF binds a skin through a mesh node, so by default the skin comes with the
// smallest mesh that draws the bones (gltf_skin.h: a triangular bipyramid per segment, 5
// vertices and 6 triangles, about 120 bytes a bone); bone_mesh = false leaves it out. The source
// frame rate and the exported frame range are in the scene's, the animation's and the asset's
// extras ("keyanim": fps, source_frame_time, frame_count, first_frame, last_frame): glTF keeps
// only seconds, and Blender 3.4's importer places keys by the scene's rate (README).
//
// What is exact and what is fitted:
//  - Translations (position channels, and OFFSET components without one) become CUBICSPLINE
//    (LINEAR where every axis is linear or constant) whose keys are the union of the axes' key
//    frames. Every Cardinal segment is a cubic, and a cubic split at any time is the same
//    cubic, so the curve is exactly the clip's: values at key times are the decoder's values
//    bit for bit; tangents (Hermite tangents over the segment's duration) are rounded once to
//    float32. With linear_only, LINEAR keys are fitted instead, like rotations.
//  - Rotations: Euler curves are not quaternion splines, so quaternion keys are fitted (LINEAR,
//    or CUBICSPLINE where fewer bytes) until forward kinematics of what a glTF player computes
//    stays within the tolerance of the clip's own forward kinematics at every source frame, for
//    every joint, End Site and shell point (three points per joint at the shell distance along
//    its local x, y and z axes). LINEAR is checked both as the glTF spec's slerp and as the
//    normalised lerp some players use (three.js below 1.8 degrees, Blender), CUBICSPLINE as the
//    spec's spline, normalised.
//  - Times are seconds in float32, as glTF stores them; the checks evaluate at the player's
//    times, rounding included, in binary64 as three.js does, and keep a margin of 1e-6 of the
//    skeleton size for players that round differently (float32 arithmetic, normalising).
// Nodes carry the rest pose: translation = OFFSET, no rotation; the bone mesh's node is a scene
// root without a transform, after the joints' nodes. Lengths stay in the file's
// units (glTF assumes metres: a viewer may need to scale a clip captured in centimetres).
#pragma once
#include <cstdint>
#include <functional>
#include <string>

#include "keyanim/clip.h"
#include "keyanim/offline/error.h"

namespace keyanim::offline {

enum class EncodeStage : uint8_t;  // encode.h

struct GltfOptions {
  // World-space tolerance of the fit, in file length units, or in percent of the
  // skeleton size with tolerance_in_percent. Defaults to 0: the tolerance the clip was encoded
  // with (its encoder note tolerance_units), or 0.05% of the skeleton size (the encoder's
  // default) when the clip has no such note.
  double tolerance = 0.0;
  bool tolerance_in_percent = false;  // Defaults to false.
  // Shell points at this percent of the skeleton size (the size percentages are of: the largest
  // side of the rest-pose box, or of the box a skeleton without extent sweeps, as encode.h's
  // reference_size); 0 measures joints and End Sites only. Defaults to -1 (any negative): the
  // shell distance the clip was encoded with (its encoder note shell_units), or 2% (the
  // project's shell metric, metrics.h) when the clip has no such note.
  double shell_percent = -1.0;
  // Defaults to 0: sparse fitted keys. F > 0: LINEAR keys every 1/F s from the range's start,
  // and one at its end, no fit; the error is measured and reported, not bounded.
  double fps = 0.0;
  // Defaults to false. True: LINEAR keys only, translations fitted within the tolerance like
  // rotations, for players that ignore CUBICSPLINE tangents (Blender 3.4's importer keeps the
  // key values and lays its own Bezier handles through them).
  bool linear_only = false;
  // Defaults to true: the skin comes with a mesh drawing the bones (gltf_skin.h). False: the skin
  // alone (Debian's Blender 3.4 fails on any glTF mesh with its default Shading, see README).
  bool bone_mesh = true;
  uint32_t first_frame = 0;          // Defaults to 0: source frames to export (inclusive);
  uint32_t last_frame = UINT32_MAX;  // Defaults to the last frame. Time 0 is first_frame.
  // Defaults to "": a binary .glb. Otherwise a .gltf JSON whose buffer is the file at this URI
  // (relative, e.g. "walk.bin"), returned separately.
  std::string bin_uri;
  std::string name = "keyanim";      // the animation's name
  // Defaults to none. Called as export_gltf() works, with the stages of encode() (encode.h):
  // rounds of fitting keys (the fraction of the tracks refitted) and verifying them as a player
  // computes them (the fraction of the frames), until within the tolerance; then measuring the
  // report. With fps, measuring only. On the calling thread; the output does not depend on it.
  std::function<void(EncodeStage stage, double fraction)> progress;
};

struct GltfReport {
  double tolerance = 0.0;       // what keys were fitted within, file length units
  double shell_distance = 0.0;  // file length units (0: no shell points)
  // Largest distance, over the source frames of the range and every joint, End Site and shell
  // point, between the clip's forward kinematics and a glTF player's (the worse of slerp and
  // normalised lerp for LINEAR rotations), and where it is.
  double max_error = 0.0;
  uint32_t worst_node = 0;
  int worst_axis = -1;          // -1: the node itself; 0, 1, 2: its shell point on x, y, z
  uint32_t worst_frame = 0;     // source frame
  uint32_t nodes = 0;
  uint32_t translation_tracks = 0, translation_keys = 0;
  uint32_t linear_rotation_tracks = 0, cubic_rotation_tracks = 0, rotation_keys = 0;
  uint32_t rounds = 0;          // verification rounds of the fit (0 with fps)
};

struct GltfOutput {
  std::string main;  // the .glb, or the .gltf JSON when options.bin_uri is set
  std::string bin;   // the .bin buffer of a .gltf (may be empty: then no buffer is referenced)
  GltfReport report;
};

// Builds the asset. Throws Error: invalid_argument for options that make no sense (tolerance or
// fps not positive and finite, shell_percent not finite, an empty or reversed frame range,
// last_frame beyond the clip, a tolerance of 0 for a skeleton without extent) and for a clip
// whose frame time is not positive while it has several frames; limit for key times that
// glTF's float32 seconds cannot hold (beyond 3.4e38 s, or two keys on one float32 time), a
// tolerance that float32 keys cannot hold, or a range too long for one asset (working memory
// above 1 GiB, more than 2^24 resampled keys, 4 GiB of output).
GltfOutput export_gltf(const Clip& clip, const GltfOptions& options);

}  // namespace keyanim::offline
