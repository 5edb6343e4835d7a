// Reconstruction error of a decoded motion against its original (see keyanim/offline/metrics.h).
#include "keyanim/offline/metrics.h"

#include <cmath>
#include <limits>

#include "keyanim/offline/fk.h"

namespace keyanim::offline {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A NaN difference means the decoded motion is broken: count it as infinitely wrong so that it
// cannot hide behind comparisons that are false for NaN.
inline double sanitize(double e) noexcept { return std::isnan(e) ? kInf : e; }

inline double channel_difference(ChannelType type, double a, double b) noexcept {
  double d = a - b;
  if (is_rotation(type)) d -= 360.0 * std::round(d / 360.0);
  return sanitize(std::fabs(d));
}

bool usable(const Motion& m) noexcept {
  return m.values.size() >= size_t(m.frame_count) * m.channel_count() &&
         channel_columns_consistent(m.skeleton);
}

// Joints whose rotation moves no node: no children, or only End Sites of zero length.
std::vector<bool> leaf_rotation_joints(const Skeleton& skeleton) {
  const size_t n = skeleton.joints.size();
  std::vector<bool> leaf(n, false);
  for (size_t j = 0; j < n; ++j) leaf[j] = !skeleton.joints[j].end_site;
  for (size_t j = 0; j < n; ++j) {
    const Joint& child = skeleton.joints[j];
    if (child.parent < 0 || static_cast<size_t>(child.parent) >= j) continue;
    const bool zero_end = child.end_site && child.offset[0] == 0.0 && child.offset[1] == 0.0 &&
                          child.offset[2] == 0.0;
    if (!zero_end) leaf[child.parent] = false;
  }
  return leaf;
}

}  // namespace

ErrorReport measure_error(const Motion& original, const Motion& decoded) {
  ErrorReport report;
  const size_t nodes = original.skeleton.joints.size();
  const uint32_t channels = original.channel_count();
  const uint32_t frames = original.frame_count;
  report.joint_max.assign(nodes, 0.0);
  report.channel_max.assign(channels, 0.0);

  if (decoded.channel_count() != channels || decoded.frame_count != frames ||
      decoded.skeleton.joints.size() != nodes || !usable(original) ||
      !usable(decoded)) {
    report.max_error = report.rms_error = report.max_leaf_rotation = kInf;
    report.joint_max.assign(nodes, kInf);
    report.channel_max.assign(channels, kInf);
    return report;
  }

  std::vector<Vec3> a;
  std::vector<Vec3> b;
  double sum_sq = 0.0;
  bool first = true;
  for (uint32_t f = 0; f < frames; ++f) {
    world_positions(original.skeleton, original.frame(f), a);
    world_positions(decoded.skeleton, decoded.frame(f), b);
    for (size_t j = 0; j < nodes; ++j) {
      const double dx = a[j][0] - b[j][0];
      const double dy = a[j][1] - b[j][1];
      const double dz = a[j][2] - b[j][2];
      const double e = sanitize(std::sqrt(dx * dx + dy * dy + dz * dz));
      sum_sq += e * e;
      if (e > report.joint_max[j]) report.joint_max[j] = e;
      if (first || e > report.max_error) {
        report.max_error = e;
        report.worst_joint = static_cast<uint32_t>(j);
        report.worst_frame = f;
        first = false;
      }
    }
  }
  const double samples = double(frames) * double(nodes);
  report.rms_error = samples > 0 ? std::sqrt(sum_sq / samples) : 0.0;

  const size_t stride = channels;  // Motion::value would recount the channels at every call
  for (uint32_t j = 0; j < nodes; ++j) {
    const Joint& joint = original.skeleton.joints[j];
    for (size_t k = 0; k < joint.channels.size(); ++k) {
      const uint32_t c = joint.first_channel + static_cast<uint32_t>(k);
      double m = 0.0;
      for (uint32_t f = 0; f < frames; ++f) {
        const double d = channel_difference(joint.channels[k], original.values[f * stride + c],
                                            decoded.values[f * stride + c]);
        if (d > m) m = d;
      }
      report.channel_max[c] = m;
    }
  }

  const std::vector<bool> leaf = leaf_rotation_joints(original.skeleton);
  for (size_t j = 0; j < nodes; ++j) {
    if (!leaf[j]) continue;
    const Joint& joint = original.skeleton.joints[j];
    for (size_t k = 0; k < joint.channels.size(); ++k) {
      const uint32_t c = joint.first_channel + static_cast<uint32_t>(k);
      if (is_rotation(joint.channels[k]) &&
          report.channel_max[c] > report.max_leaf_rotation) {
        report.max_leaf_rotation = report.channel_max[c];
      }
    }
  }
  return report;
}

}  // namespace keyanim::offline
