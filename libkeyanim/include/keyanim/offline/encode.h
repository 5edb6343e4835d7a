// The codec core: choose key frames per channel, fit tensions, quantize key values, and (in the
// default mode) guarantee a maximum world-space error of the measured points (joints, End Sites
// and the shell points around each joint: metrics.h) for what a decoder will produce.
#pragma once
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "keyanim/cardinal.h"
#include "keyanim/rotation.h"
#include "keyanim/offline/error.h"
#include "keyanim/offline/metrics.h"
#include "keyanim/offline/motion.h"

namespace keyanim::offline {

enum class KeyMode : uint8_t {
  error = 0,      // fewest keys such that every measured point (metrics.h) stays within the tolerance
  uniform = 1,    // every N-th frame
  manual = 2,     // the user's frames
  curvature = 3,  // curvature feature points (curvature.h)
};

// What encode() is doing, for a progress display.
enum class EncodeStage : uint8_t {
  fitting = 0,    // choosing keys and fitting the curves, channel by channel
  verifying = 1,  // error mode: every joint of the decoded frames against the original
  measuring = 2,  // the error report, on exactly what a decoder reproduces
};

// How rotations are stored.
enum class Rotations : uint8_t {
  // A joint with three rotation channels (consecutive, about three axes) whose rotation stays
  // within 145 degrees of one reference over the clip as the x, y, z curves of its rotation
  // relative to that reference, on key frames shared by the three (spec/FORMAT.md section 4.7,
  // a version 5 file): a pose then needs no sines and cosines and one search per joint; other
  // joints keep their Euler channels. sample() still gives every channel's Euler angle.
  quaternion = 0,
  // Every rotation as its Euler channels, keyed one by one: a version 3 file, which decoders of
  // versions 3 and 4 read, and whose keys are the BVH's own angles.
  euler = 1,
};

struct EncodeSettings {
  KeyMode key_mode = KeyMode::error;       // Defaults to error-bounded.
  Rotations rotations = Rotations::quaternion;  // Defaults to quaternion.
  double tolerance = 0.05;                 // Defaults to 0.05 (percent of the skeleton size).
  bool tolerance_in_percent = true;        // Defaults to true; false: file length units.
  double shell = kDefaultShellPercent;     // Defaults to 2 (percent of the skeleton size): distance of
                                           // the shell points the error covers (metrics.h); 0: none.
  bool shell_in_percent = true;            // Defaults to true; false: file length units.
  uint32_t uniform_interval = 10;          // uniform mode: Defaults to every 10th frame (>= 1).
  std::vector<uint32_t> manual_frames;     // manual mode: frame numbers (validated).
  bool fit_tension = false;                // Defaults to false: fixed tension (below).
  float tension = 0.0f;                    // Defaults to 0 (Catmull-Rom). Range [-1, 1].
  TangentRule tangent_rule = TangentRule::step_adjusted;  // Defaults to step-adjusted.
  bool allow_linear = true;                // Defaults to true: a channel may pick linear if cheaper.
  bool force_linear = false;               // Defaults to false. True: every channel linear (comparisons).
  std::optional<int> zstd_level;           // Defaults to none: each section at its measured
                                           // parameters (write_kanim); a level (1..22): every section.
  uint32_t threads = 1;                    // Defaults to 1; 0: one per core. Output is the same.
  // Defaults to none. Called as encode() works: the stage and the fraction of it done, 0 to 1.
  // Error mode runs fitting and verifying in rounds until every joint is within the tolerance,
  // each round's stages counting from 0 again. Called on the thread that called encode(), never
  // concurrently, at most once per channel or frame: keep it cheap. The result does not depend
  // on it.
  std::function<void(EncodeStage stage, double fraction)> progress;

  // Throws Error (invalid_argument) saying what is wrong, if anything.
  void validate() const;
};

// One channel as the container stores it.
struct EncodedChannel {
  Interpolation interp = Interpolation::cardinal;
  float tension = 0.0f;
  double step = 1.0;             // quantization step; key value = dequantize(q, step)
  std::vector<uint32_t> frames;  // key frames, strictly increasing; empty = all zeros
  std::vector<int64_t> q;        // quantized key values
};

struct EncodedClip {
  Skeleton skeleton;
  uint32_t frame_count = 0;
  double frame_time = 0.0;
  TangentRule tangent_rule = TangentRule::step_adjusted;
  std::vector<EncodedChannel> channels;
  // Nodes whose rotation is stored as quaternion curves (spec section 4.7), in increasing node
  // order: each one's rotation channels c, c + 1, c + 2 (quaternion_capable) hold x, y, z of its
  // rotation relative to the node's reference, with the same interpolation, tension and key
  // frames (steps may differ). Empty: every rotation is its Euler channels (a 3.0 file).
  std::vector<QuatNode> quat_nodes;
  std::string notes;  // informative key=value lines (settings, achieved error)
};

struct EncodeResult {
  EncodedClip clip;
  ErrorReport error;          // measured by FK on exactly what a decoder reproduces
  double tolerance_units = 0; // the tolerance in file length units
  double shell_units = 0;     // the shell distance in file length units (error.shell)
  uint64_t total_keys = 0;
  uint32_t iterations = 0;    // verify-and-tighten rounds (error mode)
};

// The motion encoded. Throws Error: invalid_argument for settings that make no sense (validate),
// a manual key frame beyond the motion, or a tolerance in percent for a skeleton without
// extent; malformed for a motion the codec cannot take or a clip no .kanim may hold (a frame
// time of 0 with several frames; a value whose key overflows in the fixed-key modes); limit
// when the tolerance cannot be reached (below binary32 precision).
EncodeResult encode(const Motion& motion, const EncodeSettings& settings);

// What a tolerance in percent is a percent of: the skeleton size (fk.h), or for a skeleton with
// no extent (a lone root) the largest side of the box its nodes sweep over the clip.
double reference_size(const Motion& motion);

// Unwraps a rotation channel in place so that no step exceeds 180 degrees.
void unwrap_degrees(std::vector<double>& signal);

}  // namespace keyanim::offline
