// The encoder's input: checks that a motion can be encoded, and each channel as the signal the
// fitter works on (a column of the motion, unwrapped if it is an angle). Internal to the
// encoder; unwrap_degrees and reference_size are public (encode.h).
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "internal/quat_layout.h"
#include "keyanim/offline/motion.h"
#include "keyanim/rotation.h"

namespace keyanim::offline {

// Throws Error unless `motion` can be encoded: values and frames x channels disagree
// (invalid_argument), a value or a joint position is beyond what binary32 keys can hold
// (malformed). Positions are checked by FK, frame windows on `threads` threads.
void check_motion(const Motion& motion, unsigned threads);

// Per channel: the node it belongs to, whether it is a rotation, and what it stores (its own
// values, or a quaternion node's x, y or z: `quats`, the clip's QuatNodes, and per channel the
// index of its node's, or UINT32_MAX).
struct ChannelLayout {
  std::vector<uint32_t> node;
  std::vector<uint8_t> rotation;
  std::vector<internal::Stored> stored;
  std::vector<QuatNode> quats;
  std::vector<uint32_t> quat_of;
};
ChannelLayout channel_layout(const Skeleton& skeleton, const std::vector<QuatNode>& quats = {});

// Channel c of `motion` (laid out as `layout` says) over every frame into `out`: unwrapped
// (unwrap_degrees) if it is an Euler angle, the x, y or z of its node's relative rotation if it
// stores one (rotations.h). Reads a column of the frame-major values: the encoder keeps no copy
// of them.
void channel_signal(const Motion& motion, const ChannelLayout& layout, uint32_t c, std::vector<double>& out);

// Every channel's signal, made once for all the encoder's rounds where they take at most
// `budget` bytes (8 per value: one more copy of the motion); otherwise none are held and each
// round reads the columns again. Storage goes to the next clip encoded on the thread (spare.h).
class Signals {
 public:
  Signals() = default;
  Signals(const Motion& motion, const ChannelLayout& layout, size_t budget, unsigned threads);
  ~Signals();
  Signals(const Signals&) = delete;
  Signals& operator=(const Signals&) = delete;
  // channel_signal(motion, layout, c, out), from the held copy when there is one.
  void get(const Motion& motion, const ChannelLayout& layout, uint32_t c, std::vector<double>& out) const;
  // Quaternion node `quat`'s relative rotation (x, y, z, w: rotations.h's quat_signals), its x,
  // y, z from the held copy when there is one and w rebuilt from them.
  void get_quat(const Motion& motion, const ChannelLayout& layout, uint32_t quat,
                std::array<std::vector<double>, 4>& out) const;

 private:
  uint32_t frames_ = 0;
  size_t budget_ = 0;
  std::vector<double> values_;  // channel-major; empty: none held
};

}  // namespace keyanim::offline
