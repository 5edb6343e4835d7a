// How far a decoded motion is from the original: world-space positions of every joint and End
// Site by forward kinematics, and per-channel value differences.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "keyanim/offline/motion.h"

namespace keyanim::offline {

struct ErrorReport {
  double max_error = 0.0;     // file length units, over every node and frame
  double rms_error = 0.0;     // over every node and frame
  uint32_t worst_joint = 0;   // node index (may be an End Site)
  uint32_t worst_frame = 0;
  std::vector<double> joint_max;    // per node
  std::vector<double> channel_max;  // per channel: length units, or degrees (compared modulo 360)
  double max_leaf_rotation = 0.0;   // degrees, largest channel error on a joint whose children
                                    // are all zero-length End Sites (a position metric misses it)
};

// Both motions must share the skeleton and frame count.
ErrorReport measure_error(const Motion& original, const Motion& decoded);

// The points a pose is measured on, kPointsPerNode per node in node order: today each node's
// world position (FK of `frame_row`). Every error keyanim reports or verifies goes through
// this one function, so that adding points (virtual points around each joint, say) changes
// the report, the encoder's verification and its guarantee together.
// With `nodes`, only the points of the nodes it marks (a set holding every ancestor of its
// members) are computed; the others are left as they were.
constexpr uint32_t kPointsPerNode = 1;
void measured_points(const Skeleton& skeleton, const double* frame_row, std::vector<std::array<double, 3>>& points,
                     const uint8_t* nodes = nullptr);
// The same for two frame rows at once (bit for bit two calls; faster): an original frame and
// its decoding, say.
void measured_points(const Skeleton& skeleton, const double* row_a, const double* row_b,
                     std::vector<std::array<double, 3>>& points_a, std::vector<std::array<double, 3>>& points_b,
                     const uint8_t* nodes = nullptr);

// measure_error in pieces, for callers that produce the decoded frames themselves (window by
// window, on several threads): add frames to one accumulator per window, merge the windows in
// frame order, then report. Windows of measure_window(frame_count) frames give exactly
// measure_error's numbers whatever the number of threads.
class ErrorAccumulator {
 public:
  // Kept by reference. The decoded frames are posed with `decoded` (null: the original's).
  explicit ErrorAccumulator(const Skeleton& original, const Skeleton* decoded = nullptr);
  // Frame `frame`: a frame row of the original and of the decoded motion.
  void add_frame(uint32_t frame, const double* original_row, const double* decoded_row);
  // Appends the frames of `later`, which all come after this one's.
  void merge(const ErrorAccumulator& later);
  // The report over `frames` frames (the rms divides by frames x nodes).
  ErrorReport report(uint32_t frames) const;

 private:
  const Skeleton* skeleton_;
  const Skeleton* decoded_skeleton_;
  double sum_sq_ = 0.0;
  bool any_ = false;
  double max_error_ = 0.0;
  uint32_t worst_joint_ = 0, worst_frame_ = 0;
  std::vector<double> joint_max_, channel_max_;
  std::vector<std::array<double, 3>> a_, b_;
};
uint32_t measure_window(uint32_t frame_count);

}  // namespace keyanim::offline
