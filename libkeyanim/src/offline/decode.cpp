// Rebuilding frames from a clip: the source frames, another frame rate, or in-betweens.
//
// Output frame i lies at source frame position
//   source rate:   first + i                         i = 0 .. last - first
//   inbetweens N:  first + i / (N + 1)               i = 0 .. (last - first) (N + 1)
//   fps:           first + (i / fps) / frame_time    i = 0 .. floor(D fps + 1e-6)
// where D = (last - first) frame_time is the range's duration in seconds: the last output frame
// is the last one at or before the range's end, and the end itself is included when it falls
// within a millionth of an output frame of a frame time (so 30 fps from 120 fps source lands on
// every 4th frame despite rounding). Positions are computed from i by one multiplication or
// division, never accumulated.
#include <cmath>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "keyanim/offline/decode.h"

namespace keyanim::offline {

void FrameDecoder::start(const Clip& clip, const ResampleOptions& options) {
  auto invalid = [](const std::string& why) { throw Error(ErrorKind::invalid_argument, why); };
  clip_ = &clip;
  options_ = options;
  count_ = 0;
  const uint32_t frames = clip.frame_count();
  if (std::isnan(options.fps) || options.fps < 0.0 || std::isinf(options.fps))
    invalid("fps must be a finite number > 0 (or 0 for the source rate)");
  if (options.fps > 0.0 && options.inbetweens > 0)
    invalid("give either fps or inbetweens, not both");
  if (options.fps > 0.0 && !(clip.frame_time() > 0.0) && frames > 1)
    invalid("the clip has no frame time; cannot resample to fps");
  const double per = static_cast<double>(options.inbetweens) + 1.0;
  frame_time_ = options.fps > 0.0 ? 1.0 / options.fps : clip.frame_time() / per;
  if (frames == 0) {
    if (options.first_frame != 0 || options.last_frame != UINT32_MAX)
      invalid("the clip has no frames; no frame range can be decoded");
    return;
  }
  first_ = options.first_frame;
  last_ = options.last_frame == UINT32_MAX ? frames - 1 : options.last_frame;
  if (last_ >= frames)
    invalid("last_frame " + std::to_string(last_) + " is beyond the clip's last frame " + std::to_string(frames - 1));
  if (first_ > last_)
    invalid("first_frame " + std::to_string(first_) + " is after last_frame " + std::to_string(last_));
  const uint64_t span = last_ - first_;
  if (options.fps > 0.0) {
    // Saturates rather than overflows: the caller compares the count with its own limits.
    const double n = std::floor(static_cast<double>(span) * clip.frame_time() * options.fps + 1e-6);
    count_ = n < 1.8e19 ? static_cast<uint64_t>(n) + 1 : UINT64_MAX;
  } else {
    count_ = span * (uint64_t(options.inbetweens) + 1) + 1;  // < 2^64: both factors < 2^32
  }
  pose_.assign(clip.channel_count(), 0.0f);
  if (cursor_.prepare(clip) != Status::ok) throw std::bad_alloc();
}

void FrameDecoder::frame(uint64_t i, std::span<double> row) {
  const uint64_t span = last_ - first_;
  double position;
  if (options_.fps > 0.0 && span == 0)
    position = first_;  // a single frame, whatever the frame time (it may be 0)
  else if (options_.fps > 0.0)
    position = first_ + (static_cast<double>(i) / options_.fps) / clip_->frame_time();
  else if (options_.inbetweens > 0)
    position = first_ + static_cast<double>(i) / (static_cast<double>(options_.inbetweens) + 1.0);
  else
    position = static_cast<double>(first_ + i);
  if (position > last_) position = last_;  // the 1e-6 slack may overshoot by a hair
  clip_->sample(position, pose_, &cursor_);
  for (size_t c = 0; c < pose_.size() && c < row.size(); ++c) row[c] = static_cast<double>(pose_[c]);
}

Motion decode_motion(const Clip& clip, const ResampleOptions& options) {
  FrameDecoder decoder;
  decoder.start(clip, options);
  const uint64_t count = decoder.frame_count();
  const uint32_t channels = clip.channel_count();
  if (count > UINT32_MAX || (channels > 0 && count > (uint64_t(1) << 40) / channels))
    throw Error(ErrorKind::limit, "too many output frames (" + std::to_string(count) + ")");
  Motion m;
  m.skeleton = clip.skeleton();
  m.skeleton.assign_channel_columns();
  m.frame_count = static_cast<uint32_t>(count);
  m.frame_time = decoder.frame_time();
  m.values.resize(static_cast<size_t>(count) * channels);
  for (uint64_t i = 0; i < count; ++i) decoder.frame(i, {m.values.data() + i * channels, channels});
  return m;
}

}  // namespace keyanim::offline
