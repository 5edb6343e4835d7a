// Engine-ready poses (Clip::sample_local / sample_model) against the offline forward
// kinematics (fk.h, itself checked against Blender and scipy) on the very channel values the
// clip samples.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "keyanim/clip.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/fk.h"

using namespace keyanim;
using namespace keyanim::offline;

namespace {

Clip encoded(const std::string& path, Rotations rotations = Rotations::quaternion) {
  Clip clip;
  EncodeSettings s;
  s.rotations = rotations;
  REQUIRE(Clip::load(write_kanim(encode(read_bvh_file(path), s).clip), clip) == Status::ok);
  return clip;
}

// Rotation matrix (row-major, acting on column vectors) of a unit quaternion (x, y, z, w).
Mat3 matrix(const float* q) {
  const double x = q[0], y = q[1], z = q[2], w = q[3];
  return {1 - 2 * (y * y + z * z), 2 * (x * y - z * w),     2 * (x * z + y * w),
          2 * (x * y + z * w),     1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
          2 * (x * z - y * w),     2 * (y * z + x * w),     1 - 2 * (x * x + y * y)};
}

double max_diff(const Mat3& a, const Mat3& b) {
  double d = 0;
  for (int i = 0; i < 9; ++i) d = std::max(d, std::fabs(a[i] - b[i]));
  return d;
}

bool same_bits(const Transform& a, const Transform& b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

TEST_SUITE("pose") {

TEST_CASE("local and model transforms agree with forward kinematics of the sampled channels") {
  for (const auto rotations_as : {Rotations::quaternion, Rotations::euler})
  for (const char* file : {"/cmu_02_01_walk.bvh", "/cmu_131_03_hop.bvh"}) {
    CAPTURE(file);
    CAPTURE(int(rotations_as));
    const Clip clip = encoded(std::string(KEYANIM_REPO_DATA_DIR) + file, rotations_as);
    const Skeleton& sk = clip.skeleton();
    // The stored values posed by the offline FK (binary64; a quaternion node's rotation from
    // its stored x, y, z: QuatForms).
    std::vector<QuatNode> quat_nodes;
    for (uint32_t i = 0; i < clip.quat_node_count(); ++i) quat_nodes.push_back(clip.quat_node(i));
    CHECK(quat_nodes.empty() == (rotations_as == Rotations::euler));
    Skeleton columns = sk;
    columns.assign_channel_columns();
    const QuatForms quats(columns, quat_nodes);
    const size_t nodes = sk.joints.size();
    const double size = skeleton_size(sk);
    std::vector<float> values(clip.channel_count());
    std::vector<double> row(clip.channel_count());
    std::vector<Transform> local(nodes), model(nodes);
    std::vector<Vec3> positions;
    std::vector<Mat3> rotations;
    double worst_rot = 0, worst_pos = 0, worst_norm = 0;
    for (double x = 0; x < clip.frame_count(); x += 0.7) {
      REQUIRE(clip.sample_stored(x, values) == Status::ok);
      for (size_t c = 0; c < row.size(); ++c) row[c] = values[c];
      REQUIRE(clip.sample_local(x, local) == Status::ok);
      REQUIRE(clip.sample_model(x, model) == Status::ok);
      world_pose(sk, row.data(), positions, rotations, PositionReading::replace, &quats);
      for (size_t i = 0; i < nodes; ++i) {
        const Joint& j = sk.joints[i];
        Mat3 want = j.end_site ? Mat3{1, 0, 0, 0, 1, 0, 0, 0, 1} : local_rotation(j, row.data());
        if (quats.of_node[i] >= 0) {  // its rotation: reference * (x, y, z, w)
          const uint32_t c = quats.column[size_t(quats.of_node[i])];
          double q[4];
          stored_rotation(quat_nodes[size_t(quats.of_node[i])], row[c], row[c + 1], row[c + 2], q);
          const float qf[4] = {float(q[0]), float(q[1]), float(q[2]), float(q[3])};
          want = matrix(qf);
        }
        worst_rot = std::max(worst_rot, max_diff(matrix(local[i].rotation), want));
        worst_rot = std::max(worst_rot, max_diff(matrix(model[i].rotation), rotations[i]));
        const float* q = model[i].rotation;
        worst_norm = std::max(worst_norm, std::fabs(std::sqrt(double(q[0]) * q[0] + double(q[1]) * q[1] +
                                                              double(q[2]) * q[2] + double(q[3]) * q[3]) - 1.0));
        for (int k = 0; k < 3; ++k)
          worst_pos = std::max(worst_pos, std::fabs(model[i].translation[k] - positions[i][k]));
      }
    }
    // binary32 quaternions and positions: a few ulps per level of the hierarchy (a quaternion
    // node's rebuilt w and product with its reference a few more).
    CHECK(worst_rot < (rotations_as == Rotations::euler ? 2e-6 : 4e-6));
    CHECK(worst_norm < 2e-6);
    CHECK(worst_pos < 2e-6 * size * 8);
  }
}

TEST_CASE("quaternions are continuous from frame to frame and the cursor changes nothing") {
  const Clip clip = encoded(std::string(KEYANIM_REPO_DATA_DIR) + "/cmu_02_01_walk.bvh");
  const size_t nodes = clip.skeleton().joints.size();
  std::vector<Transform> a(nodes), b(nodes), prev(nodes);
  Cursor cursor;
  REQUIRE(cursor.prepare(clip) == Status::ok);
  uint64_t mismatches = 0;
  double worst_dot = 1.0;
  for (double x = 0; x < clip.frame_count(); x += 0.5) {
    REQUIRE(clip.sample_local(x, a) == Status::ok);
    REQUIRE(clip.sample_local(x, b, &cursor) == Status::ok);
    for (size_t i = 0; i < nodes; ++i) {
      mismatches += !same_bits(a[i], b[i]);
      if (x > 0) {
        double dot = 0;
        for (int k = 0; k < 4; ++k) dot += double(a[i].rotation[k]) * prev[i].rotation[k];
        worst_dot = std::min(worst_dot, dot);
      }
    }
    prev = a;
  }
  CHECK(mismatches == 0);
  CHECK(worst_dot > 0.9);  // half a frame apart at 120 fps: the same hemisphere, close together
  std::vector<Transform> m1(nodes), m2(nodes);
  REQUIRE(clip.sample_model(17.25, m1) == Status::ok);
  REQUIRE(clip.sample_model(17.25, m2, &cursor) == Status::ok);
  for (size_t i = 0; i < nodes; ++i) CHECK(same_bits(m1[i], m2[i]));
}

TEST_CASE("position channels replace or add to the offset") {
  Motion m;
  Joint root{"Root", -1, {1, 2, 3}, {ChannelType::x_position, ChannelType::y_position, ChannelType::z_position}};
  Joint child{"Child", 0, {10, 20, 30}, {ChannelType::y_position, ChannelType::z_rotation}};
  Joint end{"", 1, {0, 5, 0}, {}, true};
  m.skeleton.joints = {root, child, end};
  m.skeleton.assign_channel_columns();
  m.frame_count = 2;
  m.frame_time = 0.1;
  m.values = {4, 5, 6, 7, 90, 4, 5, 6, 7, 90};
  EncodeSettings s;
  s.tolerance = 1e-6;
  s.tolerance_in_percent = false;
  const Clip clip = to_clip(encode(m, s).clip);
  std::vector<Transform> t(3);
  REQUIRE(clip.sample_local(0.0, t, nullptr, PositionReading::replace) == Status::ok);
  // (Values are the quantized keys: within the 1e-6 tolerance of the motion's.)
  CHECK(std::fabs(t[0].translation[0] - 4.0f) < 2e-6);
  CHECK(t[1].translation[0] == 10.0f);  // OFFSET components are exact
  CHECK(std::fabs(t[1].translation[1] - 7.0f) < 2e-6);
  CHECK(t[2].translation[1] == 5.0f);
  REQUIRE(clip.sample_local(0.0, t, nullptr, PositionReading::add) == Status::ok);
  CHECK(std::fabs(t[0].translation[0] - 5.0f) < 2e-6);
  CHECK(std::fabs(t[0].translation[2] - 9.0f) < 2e-6);
  CHECK(std::fabs(t[1].translation[1] - 27.0f) < 4e-6);
  // Z rotation of 90 degrees: (0, 0, sin 45, cos 45).
  CHECK(std::fabs(t[1].rotation[2] - float(std::sqrt(0.5))) < 1e-7);
  CHECK(std::fabs(t[1].rotation[3] - float(std::sqrt(0.5))) < 1e-7);
  // The End Site in model space: child at (4,5,6) + (10,7,30), then (0,5,0) turned 90 about Z.
  REQUIRE(clip.sample_model(0.0, t) == Status::ok);
  CHECK(std::fabs(t[2].translation[0] - (14.0f - 5.0f)) < 1e-5);
  CHECK(std::fabs(t[2].translation[1] - 12.0f) < 1e-5);
  CHECK(std::fabs(t[2].translation[2] - 36.0f) < 1e-5);
}

TEST_CASE("pose sampling refuses NaN and short outputs") {
  const Clip clip = encoded(std::string(KEYANIM_REPO_DATA_DIR) + "/cmu_02_01_walk.bvh");
  std::vector<Transform> t(clip.skeleton().joints.size()), small(3);
  CHECK(clip.sample_local(std::nan(""), t) == Status::invalid_argument);
  CHECK(clip.sample_model(std::nan(""), t) == Status::invalid_argument);
  CHECK(clip.sample_local(1.0, small) == Status::output_too_small);
  CHECK(clip.sample_model(1.0, small) == Status::output_too_small);
  Cursor unprepared;
  CHECK(clip.sample_local(1.0, t, &unprepared) == Status::invalid_argument);
  const Clip empty;
  std::vector<Transform> none;
  CHECK(empty.sample_local(0.0, none) == Status::ok);
}

}  // TEST_SUITE
