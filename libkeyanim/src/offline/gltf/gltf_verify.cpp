// The export's world-space check (gltf_verify.h).
#include "gltf_verify.h"

#include <cmath>

#include "gltf_player.h"

namespace keyanim::offline::gltf {

Reference::Reference(const Skeleton& skeleton, const std::vector<ChannelCurve>& curves, const Window& window,
                     double shell)
    : node_count_(uint32_t(skeleton.joints.size())), shell_(shell), window_(window) {
  points_per_frame_ = node_count_ * (shell > 0.0 ? 4 : 1);
  active_.assign(points_per_frame_, true);
  for (uint32_t j = 0; j < node_count_ && shell > 0.0; ++j)
    if (skeleton.joints[j].end_site)
      for (uint32_t a = 0; a < 3; ++a) active_[node_count_ + 3 * j + a] = false;
  points_.reserve(size_t(points_per_frame_) * window.frames());
  std::vector<double> row(curves.size());
  std::vector<Vec3> positions, frame_points;
  std::vector<Mat3> rotations;
  for (uint32_t f = window.first; f <= window.last; ++f) {
    for (size_t c = 0; c < curves.size(); ++c) row[c] = curves[c].value(f);
    world_pose(skeleton, row.data(), positions, rotations);
    pose_points(skeleton, positions, rotations, shell, frame_points);
    points_.insert(points_.end(), frame_points.begin(), frame_points.end());
  }
}

uint32_t Reference::owner(uint32_t p) const noexcept { return p < node_count_ ? p : (p - node_count_) / 3; }

void pose_points(const Skeleton& skeleton, const std::vector<Vec3>& positions, const std::vector<Mat3>& rotations,
                 double shell, std::vector<Vec3>& out) {
  const size_t n = skeleton.joints.size();
  out.assign(positions.begin(), positions.end());
  if (!(shell > 0.0)) return;
  out.resize(4 * n);
  for (size_t j = 0; j < n; ++j)
    for (int a = 0; a < 3; ++a) {
      const Mat3& r = rotations[j];
      out[n + 3 * j + a] = {positions[j][0] + shell * r[a], positions[j][1] + shell * r[3 + a],
                            positions[j][2] + shell * r[6 + a]};
    }
}

CheckResult check_model(const Model& model, const Reference& reference, double tolerance,
                        const std::function<void(double)>& progress) {
  CheckResult result;
  const Window& w = reference.window();
  const uint32_t np = reference.point_count();
  std::vector<Vec3> positions, points;
  std::vector<Mat3> rotations;
  std::vector<double> worst(np);
  for (uint32_t i = 0; i < w.frames(); ++i) {
    if (progress && i % 64 == 0) progress(double(i) / double(w.frames()));
    std::fill(worst.begin(), worst.end(), 0.0);
    for (QuatLerp lerp : kQuatLerps) {
      play_pose(model, w.time(w.first + i), lerp, positions, rotations);
      pose_points(model.skeleton, positions, rotations, reference.shell(), points);
      for (uint32_t p = 0; p < np; ++p) {
        const Vec3& r = reference.point(i, p);
        const double e = std::hypot(points[p][0] - r[0], points[p][1] - r[1], points[p][2] - r[2]);
        if (reference.measured(p) && !(e <= worst[p])) worst[p] = e;  // NaN counts as worst
      }
    }
    for (uint32_t p = 0; p < np; ++p) {
      // NaN stays the worst once found: a later finite error must not replace it (the message
      // would then quote an error below the tolerance it says cannot be held).
      if (!std::isnan(result.max_error) && !(worst[p] <= result.max_error)) {
        result.max_error = worst[p];
        result.worst_point = p;
        result.worst_frame_index = i;
      }
      if (!(worst[p] <= tolerance)) result.violations.push_back({p, i, worst[p]});
    }
  }
  if (progress) progress(1.0);
  return result;
}

}  // namespace keyanim::offline::gltf
