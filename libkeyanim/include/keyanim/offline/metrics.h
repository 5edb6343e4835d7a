// How far a decoded motion is from the original: the measured points of every frame (below),
// posed by forward kinematics, and per-channel value differences.
#pragma once
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "keyanim/offline/error.h"
#include "keyanim/offline/fk.h"
#include "keyanim/offline/motion.h"
#include "keyanim/pose.h"

namespace keyanim::offline {

// The measured points, the guarantee: what a skinned mesh sees of a pose. Every node's world
// position (joints and End Sites) and, for every joint (not End Site), three shell points at
// distance `shell` along its local x, y and z axes (the columns of its world rotation), so that
// a rotation about a bone's own axis, or of a joint whose End Site has no length, is measured
// as the vertices skinned to it see it (ACL's virtual vertices). shell = 0: joints and End
// Sites only. The default distance is 2% of the skeleton size (reference_size, encode.h):
// about 3.4 cm on a 1.7 m body (ACL's default is 3 cm).
constexpr double kDefaultShellPercent = 2.0;

// Readings of position channels below a root disagree (pose.h): a skeleton with such channels
// is measured under both, the error being the worse; otherwise under replace alone.
std::span<const PositionReading> measured_readings(const Skeleton& skeleton) noexcept;

struct ErrorReport {
  double max_error = 0.0;     // file length units, over every measured point, reading and frame
  double rms_error = 0.0;     // over every node and frame, of the node's largest point error
  uint32_t worst_joint = 0;   // node index (may be an End Site)
  uint32_t worst_point = 0;   // 0: the node itself; 1, 2, 3: its shell point along local x, y, z
  uint32_t worst_frame = 0;
  PositionReading worst_reading = PositionReading::replace;
  double shell = 0.0;           // the shell distance measured with, file units (0: no shell)
  bool both_readings = false;   // measured under replace and add (measured_readings)
  // The largest error under each reading, indexed by PositionReading (add: 0 unless measured).
  // ACL and Blender read position channels as replace: compare with them on that one.
  std::array<double, 2> reading_max{};
  std::vector<double> joint_max;    // per node, over its points and the readings
  std::vector<double> channel_max;  // per channel: length units, or degrees (compared modulo 360)
};

// Both motions must share the skeleton's layout (nodes and channels) and the frame count, and
// their values must fill frames x channels, and the shell distance (file units) must be finite
// and 0 or more; else throws Error (invalid_argument). Without a shell distance, kDefaultShellPercent of the original's reference size.
ErrorReport measure_error(const Motion& original, const Motion& decoded, double shell);
ErrorReport measure_error(const Motion& original, const Motion& decoded);
// kDefaultShellPercent of reference_size(motion), in file units.
double default_shell(const Motion& motion);

// The points a pose is measured on, kPointsPerNode per node in node order: the node's world
// position (FK of `frame_row` under `reading`), then its shell points along x, y, z (for an
// End Site, or with shell = 0, copies of its position: they measure nothing more). Every
// error keyanim reports or verifies goes through this one function, so that the report, the
// encoder's verification and its guarantee change together.
constexpr uint32_t kPointsPerNode = 4;
void measured_points(const Skeleton& skeleton, const double* frame_row, double shell, PositionReading reading,
                     std::vector<std::array<double, 3>>& points);
// The same for two frame rows at once (bit for bit two calls; faster): an original frame and
// its decoding, say. With `nodes`, only the points of the nodes it marks (a set holding every
// ancestor of its members) are computed; the others are left as they were. With add_a and
// add_b (`reading` replace), the points under the add reading too (bit for bit a call with
// it, for much less than a second call).
void measured_points(const Skeleton& skeleton, const double* row_a, const double* row_b, double shell,
                     PositionReading reading, std::vector<std::array<double, 3>>& points_a,
                     std::vector<std::array<double, 3>>& points_b, const uint8_t* nodes = nullptr,
                     std::vector<std::array<double, 3>>* add_a = nullptr,
                     std::vector<std::array<double, 3>>* add_b = nullptr);
// Four frame rows at once (bit for bit two calls of the above, on rows 0 and 1, then 2 and 3;
// faster still where the CPU has AVX2): two frames, original and decoded.
// With `quats`, the rows are a clip's stored values (fk.h's QuatForms).
void measured_points(const Skeleton& skeleton, const std::array<const double*, 4>& rows, double shell,
                     PositionReading reading, std::array<std::vector<std::array<double, 3>>, 4>& points,
                     const uint8_t* nodes = nullptr,
                     std::array<std::vector<std::array<double, 3>>, 4>* points_add = nullptr,
                     const QuatForms* quats = nullptr);
// How many of a node's points are measured (1 or kPointsPerNode).
inline uint32_t measured_point_count(const Joint& node, double shell) noexcept {
  return shell > 0.0 && !node.end_site ? kPointsPerNode : 1;
}

// measure_error in pieces, for callers that produce the decoded frames themselves (window by
// window, on several threads): add frames to one accumulator per window, merge the windows in
// frame order, then report. Windows of measure_window(frame_count) frames give exactly
// measure_error's numbers whatever the number of threads.
class ErrorAccumulator {
 public:
  // Kept by reference. The decoded frames are posed with `decoded` (null: the original's).
  // `shell`: the shell distance in file units.
  ErrorAccumulator(const Skeleton& original, double shell, const Skeleton* decoded = nullptr);
  // Frame `frame`: a frame row of the original and of the decoded motion.
  void add_frame(uint32_t frame, const double* original_row, const double* decoded_row);
  // Frames `frame` and `frame + 1` (rows: original, decoded, original, decoded): two add_frame
  // calls to the bit, posed four rows at once.
  void add_frames(uint32_t frame, const std::array<const double*, 4>& rows);
  // Appends the frames of `later`, which all come after this one's.
  void merge(const ErrorAccumulator& later);
  // The report over `frames` frames (the rms divides by frames x nodes).
  ErrorReport report(uint32_t frames) const;

 private:
  const Skeleton* skeleton_;
  const Skeleton* decoded_skeleton_;
  double shell_;
  double sum_sq_ = 0.0;
  bool any_ = false;
  double max_error_ = 0.0;
  uint32_t worst_joint_ = 0, worst_point_ = 0, worst_frame_ = 0;
  PositionReading worst_reading_ = PositionReading::replace;
  std::array<double, 2> reading_max_{};
  std::vector<double> joint_max_, channel_max_;
  std::vector<double> node_max_;  // scratch of add_frame: this frame's, per node
  void add_points(uint32_t frame, PositionReading reading, const std::vector<std::array<double, 3>>& original,
                  const std::vector<std::array<double, 3>>& decoded);
  void end_frame(const double* original_row, const double* decoded_row);
};
uint32_t measure_window(uint32_t frame_count);

// "LeftHand", "End Site of LeftHand", "LeftHand shell y": a measured point, for reports.
std::string point_name(const Skeleton& skeleton, uint32_t node, uint32_t point);

}  // namespace keyanim::offline
