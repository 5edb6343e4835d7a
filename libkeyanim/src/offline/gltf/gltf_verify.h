// The export's world-space check: the clip's forward kinematics at every source frame of the
// window (the reference) against a glTF player's, over joints, End Sites and shell points.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "gltf_curves.h"
#include "gltf_model.h"

namespace keyanim::offline::gltf {

// Points measured per frame: node j at index j; its shell point on axis a (joints only) at
// node_count + 3 j + a, at `shell` along column a of its world rotation.
class Reference {
 public:
  Reference(const Skeleton& skeleton, const std::vector<ChannelCurve>& curves, const Window& window, double shell);
  uint32_t point_count() const noexcept { return points_per_frame_; }
  bool measured(uint32_t point) const noexcept { return active_[point]; }
  const Vec3& point(uint32_t frame_index, uint32_t p) const noexcept {
    return points_[size_t(frame_index) * points_per_frame_ + p];
  }
  // The node that carries point p, and whether the node's own rotation moves it (shell points).
  uint32_t owner(uint32_t p) const noexcept;
  bool moved_by_owner(uint32_t p) const noexcept { return p >= node_count_; }
  double shell() const noexcept { return shell_; }
  const Window& window() const noexcept { return window_; }

 private:
  uint32_t node_count_ = 0;
  uint32_t points_per_frame_ = 0;
  double shell_ = 0.0;
  Window window_;
  std::vector<bool> active_;
  std::vector<Vec3> points_;  // frame-major
};

// Positions of every measured point from a pose (positions and world rotations of the nodes).
void pose_points(const Skeleton& skeleton, const std::vector<Vec3>& positions, const std::vector<Mat3>& rotations,
                 double shell, std::vector<Vec3>& out);

struct Violation {
  uint32_t point;
  uint32_t frame_index;  // within the window
  double error;
};

struct CheckResult {
  double max_error = 0.0;
  uint32_t worst_point = 0;
  uint32_t worst_frame_index = 0;
  std::vector<Violation> violations;  // error > tolerance (the worst LINEAR reading)
};

// Plays the model at every source frame of the window with each LINEAR-rotation reading
// (gltf_player.h) and compares with the reference.
// `progress`, if given, gets the fraction of the frames checked.
CheckResult check_model(const Model& model, const Reference& reference, double tolerance,
                        const std::function<void(double)>& progress = {});

}  // namespace keyanim::offline::gltf
