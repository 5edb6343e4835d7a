// Curvature feature points of one channel: He & Yung's curvature-scale-space corner detector
// (adaptive threshold, dynamic region of support), applied to the curve (frame, value) after
// scaling it into a square box. Recipe: ../shared/design/method.md section 5.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

namespace keyanim::offline {

struct CurvatureParams {
  double c = 1.5;          // Defaults to 1.5: a maximum must exceed C x the mean curvature of its region.
  double t_angle = 162.0;  // Defaults to 162 degrees: corners flatter than this are rejected.
  double sigma = 3.0;      // Defaults to 3 frames: Gaussian smoothing.
};

// Frames of the feature points, sorted, always including the first and last frame. A constant
// signal or one not longer than the kernel gives just the end frames.
std::vector<uint32_t> curvature_keys(std::span<const double> signal, const CurvatureParams& params = {});

}  // namespace keyanim::offline
