// Rebuilding frames from a clip: the source frames, another frame rate, or in-betweens, by the
// rules of decode.h (RateMap for a rate).
#include <cmath>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "keyanim/offline/decode.h"

namespace keyanim::offline {

RateMap rate_map(uint64_t span, double frame_time, double fps) noexcept {
  RateMap m;
  m.fps = fps, m.frame_time = frame_time;
  if (span == 0) {  // one frame, whatever the frame time (it may be 0)
    m.count = 1, m.per = 1;
    return m;
  }
  const double r = fps * frame_time;  // output frames per source frame
  const double n = std::round(r), k = std::round(1.0 / r);
  if (n >= 1.0 && n <= 4294967295.0 && std::fabs(r - n) <= kRateSnap * r) {
    m.per = static_cast<uint32_t>(n);
    m.count = span <= UINT64_MAX / m.per - 1 ? span * m.per + 1 : UINT64_MAX;
  } else if (k >= 2.0 && k <= 4294967295.0 && std::fabs(1.0 / r - k) <= kRateSnap / r) {
    m.every = static_cast<uint32_t>(k);
    m.count = span / m.every + 1;
  } else {
    const double c = std::floor(static_cast<double>(span) * frame_time * fps + 1e-6);
    m.count = c < 1.8e19 ? static_cast<uint64_t>(c) + 1 : UINT64_MAX;
  }
  return m;
}

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
    rate_ = rate_map(span, clip.frame_time(), options.fps);  // saturates: the caller checks the count
    count_ = rate_.count;
  } else {
    count_ = span * (uint64_t(options.inbetweens) + 1) + 1;  // < 2^64: both factors < 2^32
  }
  pose_.assign(clip.channel_count(), 0.0f);
  quats_.resize(clip.quat_node_count());
  for (uint32_t i = 0; i < quats_.size(); ++i) {
    QuatAngles& q = quats_[i];
    q.node = clip.quat_node(i);
    const Joint& j = clip.skeleton().joints[q.node.node];
    uint32_t first = 0;
    quaternion_capable(j, &first);
    q.column = j.first_channel + first;
    for (uint32_t k = 0; k < 3; ++k) q.axes[k] = static_cast<uint8_t>(channel_axis(j.channels[first + k]));
    q.have_previous = false;
  }
  if (cursor_.prepare(clip) != Status::ok) throw std::bad_alloc();
}

// A quaternion node's channels in `row`: its Euler angles in binary64 from the stored x, y, z
// (Appendix B), the solution nearest the frame decoded before (continuous channels).
void FrameDecoder::quat_angles(QuatAngles& q, std::span<double> row) {
  const float* xyz = pose_.data() + q.column;
  double rotation[4], deg[3];
  stored_rotation(q.node, xyz[0], xyz[1], xyz[2], rotation);
  euler_from_quaternion(rotation, q.axes, deg);
  if (q.have_previous) nearest_euler(q.previous, deg);
  for (uint32_t k = 0; k < 3; ++k) q.previous[k] = deg[k];
  q.have_previous = true;
  for (uint32_t k = 0; k < 3 && q.column + k < row.size(); ++k) row[q.column + k] = deg[k];
}

void FrameDecoder::frame(uint64_t i, std::span<double> row) {
  const uint64_t span = last_ - first_;
  double position;
  if (options_.fps > 0.0 && span == 0)
    position = first_;  // a single frame, whatever the frame time (it may be 0)
  else if (options_.fps > 0.0)
    position = first_ + rate_.position(i);
  else if (options_.inbetweens > 0)
    position = first_ + static_cast<double>(i) / (static_cast<double>(options_.inbetweens) + 1.0);
  else
    position = static_cast<double>(first_ + i);
  if (position > last_) position = last_;  // the 1e-6 slack may overshoot by a hair
  clip_->sample_stored(position, pose_, &cursor_);
  for (size_t c = 0; c < pose_.size() && c < row.size(); ++c) row[c] = static_cast<double>(pose_[c]);
  for (QuatAngles& q : quats_) quat_angles(q, row);
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
