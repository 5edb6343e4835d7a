// Issue 28, item 9: what render guesses when a BVH does not say. The up axis from the rest pose
// (y for data/'s CMU walk, z for the same skeleton turned +90 degrees about x, unclear for a
// skeleton as deep as it is tall); the reading under which the bones stay rigid (replace when
// the channels repeat the Offsets, as Bandai's do, with one node carrying a translation; add
// when they hold deltas, as MakeHuman's do); and a z-up file drawn upright: its front view is
// the y-up original's, line for line.
#include <doctest/doctest.h>

#include <regex>
#include <string>
#include <vector>

#include "conventions.h"
#include "figures.h"
#include "keyanim/offline/bvh.h"

using namespace keyanim;
using namespace keyanim::offline;
using cli::UpAxis;

namespace {

Motion walk() { return read_bvh_file(KEYANIM_REPO_DATA_DIR "/cmu_02_01_walk.bvh"); }

// The rest pose alone (every channel 0), turned +90 degrees about x when `z_up`:
// (x, y, z) -> (x, -z, y), which makes y-up z-up.
Motion rest(const Motion& m, bool z_up) {
  Motion r;
  r.skeleton = m.skeleton;
  r.frame_count = 1;
  r.frame_time = m.frame_time;
  r.values.assign(m.channel_count(), 0.0);
  if (z_up)
    for (Joint& j : r.skeleton.joints) j.offset = {j.offset[0], -j.offset[2], j.offset[1]};
  return r;
}

// A two-level skeleton with position channels on every joint: a root and `n` children below
// it, with Offset (0, 10, 0); frame 0 sets each child's position channels to `value`, the first
// child's to (0, 10, 300) (a node that carries a translation, like Bandai's Hips).
Motion with_positions(uint32_t n, std::array<double, 3> value) {
  Motion m;
  Joint root{"root", -1, {0, 0, 0}, {ChannelType::x_position, ChannelType::y_position, ChannelType::z_position}, false, 0};
  m.skeleton.joints.push_back(root);
  for (uint32_t i = 0; i < n; ++i) {
    Joint j = root;
    j.name = "j" + std::to_string(i), j.parent = 0, j.offset = {0, 10, 0};
    m.skeleton.joints.push_back(j);
  }
  m.skeleton.assign_channel_columns();
  m.frame_count = 1;
  m.frame_time = 0.1;
  m.values.assign(m.channel_count(), 0.0);
  for (uint32_t i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) m.values[3 * (i + 1) + size_t(a)] = i == 0 ? std::array<double, 3>{0, 10, 300}[size_t(a)] : value[size_t(a)];
  return m;
}

std::vector<std::string> bones(const std::string& svg) {
  std::vector<std::string> out;
  const std::regex re("<line [^>]*class=\"bone\"/>");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), re); it != std::sregex_iterator(); ++it) out.push_back(it->str());
  return out;
}

}  // namespace

TEST_CASE("up axis: y for the CMU walk, z for it turned, unclear for a cube") {
  const Motion m = walk();
  const cli::UpGuess y = cli::detect_up_axis(m.skeleton), z = cli::detect_up_axis(rest(m, true).skeleton);
  CHECK(y.axis == UpAxis::y);
  CHECK_FALSE(y.ambiguous);
  CHECK(z.axis == UpAxis::z);
  CHECK_FALSE(z.ambiguous);
  CHECK(z.extents[2] == doctest::Approx(y.extents[1]));
  Motion cube = with_positions(1, {0, 0, 0});
  cube.skeleton.joints[1].offset = {0, 10, 10};
  const cli::UpGuess c = cli::detect_up_axis(cube.skeleton);
  CHECK(c.ambiguous);
  CHECK(c.axis == UpAxis::y);
}

TEST_CASE("rigid reading: replace when the channels repeat the Offsets, add when they are deltas") {
  const Motion bandai_like = with_positions(8, {0, 10, 0}), deltas = with_positions(8, {0, 0.01, 0});
  CHECK(cli::rigid_reading(bandai_like, 0) == PositionReading::replace);
  CHECK(cli::rigid_bones(bandai_like, 0).kept == std::array<uint32_t, 2>{7, 0});  // j0 carries a translation
  CHECK(cli::rigid_reading(deltas, 0) == PositionReading::add);
  CHECK(cli::rigid_bones(deltas, 0).nodes == 8);
  // Half-way (channels of 5 on an Offset of 10): neither keeps the bones, no guess.
  CHECK_FALSE(cli::rigid_reading(with_positions(8, {0, 5, 0}), 0).has_value());
  CHECK_FALSE(cli::rigid_reading(walk(), 0).has_value());  // no position channels below the root
}

TEST_CASE("render of a z-up file: upright, its front view the y-up original's") {
  const Motion m = walk(), y = rest(m, false), z = rest(m, true);
  const std::string up_y = cli::render_pose({{&y, "y"}}, 0, "t", PositionReading::replace, UpAxis::y).svg;
  const std::string up_z = cli::render_pose({{&z, "z"}}, 0, "t", PositionReading::replace, UpAxis::z).svg;
  const std::string lying = cli::render_pose({{&z, "z"}}, 0, "t", PositionReading::replace, UpAxis::y).svg;
  CHECK(up_z.find(">front view (x-z)</text>") != std::string::npos);
  CHECK(up_z.find(">side view (y-z)</text>") != std::string::npos);
  CHECK(up_z.find(">z (file units)</text>") != std::string::npos);
  const std::vector<std::string> a = bones(up_y), b = bones(up_z), c = bones(lying);
  REQUIRE(a.size() == 2 * 37);  // 37 bones in each view
  REQUIRE(b.size() == a.size());
  CHECK(std::vector<std::string>(a.begin(), a.begin() + 37) == std::vector<std::string>(b.begin(), b.begin() + 37));
  // Drawn y-up, the turned file's front view is another picture (the figure lies down).
  CHECK(std::vector<std::string>(a.begin(), a.begin() + 37) != std::vector<std::string>(c.begin(), c.begin() + 37));
}
