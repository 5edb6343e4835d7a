// Reconstruction error of a decoded motion against its original (see keyanim/offline/metrics.h).
#include "keyanim/offline/metrics.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "keyanim/offline/encode.h"
#include "keyanim/offline/fk.h"
#include "keyanim/offline/number_text.h"

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

}  // namespace

std::span<const PositionReading> measured_readings(const Skeleton& skeleton) noexcept {
  static constexpr PositionReading kBoth[] = {PositionReading::replace, PositionReading::add};
  return {kBoth, has_position_channels_below_root(skeleton) ? 2u : 1u};
}

namespace {

// Points of node j from its pose: its position, then position + shell x column `axis` of its
// world rotation (copies of the position for an End Site or without a shell).
inline void node_points(const Joint& node, double shell, const Vec3& p, const Mat3& r, Vec3* out) noexcept {
  out[0] = p;
  const bool with_shell = shell > 0.0 && !node.end_site;
  for (int axis = 0; axis < 3; ++axis)
    out[1 + axis] = with_shell ? Vec3{p[0] + shell * r[axis], p[1] + shell * r[3 + axis], p[2] + shell * r[6 + axis]} : p;
}

}  // namespace

void measured_points(const Skeleton& skeleton, const double* frame_row, double shell, PositionReading reading,
                     std::vector<std::array<double, 3>>& points) {
  thread_local std::vector<Vec3> pos;
  thread_local std::vector<Mat3> rot;
  world_pose(skeleton, frame_row, pos, rot, reading);
  const size_t n = skeleton.joints.size();
  points.resize(n * kPointsPerNode);
  for (size_t j = 0; j < n; ++j) node_points(skeleton.joints[j], shell, pos[j], rot[j], &points[j * kPointsPerNode]);
}

void measured_points(const Skeleton& skeleton, const double* row_a, const double* row_b, double shell,
                     PositionReading reading, std::vector<std::array<double, 3>>& points_a,
                     std::vector<std::array<double, 3>>& points_b, const uint8_t* nodes,
                     std::vector<std::array<double, 3>>* add_a, std::vector<std::array<double, 3>>* add_b) {
  static_assert(kPointsPerNode == 4, "world_points gives the node and its three shell points");
  world_points(skeleton, row_a, row_b, nodes, reading, shell, points_a, points_b, add_a, add_b);  // node_points, two at once
}

void measured_points(const Skeleton& skeleton, const std::array<const double*, 4>& rows, double shell,
                     PositionReading reading, std::array<std::vector<std::array<double, 3>>, 4>& points,
                     const uint8_t* nodes, std::array<std::vector<std::array<double, 3>>, 4>* points_add,
                     const QuatForms* quats) {
  world_points(skeleton, rows, nodes, reading, shell, points, points_add, quats);  // node_points, four at once
}

std::string point_name(const Skeleton& s, uint32_t node, uint32_t point) {
  if (node >= s.joints.size()) return "?";
  const Joint& j = s.joints[node];
  std::string name = j.name;
  if (j.end_site && j.name.empty())
    name = j.parent >= 0 && size_t(j.parent) < s.joints.size() ? "End Site of " + s.joints[size_t(j.parent)].name : "End Site";
  if (point >= 1 && point <= 3) name += std::string(" shell ") + char('x' + point - 1);
  return name;
}

double default_shell(const Motion& motion) { return kDefaultShellPercent / 100.0 * reference_size(motion); }

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

ErrorAccumulator::ErrorAccumulator(const Skeleton& skeleton, double shell, const Skeleton* decoded)
    : skeleton_(&skeleton),
      decoded_skeleton_(decoded && !same_pose_rules(skeleton, *decoded) ? decoded : &skeleton),
      shell_(shell),
      joint_max_(skeleton.joints.size(), 0.0),
      channel_max_(skeleton.channel_count(), 0.0),
      node_max_(skeleton.joints.size(), 0.0) {}

void ErrorAccumulator::add_frame(uint32_t frame, const double* original, const double* decoded) {
  std::fill(node_max_.begin(), node_max_.end(), 0.0);
  thread_local std::vector<Vec3> a, b;  // scratch, per thread (as in add_frames)
  for (const PositionReading reading : measured_readings(*skeleton_)) {
    if (decoded_skeleton_ == skeleton_) {
      measured_points(*skeleton_, original, decoded, shell_, reading, a, b);
    } else {
      measured_points(*skeleton_, original, shell_, reading, a);
      measured_points(*decoded_skeleton_, decoded, shell_, reading, b);
    }
    add_points(frame, reading, a, b);
  }
  end_frame(original, decoded);
}

void ErrorAccumulator::add_frames(uint32_t frame, const std::array<const double*, 4>& rows) {
  if (decoded_skeleton_ != skeleton_) {
    add_frame(frame, rows[0], rows[1]);
    return add_frame(frame + 1, rows[2], rows[3]);
  }
  // Both frames' points under every reading first, then each frame as add_frame takes it:
  // the same comparisons in the same order (the first of equal errors stays the worst).
  const std::span<const PositionReading> readings = measured_readings(*skeleton_);  // replace, then add
  // Per thread, not per accumulator: a long clip's measurement holds an accumulator per window
  // until they are merged (172 of them on 44,032 frames), and these points are scratch.
  thread_local std::array<std::array<std::vector<Vec3>, 4>, 2> quad;  // per reading
  measured_points(*skeleton_, rows, shell_, readings[0], quad[0], nullptr, readings.size() > 1 ? &quad[1] : nullptr);
  for (size_t k = 0; k < 2; ++k) {
    std::fill(node_max_.begin(), node_max_.end(), 0.0);
    for (size_t r = 0; r < readings.size(); ++r)
      add_points(frame + uint32_t(k), readings[r], quad[r][2 * k], quad[r][2 * k + 1]);
    end_frame(rows[2 * k], rows[2 * k + 1]);
  }
}

