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
//   fps:           first + (i / fps) / frame_time      (floor(D fps + 1e-6) + 1 frames)
// with D = (last - first) frame_time seconds: frames every 1/fps s from the range's start up
// to its end, the end included when it lands on an output frame (within 1e-6 of one).
// Values are the clip's float samples as doubles; frame_time becomes frame_time / (N + 1) or
// 1 / fps. A clip without frames decodes to no frames.
//
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
  // Output frame i < frame_count(): clip.channel_count() values. Fastest in increasing i.
  void frame(uint64_t i, std::span<double> row);

 private:
  const Clip* clip_ = nullptr;
  ResampleOptions options_;
  uint32_t first_ = 0, last_ = 0;
  uint64_t count_ = 0;
  double frame_time_ = 0.0;
  std::vector<float> pose_;
  Cursor cursor_;
};

// All frames of a FrameDecoder as one Motion. Throws as FrameDecoder::start, and Error (limit)
// when the result would have 2^32 frames or more, or more than 2^40 values.
Motion decode_motion(const Clip& clip, const ResampleOptions& options = {});

}  // namespace keyanim::offline
