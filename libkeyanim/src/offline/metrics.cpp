// Reconstruction error of a decoded motion against its original (see keyanim/offline/metrics.h).
#include "keyanim/offline/metrics.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "keyanim/offline/fk.h"

namespace keyanim::offline {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr uint32_t kWindow = 256;            // frames per window, at least
constexpr uint32_t kMaxWindows = 1024;       // beyond this, windows grow

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

void measured_points(const Skeleton& skeleton, const double* frame_row, std::vector<std::array<double, 3>>& points,
                     const uint8_t* nodes) {
  if (nodes) world_positions(skeleton, frame_row, nodes, points);
  else world_positions(skeleton, frame_row, points);
}

void measured_points(const Skeleton& skeleton, const double* row_a, const double* row_b,
                     std::vector<std::array<double, 3>>& points_a, std::vector<std::array<double, 3>>& points_b,
                     const uint8_t* nodes) {
  world_positions(skeleton, row_a, row_b, nodes, points_a, points_b);
}

uint32_t measure_window(uint32_t frame_count) {
  const uint32_t windows_of_min = (frame_count + kWindow - 1) / kWindow;
  return kWindow * std::max<uint32_t>(1, (windows_of_min + kMaxWindows - 1) / kMaxWindows);
}

// Whether FK poses two skeletons alike (then one skeleton serves both, two rows at a time).
bool same_pose_rules(const Skeleton& a, const Skeleton& b) {
  if (&a == &b) return true;
  if (a.joints.size() != b.joints.size()) return false;
  for (size_t j = 0; j < a.joints.size(); ++j) {
    const Joint &x = a.joints[j], &y = b.joints[j];
    if (x.parent != y.parent || x.channels != y.channels || x.first_channel != y.first_channel ||
        std::memcmp(x.offset.data(), y.offset.data(), sizeof x.offset) != 0)
      return false;
  }
  return true;
}

ErrorAccumulator::ErrorAccumulator(const Skeleton& skeleton, const Skeleton* decoded)
    : skeleton_(&skeleton),
      decoded_skeleton_(decoded && !same_pose_rules(skeleton, *decoded) ? decoded : &skeleton),
      joint_max_(skeleton.joints.size(), 0.0), channel_max_(skeleton.channel_count(), 0.0) {}

void ErrorAccumulator::add_frame(uint32_t frame, const double* original, const double* decoded) {
  if (decoded_skeleton_ == skeleton_) {
    measured_points(*skeleton_, original, decoded, a_, b_);
  } else {
    measured_points(*skeleton_, original, a_);
    measured_points(*decoded_skeleton_, decoded, b_);
  }
  const size_t nodes = joint_max_.size();
  for (size_t j = 0; j < nodes; ++j) {
    double e = 0.0;
    for (size_t p = j * kPointsPerNode; p < (j + 1) * kPointsPerNode; ++p) {
      const double dx = a_[p][0] - b_[p][0];
      const double dy = a_[p][1] - b_[p][1];
      const double dz = a_[p][2] - b_[p][2];
      e = std::max(e, sanitize(std::sqrt(dx * dx + dy * dy + dz * dz)));
    }
    sum_sq_ += e * e;
    if (e > joint_max_[j]) joint_max_[j] = e;
    if (!any_ || e > max_error_) {
      max_error_ = e, worst_joint_ = static_cast<uint32_t>(j), worst_frame_ = frame;
      any_ = true;
    }
  }
  for (const Joint& joint : skeleton_->joints) {
    for (size_t k = 0; k < joint.channels.size(); ++k) {
      const size_t c = joint.first_channel + k;
      channel_max_[c] = std::max(channel_max_[c], channel_difference(joint.channels[k], original[c], decoded[c]));
    }
  }
}

void ErrorAccumulator::merge(const ErrorAccumulator& later) {
  sum_sq_ += later.sum_sq_;
  if (later.any_ && (!any_ || later.max_error_ > max_error_))
    max_error_ = later.max_error_, worst_joint_ = later.worst_joint_, worst_frame_ = later.worst_frame_, any_ = true;
  for (size_t j = 0; j < joint_max_.size(); ++j) joint_max_[j] = std::max(joint_max_[j], later.joint_max_[j]);
  for (size_t c = 0; c < channel_max_.size(); ++c) channel_max_[c] = std::max(channel_max_[c], later.channel_max_[c]);
}

ErrorReport ErrorAccumulator::report(uint32_t frames) const {
  ErrorReport r;
  r.max_error = max_error_;
  r.worst_joint = worst_joint_;
  r.worst_frame = worst_frame_;
  r.joint_max = joint_max_;
  r.channel_max = channel_max_;
  const double samples = double(frames) * double(joint_max_.size());
  r.rms_error = samples > 0 ? std::sqrt(sum_sq_ / samples) : 0.0;
  const std::vector<bool> leaf = leaf_rotation_joints(*skeleton_);
  for (size_t j = 0; j < leaf.size(); ++j) {
    if (!leaf[j]) continue;
    const Joint& joint = skeleton_->joints[j];
    for (size_t k = 0; k < joint.channels.size(); ++k) {
      const uint32_t c = joint.first_channel + static_cast<uint32_t>(k);
      if (is_rotation(joint.channels[k]) && r.channel_max[c] > r.max_leaf_rotation)
        r.max_leaf_rotation = r.channel_max[c];
    }
  }
  return r;
}

ErrorReport measure_error(const Motion& original, const Motion& decoded) {
  const size_t nodes = original.skeleton.joints.size();
  const uint32_t channels = original.channel_count();
  const uint32_t frames = original.frame_count;
  if (decoded.channel_count() != channels || decoded.frame_count != frames ||
      decoded.skeleton.joints.size() != nodes || !usable(original) || !usable(decoded)) {
    ErrorReport report;
    report.max_error = report.rms_error = report.max_leaf_rotation = kInf;
    report.joint_max.assign(nodes, kInf);
    report.channel_max.assign(channels, kInf);
    return report;
  }
  // Window by window, as a caller measuring in parallel does, so that both agree to the bit.
  ErrorAccumulator total(original.skeleton, &decoded.skeleton);
  const uint32_t window = measure_window(frames);
  for (uint32_t first = 0; first < frames; first += window) {
    ErrorAccumulator part(original.skeleton, &decoded.skeleton);
    for (uint32_t f = first; f < std::min(frames, first + window); ++f)
      part.add_frame(f, original.values.data() + size_t(f) * channels, decoded.values.data() + size_t(f) * channels);
    total.merge(part);
  }
  return total.report(frames);
}

}  // namespace keyanim::offline