void ErrorAccumulator::add_points(uint32_t frame, PositionReading reading, const std::vector<Vec3>& a,
                                  const std::vector<Vec3>& b) {
  for (size_t j = 0; j < node_max_.size(); ++j) {
    const size_t first = j * kPointsPerNode;
    for (size_t p = first; p < first + measured_point_count(skeleton_->joints[j], shell_); ++p) {
      const double dx = a[p][0] - b[p][0];
      const double dy = a[p][1] - b[p][1];
      const double dz = a[p][2] - b[p][2];
      const double e = sanitize(std::sqrt(dx * dx + dy * dy + dz * dz));
      node_max_[j] = std::max(node_max_[j], e);
      double& by_reading = reading_max_[size_t(reading)];
      by_reading = std::max(by_reading, e);
      if (!any_ || e > max_error_) {
        max_error_ = e, worst_joint_ = uint32_t(j), worst_point_ = uint32_t(p - first), worst_frame_ = frame;
        worst_reading_ = reading;
        any_ = true;
      }
    }
  }
}

void ErrorAccumulator::end_frame(const double* original, const double* decoded) {
  for (size_t j = 0; j < node_max_.size(); ++j) {
    sum_sq_ += node_max_[j] * node_max_[j];
    joint_max_[j] = std::max(joint_max_[j], node_max_[j]);
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
  if (later.any_ && (!any_ || later.max_error_ > max_error_)) {
    max_error_ = later.max_error_, worst_joint_ = later.worst_joint_, worst_point_ = later.worst_point_;
    worst_frame_ = later.worst_frame_, worst_reading_ = later.worst_reading_, any_ = true;
  }
  for (size_t r = 0; r < 2; ++r) reading_max_[r] = std::max(reading_max_[r], later.reading_max_[r]);
  for (size_t j = 0; j < joint_max_.size(); ++j) joint_max_[j] = std::max(joint_max_[j], later.joint_max_[j]);
  for (size_t c = 0; c < channel_max_.size(); ++c) channel_max_[c] = std::max(channel_max_[c], later.channel_max_[c]);
}

ErrorReport ErrorAccumulator::report(uint32_t frames) const {
  ErrorReport r;
  r.max_error = max_error_;
  r.worst_joint = worst_joint_;
  r.worst_point = worst_point_;
  r.worst_frame = worst_frame_;
  r.worst_reading = worst_reading_;
  r.shell = shell_;
  r.both_readings = measured_readings(*skeleton_).size() == 2;
  r.reading_max = reading_max_;
  r.joint_max = joint_max_;
  r.channel_max = channel_max_;
  const double samples = double(frames) * double(joint_max_.size());
  r.rms_error = samples > 0 ? std::sqrt(sum_sq_ / samples) : 0.0;
  return r;
}

ErrorReport measure_error(const Motion& original, const Motion& decoded) {
  return measure_error(original, decoded, default_shell(original));
}

ErrorReport measure_error(const Motion& original, const Motion& decoded, double shell) {
  const size_t nodes = original.skeleton.joints.size();
  const uint32_t channels = original.channel_count();
  const uint32_t frames = original.frame_count;
  if (decoded.channel_count() != channels || decoded.frame_count != frames || decoded.skeleton.joints.size() != nodes)
    throw Error(ErrorKind::invalid_argument,
                "cannot compare motions that differ in frames, channels or nodes (" + std::to_string(frames) + ", " +
                    std::to_string(channels) + ", " + std::to_string(nodes) + " against " +
                    std::to_string(decoded.frame_count) + ", " + std::to_string(decoded.channel_count()) + ", " +
                    std::to_string(decoded.skeleton.joints.size()) + ")");
  if (!usable(original) || !usable(decoded))
    throw Error(ErrorKind::invalid_argument, "a motion's values do not fill frames x channels, or its channel "
                                             "columns lie outside a frame");
  if (!(shell >= 0.0 && std::isfinite(shell)))
    throw Error(ErrorKind::invalid_argument, "the shell distance must be 0 or more and finite, got " + general_text(shell));
  // Without channels every frame of both is the rest pose: frame 0 stands for all (and the
  // work follows the input, not a declared frame count).
  const uint32_t measured = channels == 0 ? std::min<uint32_t>(frames, 1) : frames;
  // Window by window, as a caller measuring in parallel does, so that both agree to the bit.
  ErrorAccumulator total(original.skeleton, shell, &decoded.skeleton);
  const uint32_t window = measure_window(measured);
  for (uint32_t first = 0; first < measured; first += window) {
    ErrorAccumulator part(original.skeleton, shell, &decoded.skeleton);
    const uint32_t end = std::min(measured, first + window);
    auto row = [&](const Motion& m, uint32_t f) { return m.values.data() + size_t(f) * channels; };
    uint32_t f = first;
    for (; f + 1 < end; f += 2) part.add_frames(f, {row(original, f), row(decoded, f), row(original, f + 1), row(decoded, f + 1)});
    if (f < end) part.add_frame(f, row(original, f), row(decoded, f));
    total.merge(part);
  }
  return total.report(measured);
}

}  // namespace keyanim::offline
