#include "dense_clip.h"

#include <cmath>

#include "keyanim/offline/container.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/error.h"

namespace keyanim::python {
namespace {

// Key values of one channel: q = round(v / step), step = 2^(e - 24) for the channel's largest
// magnitude below 2^e (float32's 24-bit significand at that magnitude).
offline::EncodedChannel keyed_everywhere(std::vector<double> signal, bool rotation) {
  offline::EncodedChannel ch;
  if (rotation) offline::unwrap_degrees(signal);
  double largest = 0.0;
  for (double v : signal) largest = std::max(largest, std::fabs(v));
  if (!(largest > 0.0) || !std::isfinite(largest)) {
    if (largest == 0.0) return ch;  // all zeros: no keys
    throw offline::Error(offline::ErrorKind::malformed, "a channel holds a value that is not finite");
  }
  ch.step = std::ldexp(1.0, std::ilogb(largest) + 1 - 24);
  ch.frames.resize(signal.size());
  ch.q.resize(signal.size());
  for (size_t f = 0; f < signal.size(); ++f) {
    ch.frames[f] = uint32_t(f);
    ch.q[f] = std::llround(signal[f] / ch.step);
  }
  return ch;
}

}  // namespace

Clip dense_clip(const offline::Motion& motion) {
  offline::EncodedClip enc;
  enc.skeleton = motion.skeleton;
  enc.frame_count = motion.frame_count;
  enc.frame_time = motion.frame_time;
  enc.tangent_rule = TangentRule::step_adjusted;
  const uint32_t channels = motion.channel_count();
  if (motion.values.size() != size_t(motion.frame_count) * channels)
    throw offline::Error(offline::ErrorKind::invalid_argument, "the motion's values do not fill frames x channels");
  enc.channels.resize(channels);
  for (uint32_t c = 0; c < channels; ++c) {
    const uint32_t node = motion.skeleton.joint_of_channel(c);
    const Joint& j = motion.skeleton.joints[node];
    enc.channels[c] = keyed_everywhere(motion.channel(c), is_rotation(j.channels[c - j.first_channel]));
  }
  try {
    offline::validate_encoded_clip(enc);
  } catch (const offline::Error& e) {
    throw offline::Error(offline::ErrorKind::malformed, "cannot be held as a clip: " + e.message());
  }
  return offline::to_clip(enc);
}

}  // namespace keyanim::python
