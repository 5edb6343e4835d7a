// From a loaded clip back to a motion: at the source frame rate, at another rate, or with N
// in-between frames per source frame interval (motion tweening: values come from the curves).
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "keyanim/clip.h"
#include "keyanim/offline/error.h"
#include "keyanim/offline/motion.h"

namespace keyanim::offline {

struct ResampleOptions {
  double fps = 0.0;         // Defaults to 0: the source rate. Otherwise frames every 1/fps s.
  uint32_t inbetweens = 0;  // Defaults to 0. N > 0: N extra frames in every source interval.
  uint32_t first_frame = 0;            // Defaults to 0: source frame range to decode
  uint32_t last_frame = UINT32_MAX;    // Defaults to the last frame (inclusive).
};

// Output frame i lies at source frame position
//   source rate:   first + i                           (last - first + 1 frames)
//   inbetweens N:  first + i / (N + 1)                 ((last - first) (N + 1) + 1 frames)
//   fps:           as RateMap below
// Values are the clip's float samples as doubles; frame_time becomes frame_time / (N + 1) or
// 1 / fps. A quaternion node's rotation channels (version 5) are its Euler angles computed in
// binary64 from its stored values (spec Appendix B), each frame's the solution nearest the
// frame decoded before it, so that a rebuilt BVH file's channels are continuous. A clip without
// frames decodes to no frames.
//
// The rule for a rate. BVH files store Frame Time rounded (.0083333 for 1/120 s), so a rate
// asked for is compared with the clip's own first: a rate within 0.01% (kRateSnap) of N times
// the clip's (N = 1, 2, ...) gives exactly the source frames and their N - 1 in-betweens
// (positions i / N: --fps 120 on a 120 fps clip reproduces its frames, --fps 240 equals
// --inbetweens 1), and a rate within 0.01% of the clip's divided by M (M = 2, 3, ...) gives every
// M-th source frame (positions i M). Any other rate gives frames every 1/fps s from the range's
// start (positions (i / fps) / frame_time) up to its end D = span frame_time s: floor(D fps +
// 1e-6) + 1 frames, so the last frame is the last one at or before the end (the end itself
// when it lands within a millionth of a frame of it). Positions come from i by one
// multiplication or division, never accumulated.
inline constexpr double kRateSnap = 1e-4;
struct RateMap {
  uint64_t count = 0;  // output frames (saturates at UINT64_MAX rather than overflow)
  uint32_t per = 0;    // N > 0: N output frames per source frame (a multiple of the clip's rate)
  uint32_t every = 0;  // M > 0: one output frame every M source frames (a divisor of its rate)
  double fps = 0.0, frame_time = 0.0;
  // Output frame i's source frame position, from the range's start.
  double position(uint64_t i) const noexcept {
    if (per) return static_cast<double>(i) / per;
    if (every) return static_cast<double>(i) * every;
    return (static_cast<double>(i) / fps) / frame_time;
  }
};
// For `span` source frame intervals of `frame_time` s (> 0 when span > 0) at `fps` (> 0).
RateMap rate_map(uint64_t span, double frame_time, double fps) noexcept;

// FrameDecoder produces those frames one at a time, so that a caller can stream them (e.g. to
// a BvhWriter) in memory independent of their number, and can see how many there will be
// before producing any.
class FrameDecoder {
 public:
  // Checks `options` against `clip` (which must outlive the decoder). Throws Error
  // (invalid_argument) only for options that make no sense: fps < 0 or not finite, both fps and
  // inbetweens, fps for a clip without frame time, an empty or reversed range, last_frame
  // beyond the clip. Any number of output frames is accepted here.
  void start(const Clip& clip, const ResampleOptions& options);
  uint64_t frame_count() const noexcept { return count_; }
  double frame_time() const noexcept { return frame_time_; }
  // Output frame i < frame_count(): clip.channel_count() values. Fastest in increasing i (and a
  // quaternion node's angles are continuous from call to call).
  void frame(uint64_t i, std::span<double> row);

 private:
  const Clip* clip_ = nullptr;
  ResampleOptions options_;
  uint32_t first_ = 0, last_ = 0;
  uint64_t count_ = 0;
  double frame_time_ = 0.0;
  RateMap rate_;  // with fps
  std::vector<float> pose_;
  // Per quaternion node: where its channels are, their axes, and the angles last decoded.
  struct QuatAngles {
    QuatNode node;
    uint32_t column = 0;
    uint8_t axes[3] = {};
    double previous[3] = {};
    bool have_previous = false;
  };
  std::vector<QuatAngles> quats_;
  void quat_angles(QuatAngles& q, std::span<double> row);
  Cursor cursor_;
};

// All frames of a FrameDecoder as one Motion. Throws as FrameDecoder::start, and Error (limit)
// when the result would have 2^32 frames or more, or more than 2^40 values.
Motion decode_motion(const Clip& clip, const ResampleOptions& options = {});

}  // namespace keyanim::offline
