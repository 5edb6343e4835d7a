// Rebuilding a Motion from a clip: the source frames, another frame rate, or in-betweens.
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
#include <string>
#include <utility>
#include <vector>

#include "keyanim/offline/decode.h"

namespace keyanim::offline {

bool decode_motion(const Clip& clip, const ResampleOptions& options, Motion& out, std::string& error) {
  error.clear();
  const uint32_t frames = clip.frame_count();
  if (std::isnan(options.fps) || options.fps < 0.0 || std::isinf(options.fps)) {
    error = "fps must be a finite number > 0 (or 0 for the source rate)";
    return false;
  }
  if (options.fps > 0.0 && options.inbetweens > 0) {
    error = "give either fps or inbetweens, not both";
    return false;
  }
  if (options.fps > 0.0 && !(clip.frame_time() > 0.0) && frames > 1) {
    error = "the clip has no frame time; cannot resample to fps";
    return false;
  }
  const bool whole = options.first_frame == 0 && options.last_frame == UINT32_MAX;
  Motion m;
  m.skeleton = clip.skeleton();
  m.skeleton.assign_channel_columns();
  const uint32_t channels = clip.channel_count();
  if (frames == 0) {
    if (!whole) {
      error = "the clip has no frames; no frame range can be decoded";
      return false;
    }
    m.frame_time = options.fps > 0.0 ? 1.0 / options.fps : clip.frame_time() / (options.inbetweens + 1.0);
    out = std::move(m);
    return true;
  }
  const uint32_t first = options.first_frame;
  const uint32_t last = options.last_frame == UINT32_MAX ? frames - 1 : options.last_frame;
  if (last >= frames) {
    error = "last_frame " + std::to_string(last) + " is beyond the clip's last frame " + std::to_string(frames - 1);
    return false;
  }
  if (first > last) {
    error = "first_frame " + std::to_string(first) + " is after last_frame " + std::to_string(last);
    return false;
  }

  const uint64_t span = last - first;
  uint64_t count = 0;
  double frame_time = clip.frame_time();
  if (options.fps > 0.0) {
    const double duration = static_cast<double>(span) * clip.frame_time();
    const double n = std::floor(duration * options.fps + 1e-6);
    if (!(n < 4294967295.0)) {
      error = "too many output frames";
      return false;
    }
    count = static_cast<uint64_t>(n) + 1;
    frame_time = 1.0 / options.fps;
  } else {
    const uint64_t per = uint64_t(options.inbetweens) + 1;
    count = span * per + 1;
    frame_time = clip.frame_time() / static_cast<double>(per);
  }
  if (count > UINT32_MAX || (channels > 0 && count > (uint64_t(1) << 40) / channels)) {
    error = "too many output frames (" + std::to_string(count) + ")";
    return false;
  }
  m.frame_count = static_cast<uint32_t>(count);
  m.frame_time = frame_time;
  m.values.resize(static_cast<size_t>(count) * channels);
  std::vector<float> pose(channels);
  Cursor cursor;
  if (cursor.prepare(clip) != Status::ok) throw std::bad_alloc();
  const double per = static_cast<double>(options.inbetweens) + 1.0;
  for (uint64_t i = 0; i < count; ++i) {
    double position;
    if (options.fps > 0.0 && span == 0)
      position = first;  // a single frame, whatever the frame time (it may be 0)
    else if (options.fps > 0.0)
      position = first + (static_cast<double>(i) / options.fps) / clip.frame_time();
    else if (options.inbetweens > 0)
      position = first + static_cast<double>(i) / per;
    else
      position = static_cast<double>(first + i);
    if (position > last) position = last;  // the 1e-6 slack may overshoot by a hair
    clip.sample(position, pose, &cursor);
    double* row = m.values.data() + i * channels;
    for (uint32_t c = 0; c < channels; ++c) row[c] = static_cast<double>(pose[c]);
  }
  out = std::move(m);
  return true;
}

}  // namespace keyanim::offline
