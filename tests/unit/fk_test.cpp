// Forward kinematics and error metrics against independent references: poses computed by hand,
// a naive product of literal rotation matrices, and world positions exported by Blender's BVH
// importer and by scipy (tests/data/fk/README.md says how those were made).
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "corpus_files.h"
#include "report_checks.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/fk.h"
#include "keyanim/offline/metrics.h"

namespace {

using keyanim::ChannelType;
using keyanim::Joint;
using keyanim::Skeleton;
using keyanim::offline::Mat3;
using keyanim::offline::Motion;
using keyanim::offline::Vec3;

constexpr ChannelType kXp = ChannelType::x_position;
constexpr ChannelType kYp = ChannelType::y_position;
constexpr ChannelType kZp = ChannelType::z_position;
constexpr ChannelType kXr = ChannelType::x_rotation;
constexpr ChannelType kYr = ChannelType::y_rotation;
constexpr ChannelType kZr = ChannelType::z_rotation;

Joint joint(const char* name, int32_t parent, Vec3 offset, std::vector<ChannelType> channels) {
  Joint j;
  j.name = name;
  j.parent = parent;
  j.offset = offset;
  j.channels = std::move(channels);
  return j;
}

Joint end_site(int32_t parent, Vec3 offset) {
  Joint j;
  j.parent = parent;
  j.offset = offset;
  j.end_site = true;
  return j;
}

Skeleton skeleton_of(std::vector<Joint> joints) {
  Skeleton s;
  s.joints = std::move(joints);
  s.assign_channel_columns();
  return s;
}

std::vector<Vec3> fk(const Skeleton& s, const std::vector<double>& row) {
  std::vector<Vec3> out;
  keyanim::offline::world_positions(s, row.data(), out);
  return out;
}

double distance(const Vec3& a, const Vec3& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

void check_at(const Vec3& got, const Vec3& want, double tol = 1e-12) {
  INFO("got (" << got[0] << ", " << got[1] << ", " << got[2] << "), want (" << want[0] << ", "
               << want[1] << ", " << want[2] << ")");
  CHECK(distance(got, want) <= tol);
}

// Literal right-handed elementary rotations and a naive product: a second implementation of
// the Euler composition, sharing nothing with fk.cpp's column updates.
Mat3 elementary(ChannelType axis, double degrees) {
  const double a = degrees * std::numbers::pi / 180.0;
  const double c = std::cos(a);
  const double s = std::sin(a);
  if (axis == kXr) return {1, 0, 0, 0, c, -s, 0, s, c};
  if (axis == kYr) return {c, 0, s, 0, 1, 0, -s, 0, c};
  return {c, -s, 0, s, c, 0, 0, 0, 1};
}

Mat3 multiply(const Mat3& a, const Mat3& b) {
  Mat3 m{};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) m[r * 3 + c] += a[r * 3 + k] * b[k * 3 + c];
  return m;
}

}  // namespace

TEST_SUITE("fk") {

// Chain used below: Hips (root) -> Knee at OFFSET (0,-4,0) -> End Site at OFFSET (0,0,2).
// Rz(90) takes x->y, y->-x; Rx(90) takes y->z, z->-y; Ry(90) takes z->x, x->-z.
TEST_CASE("fk hand-computed chain with position channels and ZYX order") {
  const Skeleton s = skeleton_of({
      joint("Hips", -1, {1, 2, 3}, {kXp, kYp, kZp, kZr, kYr, kXr}),
      joint("Knee", 0, {0, -4, 0}, {kZr, kYr, kXr}),
      end_site(1, {0, 0, 2}),
  });
  // Hips at (10,20,30) (the channels replace OFFSET (1,2,3)), Hips Z=90, Knee X=90.
  const auto p = fk(s, {10, 20, 30, 90, 0, 0, 0, 0, 90});
  REQUIRE(p.size() == 3);
  check_at(p[0], {10, 20, 30});
  // Knee = Hips + Rz90 (0,-4,0) = (10,20,30) + (4,0,0).
  check_at(p[1], {14, 20, 30});
  // End = Knee + Rz90 Rx90 (0,0,2) = Knee + Rz90 (0,-2,0) = Knee + (2,0,0).
  check_at(p[2], {16, 20, 30});
}

TEST_CASE("fk hand-computed chain depends on the listed rotation order") {
  // Root OFFSET (1,2,3) and no position channels; root angles Z=90, X=90 in two orders.
  const Skeleton zxy = skeleton_of({
      joint("Hips", -1, {1, 2, 3}, {kZr, kXr, kYr}),
      joint("Knee", 0, {0, -4, 0}, {kZr, kXr, kYr}),
      end_site(1, {0, 0, 2}),
  });
  // R = Rz90 Rx90. Knee = (1,2,3) + Rz90 Rx90 (0,-4,0) = (1,2,3) + Rz90 (0,0,-4) = (1,2,-1).
  // End = Knee + Rz90 Rx90 (0,0,2) = Knee + Rz90 (0,-2,0) = Knee + (2,0,0) = (3,2,-1).
  auto p = fk(zxy, {90, 90, 0, 0, 0, 0});
  check_at(p[0], {1, 2, 3});
  check_at(p[1], {1, 2, -1});
  check_at(p[2], {3, 2, -1});

  const Skeleton xzy = skeleton_of({
      joint("Hips", -1, {1, 2, 3}, {kXr, kZr, kYr}),
      joint("Knee", 0, {0, -4, 0}, {kZr, kXr, kYr}),
      end_site(1, {0, 0, 2}),
  });
  // R = Rx90 Rz90. Knee = (1,2,3) + Rx90 (4,0,0) = (5,2,3).
  // End = Knee + Rx90 Rz90 (0,0,2) = Knee + Rx90 (0,0,2) = Knee + (0,-2,0) = (5,0,3).
  p = fk(xzy, {90, 90, 0, 0, 0, 0});
  check_at(p[1], {5, 2, 3});
  check_at(p[2], {5, 0, 3});
}

TEST_CASE("fk hand-computed Y and Z turns in both orders") {
  // Root at the origin, joint B at OFFSET (1,0,0), End Site at OFFSET (0,2,0); Y=90 and Z=90.
  const Skeleton yz = skeleton_of({
      joint("A", -1, {0, 0, 0}, {kYr, kZr}),
      joint("B", 0, {1, 0, 0}, {kZr}),
      end_site(1, {0, 2, 0}),
  });
  // R = Ry90 Rz90: B = Ry90 (0,1,0) = (0,1,0); End = B + Ry90 (-2,0,0) = B + (0,0,2).
  auto p = fk(yz, {90, 90, 0});
  check_at(p[1], {0, 1, 0});
  check_at(p[2], {0, 1, 2});
  const Skeleton zy = skeleton_of({
      joint("A", -1, {0, 0, 0}, {kZr, kYr}),
      joint("B", 0, {1, 0, 0}, {kZr}),
      end_site(1, {0, 2, 0}),
  });
  // R = Rz90 Ry90: B = Rz90 (0,0,-1) = (0,0,-1); End = B + Rz90 (0,2,0) = B + (-2,0,0).
  p = fk(zy, {90, 90, 0});
  check_at(p[1], {0, 0, -1});
  check_at(p[2], {-2, 0, -1});
  // B's own rotation turns its End Site but not B: B Z=90 with the root still Y=90, Z=90:
  // End = B + Ry90 Rz90 Rz90 (0,2,0) = B + Ry90 (0,-2,0) = (0,1,0) + (0,-2,0).
  p = fk(yz, {90, 90, 90});
  check_at(p[1], {0, 1, 0});
  check_at(p[2], {0, -1, 0});
}

TEST_CASE("fk non-right angle and partial position channels") {
  const Skeleton s = skeleton_of({
      joint("Root", -1, {0, 0, 0}, {kZr}),
      joint("Slide", 0, {1, 2, 3}, {kYp}),  // Yposition replaces only OFFSET's y
      joint("Arm", 0, {2, 0, 0}, {}),
  });
  // Z=30: Slide = Rz30 (1,7,3) = (cos30 - 7 sin30, sin30 + 7 cos30, 3); Arm = (2cos30, 2sin30, 0).
  const double c = std::sqrt(3.0) / 2.0;
  const auto p = fk(s, {30, 7});
  check_at(p[1], {c - 3.5, 0.5 + 7 * c, 3}, 1e-14);
  check_at(p[2], {2 * c, 1, 0}, 1e-14);
}

TEST_CASE("fk angles 360 degrees apart give identical positions") {
  const Skeleton s = skeleton_of({
      joint("Hips", -1, {0, 0, 0}, {kZr, kXr, kYr}),
      joint("Knee", 0, {0, -4, 0}, {kZr, kXr, kYr}),
      end_site(1, {0.5, 0, 2}),
  });
  const auto a = fk(s, {30.25, -17.5, 101.125, 12.5, 250.75, -3});
  const auto b = fk(s, {390.25, 342.5, -258.875, -347.5, -109.25, 717});
  for (size_t j = 0; j < a.size(); ++j) CHECK(a[j] == b[j]);
}

TEST_CASE("fk sine and cosine are within one ulp of libm, exact at right angles") {
  // The kernel is fdlibm's, not libm's: the same bits everywhere. libm (correctly rounded or
  // nearly) is the independent reference here.
  auto ulps = [](double a, double b) {
    if (a == b) return 0.0;
    return std::fabs(a - b) / (std::nextafter(std::fabs(b), HUGE_VAL) - std::fabs(b));
  };
  double worst = 0.0;
  for (int i = -200000; i <= 200000; ++i) {
    const double deg = i * 0.0137 + 0.25 * std::sin(double(i));  // dense over [-2740, 2740]
    double s, c;
    keyanim::offline::sin_cos_deg(deg, s, c);
    // Reference on the same reduced angle: the reduction is exact, so this isolates the kernel.
    const double q = std::nearbyint(deg / 90.0);
    const double r = (deg - q * 90.0) * (std::numbers::pi / 180.0);
    const int quadrant = int(std::fmod(std::fmod(q, 4.0) + 4.0, 4.0));
    const double sr = std::sin(r), cr = std::cos(r);
    const double want_s = quadrant == 0 ? sr : quadrant == 1 ? cr : quadrant == 2 ? -sr : -cr;
    const double want_c = quadrant == 0 ? cr : quadrant == 1 ? -sr : quadrant == 2 ? -cr : sr;
    worst = std::max({worst, ulps(s, want_s), ulps(c, want_c)});
  }
  CHECK(worst <= 1.0);
  for (int k = -8; k <= 8; ++k) {
    double s, c;
    keyanim::offline::sin_cos_deg(90.0 * k, s, c);
    const int q = ((k % 4) + 4) % 4;
    CHECK(s == (q == 1 ? 1.0 : q == 3 ? -1.0 : 0.0));
    CHECK(c == (q == 0 ? 1.0 : q == 2 ? -1.0 : 0.0));
  }
}

TEST_CASE("fk of two or four frames at once is bit for bit one frame at a time") {
  // Every frame of two corpus clips paired with another, with and without a node subset, plus
  // angles that take the scalar path (10^9 degrees and more) in one lane only. Without the
  // corpus, the same CMU 131_03 take shipped in data/.
  std::vector<std::string> paths;
  for (const auto& path : keyanim::test::corpus_bvh_files())
    if (path.filename().string().find("131_03") != std::string::npos ||
        path.filename().string().find("05_20-daz") != std::string::npos)
      paths.push_back(path.string());
  if (paths.empty()) paths.push_back(KEYANIM_REPO_DATA_DIR "/cmu_131_03_hop.bvh");
  std::vector<Motion> motions;
  for (const std::string& path : paths) {
    Motion m = keyanim::offline::read_bvh_file(path);
    motions.push_back(std::move(m));
  }
  Motion odd;
  odd.skeleton = skeleton_of({joint("Hips", -1, {1, 2, 3}, {kXp, kZr, kXr, kYr}), joint("Arm", 0, {0, 4, 0}, {kZr, kXr, kYr}),
                              end_site(1, {0, 0, 5})});
  odd.frame_count = 3;
  odd.values = {0.5, 30.25, -1e9, 720.5, 45, 135, -225,
                -2, 3e12, -17.5, 90, -45, -135, 1e-300,
                0, -0.0, 44.999999999999, 45.000000000001, -90, 180, 359.5};
  motions.push_back(odd);
  size_t differ = 0, pairs = 0, quads = 0;
  std::vector<Vec3> a, b, a2, b2;
  std::array<std::vector<Vec3>, 4> four;
  for (const Motion& m : motions) {
    const size_t n = m.skeleton.joints.size();
    std::vector<uint8_t> some(n, 0);
    for (size_t j = 0; j < n; j += 3) some[j] = 1;  // every third node and its ancestors
    for (size_t j = n; j-- > 0;)
      if (some[j] && m.skeleton.joints[j].parent >= 0) some[size_t(m.skeleton.joints[j].parent)] = 1;
    for (uint32_t f = 0; f < m.frame_count; ++f) {
      const uint32_t g = (f * 7 + 3) % m.frame_count;
      for (const uint8_t* nodes : {static_cast<const uint8_t*>(nullptr), static_cast<const uint8_t*>(some.data())}) {
        keyanim::offline::world_positions(m.skeleton, m.frame(f), m.frame(g), nodes, a2, b2);
        if (nodes) {
          keyanim::offline::world_positions(m.skeleton, m.frame(f), nodes, a);
          keyanim::offline::world_positions(m.skeleton, m.frame(g), nodes, b);
        } else {
          keyanim::offline::world_positions(m.skeleton, m.frame(f), a);
          keyanim::offline::world_positions(m.skeleton, m.frame(g), b);
        }
        for (size_t j = 0; j < n; ++j) {
          if (nodes && !nodes[j]) continue;
          for (int k = 0; k < 3; ++k)
            differ += std::memcmp(&a[j][k], &a2[j][k], 8) != 0 || std::memcmp(&b[j][k], &b2[j][k], 8) != 0;
        }
        ++pairs;
      }
      // The measured points too (shell points, either reading).
      for (const auto reading : {keyanim::PositionReading::replace, keyanim::PositionReading::add}) {
        keyanim::offline::measured_points(m.skeleton, m.frame(f), m.frame(g), 1.75, reading, a2, b2);
        keyanim::offline::measured_points(m.skeleton, m.frame(f), 1.75, reading, a);
        keyanim::offline::measured_points(m.skeleton, m.frame(g), 1.75, reading, b);
        REQUIRE(a.size() == a2.size());
        differ += std::memcmp(a.data(), a2.data(), a.size() * sizeof(Vec3)) != 0 ||
                  std::memcmp(b.data(), b2.data(), b.size() * sizeof(Vec3)) != 0;
        // Four rows at once (four AVX lanes where the CPU has AVX2): rows f, g, g + 1, f.
        const uint32_t h = (g + 1) % m.frame_count;
        std::vector<Vec3> c;
        keyanim::offline::measured_points(m.skeleton, m.frame(h), 1.75, reading, c);
        keyanim::offline::measured_points(m.skeleton, {m.frame(f), m.frame(g), m.frame(h), m.frame(f)}, 1.75, reading,
                                          four);
        for (const auto& [got, want] : {std::pair{&four[0], &a}, {&four[1], &b}, {&four[2], &c}, {&four[3], &a}}) {
          REQUIRE(got->size() == want->size());
          differ += std::memcmp(got->data(), want->data(), want->size() * sizeof(Vec3)) != 0;
        }
        ++quads;
      }
      // Four rows with a node subset: the marked nodes' points are those of one row at a time.
      keyanim::offline::measured_points(m.skeleton, {m.frame(g), m.frame(f), m.frame(f), m.frame(g)}, 0.5,
                                        keyanim::PositionReading::replace, four, some.data());
      keyanim::offline::measured_points(m.skeleton, m.frame(f), 0.5, keyanim::PositionReading::replace, a);
      keyanim::offline::measured_points(m.skeleton, m.frame(g), 0.5, keyanim::PositionReading::replace, b);
      for (size_t j = 0; j < n; ++j) {
        if (!some[j]) continue;
        for (size_t p = 4 * j; p < 4 * j + 4; ++p)
          differ += four[0][p] != b[p] || four[1][p] != a[p] || four[2][p] != a[p] || four[3][p] != b[p];
      }
    }
  }
  CHECK(pairs > 1000);
  CHECK(quads > 1000);
  CHECK(differ == 0);
}

TEST_CASE("fk of both readings in one pass is bit for bit a pass per reading") {
  // A Bandai take (position channels on every joint) when the corpus is here, and always a
  // chain with position channels below the root and angles that take the scalar sine path.
  std::vector<Motion> motions;
  for (const auto& path : keyanim::test::corpus_bvh_files())
    if (path.filename().string().find("bow_feminine_001") != std::string::npos)
      motions.push_back(keyanim::offline::read_bvh_file(path.string()));
  Motion chain;
  chain.skeleton = skeleton_of({joint("Hips", -1, {1, 2, 3}, {kXp, kYp, kZp, kZr, kXr, kYr}),
                                joint("Arm", 0, {0, 4, 0}, {kXp, kZp, kZr, kXr, kYr}), end_site(1, {0, 0, 5}),
                                joint("Leg", 0, {0.5, -3, 0.25}, {kYp, kXr, kZr})});
  chain.frame_count = 3;
  chain.values = {0.5, -1, 2, 30.25, -1e9, 720.5, 7, -3.5, 45, 135, -225, 0.125, 10, 20,
                  -2, 0, 1e-3, 3e12, -17.5, 90, 1e5, -1e5, -45, -135, 1e-300, -0.0, 33, -33,
                  0, 0.25, -0.25, -0.0, 44.999999999999, 45.000000000001, 9, 8, -90, 180, 359.5, 1, 2, 3};
  motions.push_back(chain);
  const auto replace = keyanim::PositionReading::replace, add = keyanim::PositionReading::add;
  size_t compared = 0, differ = 0, frames = 0;
  for (const Motion& m : motions) {
    REQUIRE(keyanim::offline::has_position_channels_below_root(m.skeleton));
    const size_t n = m.skeleton.joints.size();
    std::vector<uint8_t> some(n, 0);
    for (size_t j = 1; j < n; j += 3) some[j] = 1;  // every third node and its ancestors
    for (size_t j = n; j-- > 0;)
      if (some[j] && m.skeleton.joints[j].parent >= 0) some[size_t(m.skeleton.joints[j].parent)] = 1;
    auto same = [&](const std::vector<Vec3>& got, const std::vector<Vec3>& want, const uint8_t* nodes) {
      for (size_t j = 0; j < n; ++j)
        if (!nodes || nodes[j]) differ += std::memcmp(&got[4 * j], &want[4 * j], 4 * sizeof(Vec3)) != 0;
      ++compared;
    };
    std::array<std::vector<Vec3>, 4> four, four_add, one_pass, one_pass_add;
    std::vector<Vec3> a, b, a_add, b_add;
    frames += m.frame_count;
    for (uint32_t f = 0; f < m.frame_count; ++f) {
      const uint32_t g = (f * 7 + 1) % m.frame_count, h = (f + 2) % m.frame_count;
      const std::array<const double*, 4> rows{m.frame(f), m.frame(g), m.frame(h), m.frame(f)};
      for (const uint8_t* nodes : {static_cast<const uint8_t*>(nullptr), static_cast<const uint8_t*>(some.data())}) {
        keyanim::offline::measured_points(m.skeleton, rows, 1.5, replace, four, nodes);
        keyanim::offline::measured_points(m.skeleton, rows, 1.5, add, four_add, nodes);
        keyanim::offline::measured_points(m.skeleton, rows, 1.5, replace, one_pass, nodes, &one_pass_add);
        for (size_t i = 0; i < 4; ++i) same(one_pass[i], four[i], nodes), same(one_pass_add[i], four_add[i], nodes);
        // Two rows (SSE2 lanes on every machine).
        keyanim::offline::measured_points(m.skeleton, m.frame(f), m.frame(g), 1.5, replace, a, b, nodes, &a_add, &b_add);
        same(a, four[0], nodes), same(b, four[1], nodes), same(a_add, four_add[0], nodes), same(b_add, four_add[1], nodes);
      }
    }
    // The add reading does differ from replace here (else the test could not tell them apart).
    CHECK(std::memcmp(four[0].data(), four_add[0].data(), four[0].size() * sizeof(Vec3)) != 0);
  }
  CHECK(compared == frames * 2 * 12);  // every frame, both node sets, 8 four-row and 4 two-row outputs
  CHECK(differ == 0);
}

TEST_CASE("fk local rotation equals the product of literal elementary matrices") {
  const std::array<std::array<ChannelType, 3>, 6> orders{{{kXr, kYr, kZr},
                                                           {kXr, kZr, kYr},
                                                           {kYr, kXr, kZr},
                                                           {kYr, kZr, kXr},
                                                           {kZr, kXr, kYr},
                                                           {kZr, kYr, kXr}}};
  const std::vector<double> row{5, 6, 7, 23.5, -71.25, 148.0};
  for (const auto& order : orders) {
    Joint j = joint("J", -1, {0, 0, 0}, {kXp, kYp, kZp, order[0], order[1], order[2]});
    const Mat3 got = keyanim::offline::local_rotation(j, row.data());
    const Mat3 want = multiply(multiply(elementary(order[0], row[3]), elementary(order[1], row[4])),
                               elementary(order[2], row[5]));
    for (size_t k = 0; k < 9; ++k) CHECK(got[k] == doctest::Approx(want[k]).epsilon(1e-13));
  }
}

TEST_CASE("fk world pose rotations compose parent then local") {
  const Skeleton s = skeleton_of({
      joint("Hips", -1, {0, 0, 0}, {kXp, kYp, kZp, kYr, kXr, kZr}),
      joint("Spine", 0, {0, 3, 0}, {kXr, kZr, kYr}),
      end_site(1, {0, 1, 0}),
  });
  const std::vector<double> row{1, 2, 3, 10, 20, 30, -40, 50, -60};
  std::vector<Vec3> pos;
  std::vector<Mat3> rot;
  keyanim::offline::world_pose(s, row.data(), pos, rot);
  const Mat3 hips = multiply(multiply(elementary(kYr, 10), elementary(kXr, 20)), elementary(kZr, 30));
  const Mat3 spine = multiply(
      hips, multiply(multiply(elementary(kXr, -40), elementary(kZr, 50)), elementary(kYr, -60)));
  for (size_t k = 0; k < 9; ++k) {
    CHECK(rot[0][k] == doctest::Approx(hips[k]).epsilon(1e-13));
    CHECK(rot[1][k] == doctest::Approx(spine[k]).epsilon(1e-13));
    CHECK(rot[2][k] == rot[1][k]);  // an End Site has no rotation of its own
  }
  // Spine = (1,2,3) + hips (0,3,0); End = Spine + spine (0,1,0): the middle columns.
  check_at(pos[1], {1 + 3 * hips[1], 2 + 3 * hips[4], 3 + 3 * hips[7]}, 1e-13);
  check_at(pos[2], {pos[1][0] + spine[1], pos[1][1] + spine[4], pos[1][2] + spine[7]}, 1e-13);
  // world_positions is the same computation.
  const auto p = fk(s, row);
  for (size_t j = 0; j < 3; ++j) CHECK(p[j] == pos[j]);
}

TEST_CASE("fk several roots each start at the origin") {
  const Skeleton s = skeleton_of({
      joint("A", -1, {1, 0, 0}, {kZr}),
      end_site(0, {1, 0, 0}),
      joint("B", -1, {0, 0, 5}, {kXr}),
      end_site(2, {0, 1, 0}),
  });
  const auto p = fk(s, {90, 90});
  check_at(p[0], {1, 0, 0});
  check_at(p[1], {1, 1, 0});
  check_at(p[2], {0, 0, 5});
  check_at(p[3], {0, 0, 6});
}

TEST_CASE("fk a parent index not before its child is treated as a root") {
  Skeleton s = skeleton_of({joint("A", -1, {1, 0, 0}, {}), joint("B", 5, {0, 2, 0}, {})});
  const auto p = fk(s, {});
  check_at(p[1], {0, 2, 0});
  s.joints[1].parent = 1;  // itself
  check_at(fk(s, {})[1], {0, 2, 0});
}

TEST_CASE("fk world_positions_all matches per-frame world_positions") {
  Motion m;
  m.skeleton = skeleton_of({
      joint("Hips", -1, {0, 0, 0}, {kXp, kYp, kZp, kZr, kXr, kYr}),
      joint("Knee", 0, {0, -4, 0}, {kZr, kXr, kYr}),
      end_site(1, {0, 0, 2}),
  });
  m.frame_count = 3;
  for (int f = 0; f < 3; ++f)
    for (int c = 0; c < 9; ++c) m.values.push_back(0.5 * f + 7.25 * c - 11.0 * f * c);
  const auto all = keyanim::offline::world_positions_all(m);
  REQUIRE(all.size() == 9);
  for (uint32_t f = 0; f < 3; ++f) {
    std::vector<Vec3> one;
    keyanim::offline::world_positions(m.skeleton, m.frame(f), one);
    for (size_t j = 0; j < 3; ++j) CHECK(all[f * 3 + j] == one[j]);
  }
  // Too few values for the last frame: an error, not a read past the end.
  Motion partial = m;
  partial.values.resize(2 * 9 + 4);
  CHECK_THROWS_AS(keyanim::offline::world_positions_all(partial), keyanim::offline::Error);
  // first_channel past the row: an error.
  m.skeleton.joints[1].first_channel = 8;
  CHECK_FALSE(keyanim::offline::channel_columns_consistent(m.skeleton));
  CHECK_THROWS_AS(keyanim::offline::world_positions_all(m), keyanim::offline::Error);
}

TEST_CASE("fk skeleton size is the largest side of the rest-pose box") {
  // Rest positions: Root (100,0,0), Spine (100,10,0), End (103,10,0), Leg (98,-5,1),
  // Foot End Site (98,-5,-7). Box sides x 5, y 15, z 8.
  const Skeleton s = skeleton_of({
      joint("Root", -1, {100, 0, 0}, {kXp, kYp, kZp, kZr, kYr, kXr}),
      joint("Spine", 0, {0, 10, 0}, {kZr}),
      end_site(1, {3, 0, 0}),
      joint("Leg", 0, {-2, -5, 1}, {kZr}),
      end_site(3, {0, 0, -8}),
  });
  CHECK(keyanim::offline::skeleton_size(s) == 15.0);
  // An End Site can set the size: the foot 20 below the leg makes y span 10 - (-25) = 35.
  Skeleton t = s;
  t.joints[4].offset = {0, -20, 0};
  CHECK(keyanim::offline::skeleton_size(t) == 35.0);
  CHECK(keyanim::offline::skeleton_size(Skeleton{}) == 0.0);
  CHECK(keyanim::offline::skeleton_size(skeleton_of({joint("A", -1, {4, 5, 6}, {})})) == 0.0);
}

TEST_CASE("fk matches Blender and scipy positions for corpus files") {
  const std::filesystem::path corpus = keyanim::test::corpus_dir();
  for (const std::string name : {"assimp__01_01", "bvh11__131_01", "makehuman__tpose"}) {
    CAPTURE(name);
    std::ifstream in(std::filesystem::path(KEYANIM_TEST_DATA_DIR) / "fk" / (name + ".json"));
    REQUIRE(in.good());
    const nlohmann::json ref = nlohmann::json::parse(in);
    const std::filesystem::path bvh = corpus / ref.at("source").get<std::string>();
    if (!std::filesystem::exists(bvh)) {
      KEYANIM_SKIP_CORPUS_TEST(bvh.string());
      continue;
    }
    Motion m = keyanim::offline::read_bvh_file(bvh.string());

    const auto& nodes = ref.at("nodes");
    REQUIRE(nodes.size() == m.skeleton.joints.size());
    for (size_t j = 0; j < nodes.size(); ++j) {
      const Joint& joint = m.skeleton.joints[j];
      CHECK(nodes[j].at("parent").get<int>() == joint.parent);
      CHECK(nodes[j].at("end_site").get<bool>() == joint.end_site);
      if (!joint.end_site) CHECK(nodes[j].at("name").get<std::string>() == joint.name);
    }
    const double size = keyanim::offline::skeleton_size(m.skeleton);
    CHECK(size == doctest::Approx(ref.at("skeleton_size").get<double>()).epsilon(1e-10));

    // Blender works in float32: it agrees with scipy to < 5e-7 of the size (README.md).
    const double blender_tol = 1e-6 * size;
    const double f64_tol = 1e-9 * size;
    double worst_blender = 0.0;
    double worst_f64 = 0.0;
    const auto& frames = ref.at("frames");
    for (size_t k = 0; k < frames.size(); ++k) {
      const uint32_t f = frames[k].get<uint32_t>();
      REQUIRE(f < m.frame_count);
      std::vector<Vec3> got;
      keyanim::offline::world_positions(m.skeleton, m.frame(f), got);
      const auto& blender = ref.at("positions_blender")[k];
      const auto& f64 = ref.at("positions_f64")[k];
      REQUIRE(blender.size() == 3 * got.size());
      REQUIRE(f64.size() == 3 * got.size());
      for (size_t j = 0; j < got.size(); ++j) {
        const Vec3 b{blender[3 * j].get<double>(), blender[3 * j + 1].get<double>(),
                     blender[3 * j + 2].get<double>()};
        const Vec3 s{f64[3 * j].get<double>(), f64[3 * j + 1].get<double>(),
                     f64[3 * j + 2].get<double>()};
        worst_blender = std::max(worst_blender, distance(got[j], b));
        worst_f64 = std::max(worst_f64, distance(got[j], s));
      }
    }
    MESSAGE(name << ": largest distance to Blender " << worst_blender / size
                 << " of the skeleton size, to scipy " << worst_f64 / size);
    CHECK(worst_blender <= blender_tol);
    CHECK(worst_f64 <= f64_tol);
  }
}

TEST_CASE("fk of every corpus file is unchanged by a BVH write and read") {
  const auto files = keyanim::test::corpus_bvh_files();
  if (files.empty()) KEYANIM_SKIP_CORPUS_TEST(keyanim::test::corpus_dir().string());
  for (const auto& path : files) {
    const std::string file = path.string();
    CAPTURE(file);
    const Motion a = keyanim::offline::read_bvh_file(file);
    const std::string text = keyanim::offline::write_bvh(a);
    const Motion b = keyanim::offline::read_bvh(text, "rewritten");
    const auto pa = keyanim::offline::world_positions_all(a);
    const auto pb = keyanim::offline::world_positions_all(b);
    REQUIRE(pa.size() == pb.size());
    size_t differing = 0;
    for (size_t i = 0; i < pa.size(); ++i) differing += pa[i] != pb[i] ? 1 : 0;
    CHECK(differing == 0);
  }
}

}  // TEST_SUITE

TEST_SUITE("metrics") {

namespace {

// Hips (root, 6 channels, cols 0-5) with three children:
//   Arm   at (0,5,0), ZXY cols 6-8, End Site 3 along x (a rotation about Arm's Z swings it);
//   Head  at (0,2,0), ZXY cols 9-11, End Site of zero length (its rotation moves nothing);
//   Tip   at (1,0,0), Yrotation col 12, no children (its rotation moves nothing).
Motion metrics_motion() {
  Motion m;
  m.skeleton = skeleton_of({
      joint("Hips", -1, {0, 0, 0}, {kXp, kYp, kZp, kZr, kXr, kYr}),
      joint("Arm", 0, {0, 5, 0}, {kZr, kXr, kYr}),
      end_site(1, {3, 0, 0}),
      joint("Head", 0, {0, 2, 0}, {kZr, kXr, kYr}),
      end_site(3, {0, 0, 0}),
      joint("Tip", 0, {1, 0, 0}, {kYr}),
  });
  m.frame_count = 3;
  m.frame_time = 1.0 / 30;
  m.values.assign(3 * 13, 0.0);
  return m;
}

void set(Motion& m, uint32_t f, uint32_t c, double v) { m.values[f * 13 + c] = v; }

}  // namespace

TEST_CASE("metrics identical motions have zero error") {
  Motion a = metrics_motion();
  set(a, 1, 7, 33.0);
  const auto r = keyanim::offline::measure_error(a, a);
  CHECK(r.max_error == 0.0);
  CHECK(r.rms_error == 0.0);
  CHECK(r.shell == doctest::Approx(0.02 * 5.0));  // 2% of the rest pose box: 3 x 5 x 0
  CHECK(r.joint_max == std::vector<double>(6, 0.0));
  CHECK(r.channel_max == std::vector<double>(13, 0.0));
}

TEST_CASE("metrics hand-computed errors worst node and frame and channels (joints and End Sites only)") {
  Motion original = metrics_motion();
  Motion decoded = metrics_motion();
  for (uint32_t f = 0; f < 3; ++f) {
    set(original, f, 3, 170.0);  // Hips Z: 360 apart, the same pose and no channel error
    set(decoded, f, 3, -190.0);
  }
  set(decoded, 0, 0, 0.25);   // frame 0: Hips x moves every node by 0.25
  set(decoded, 1, 6, 10.0);   // frame 1: Arm Z 10 degrees: End Site chord 2*3*sin(5)
  set(decoded, 2, 6, 4.0);    // frame 2: Arm Z 4 degrees: chord 2*3*sin(2)
  set(decoded, 0, 10, 7.0);   // Head X: moves nothing (zero-length End Site)
  set(original, 0, 12, 179.0);  // Tip Y: 179 vs -179 differ by 2 modulo 360
  set(decoded, 0, 12, -179.0);

  const double deg = std::numbers::pi / 180.0;
  const double e1 = 2 * 3 * std::sin(5 * deg);
  const double e2 = 2 * 3 * std::sin(2 * deg);
  auto r = keyanim::offline::measure_error(original, decoded, 0.0);
  CHECK(r.max_error == doctest::Approx(e1).epsilon(1e-12));
  CHECK(r.worst_joint == 2);
  CHECK(r.worst_point == 0);
  CHECK(r.worst_frame == 1);
  CHECK(r.shell == 0.0);
  CHECK_FALSE(r.both_readings);
  const double rms = std::sqrt((6 * 0.25 * 0.25 + e1 * e1 + e2 * e2) / 18.0);
  CHECK(r.rms_error == doctest::Approx(rms).epsilon(1e-12));
  REQUIRE(r.joint_max.size() == 6);
  for (size_t j : {0, 1, 3, 4, 5}) CHECK(r.joint_max[j] == doctest::Approx(0.25).epsilon(1e-12));
  CHECK(r.joint_max[2] == doctest::Approx(e1).epsilon(1e-12));
  REQUIRE(r.channel_max.size() == 13);
  const std::vector<double> want{0.25, 0, 0, 0, 0, 0, 10, 0, 0, 0, 7, 0, 2};
  for (size_t c = 0; c < 13; ++c) {
    CAPTURE(c);
    CHECK(r.channel_max[c] == doctest::Approx(want[c]).epsilon(1e-12));
  }

  // Tip (no children at all): its rotation moves no joint or End Site.
  set(decoded, 2, 12, -12.5);
  r = keyanim::offline::measure_error(original, decoded, 0.0);
  CHECK(r.channel_max[12] == doctest::Approx(12.5).epsilon(1e-12));
  CHECK(r.max_error == doctest::Approx(e1).epsilon(1e-12));
}

TEST_CASE("metrics shell points see a rotation that moves no joint or End Site") {
  const double deg = std::numbers::pi / 180.0;
  const double d = 0.5;  // shell distance
  Motion original = metrics_motion();
  Motion decoded = metrics_motion();
  set(decoded, 1, 10, 7.0);   // frame 1: Head X 7 degrees (its End Site has zero length)
  set(decoded, 2, 12, 40.0);  // frame 2: Tip Y 40 degrees (no children at all)
  CHECK(keyanim::offline::measure_error(original, decoded, 0.0).max_error == 0.0);
  const auto r = keyanim::offline::measure_error(original, decoded, d);
  // A rotation by a about one axis moves the shell points on the other two by the chord 2 d sin(a/2).
  const double head = 2 * d * std::sin(3.5 * deg), tip = 2 * d * std::sin(20 * deg);
  CHECK(r.shell == d);
  CHECK(r.max_error == doctest::Approx(tip).epsilon(1e-12));
  CHECK(r.worst_joint == 5);
  CHECK(r.worst_frame == 2);
  CHECK((r.worst_point == 1 || r.worst_point == 3));  // Tip's x or z shell point, not y (its axis)
  CHECK(keyanim::offline::point_name(original.skeleton, 5, r.worst_point) ==
        std::string("Tip shell ") + char('x' + r.worst_point - 1));
  CHECK(r.joint_max[3] == doctest::Approx(head).epsilon(1e-12));
  CHECK(r.joint_max[4] == 0.0);  // Head's End Site: a point, no shell
  CHECK(r.joint_max[0] == 0.0);
  // The rms is over nodes and frames of each node's largest point error.
  CHECK(r.rms_error == doctest::Approx(std::sqrt((head * head + tip * tip) / 18.0)).epsilon(1e-12));
}

TEST_CASE("metrics position channels below the root are measured under both readings") {
  // Hips (Zr) -> Arm, OFFSET (0,5,0), channels Xp Yp Zp Zr with values (0,5,0): replace gives
  // the translation (0,5,0), add (0,10,0) -> End Site (3,0,0).
  Motion m;
  m.skeleton = skeleton_of({joint("Hips", -1, {0, 0, 0}, {kZr}), joint("Arm", 0, {0, 5, 0}, {kXp, kYp, kZp, kZr}),
                            end_site(1, {3, 0, 0})});
  m.frame_count = 1;
  m.frame_time = 1.0 / 30;
  m.values = {0, 0, 5, 0, 0};
  Motion decoded = m;
  decoded.values[0] = 2.0;  // Hips Z 2 degrees: each point moves by 2 |p| sin(1 degree)
  const double deg = std::numbers::pi / 180.0;
  const auto r = keyanim::offline::measure_error(m, decoded, 0.0);
  CHECK(r.both_readings);
  CHECK(r.worst_reading == keyanim::PositionReading::add);
  CHECK(r.worst_joint == 2);
  CHECK(r.max_error == doctest::Approx(2 * std::sqrt(109.0) * std::sin(deg)).epsilon(1e-12));
  CHECK(r.reading_max[size_t(keyanim::PositionReading::add)] == r.max_error);
  CHECK(r.reading_max[size_t(keyanim::PositionReading::replace)] ==
        doctest::Approx(2 * std::sqrt(34.0) * std::sin(deg)).epsilon(1e-12));
  CHECK(r.joint_max[1] == doctest::Approx(2 * 10 * std::sin(deg)).epsilon(1e-12));
  // FK itself under each reading.
  std::vector<Vec3> replaced, added;
  keyanim::offline::world_positions(m.skeleton, m.values.data(), replaced, keyanim::PositionReading::replace);
  keyanim::offline::world_positions(m.skeleton, m.values.data(), added, keyanim::PositionReading::add);
  CHECK(replaced[2] == Vec3{3, 5, 0});
  CHECK(added[2] == Vec3{3, 10, 0});
  // Position channels on a root alone: one reading (a root's OFFSET shifts both poses alike).
  Motion root_only = m;
  root_only.skeleton = skeleton_of({joint("Hips", -1, {1, 2, 3}, {kXp, kYp, kZp, kZr}), end_site(0, {3, 0, 0})});
  root_only.values = {0, 0, 0, 0};
  Motion moved = root_only;
  moved.values[3] = 2.0;
  const auto one = keyanim::offline::measure_error(root_only, moved, 0.0);
  CHECK_FALSE(one.both_readings);
  CHECK(one.max_error == doctest::Approx(2 * 3 * std::sin(deg)).epsilon(1e-12));
}

TEST_CASE("metrics modulo 360 channel comparison") {
  Motion a = metrics_motion();
  Motion b = metrics_motion();
  set(a, 0, 9, 359.0);    // Head Z: 359 vs -359 differ by 718 = 2*360 - 2
  set(b, 0, 9, -359.0);
  set(a, 1, 11, 540.0);   // Head Y: 540 vs 0 differ by 180 either way round
  set(a, 2, 10, -360.0);  // Head X: -360 vs 0 is no difference
  set(a, 2, 0, 540.0);    // Hips x is a length: no wrapping, 540
  const auto r = keyanim::offline::measure_error(a, b);
  CHECK(r.channel_max[9] == doctest::Approx(2.0).epsilon(1e-12));
  CHECK(r.channel_max[11] == doctest::Approx(180.0).epsilon(1e-12));
  CHECK(r.channel_max[10] == 0.0);
  CHECK(r.channel_max[0] == 540.0);
}

TEST_CASE("metrics: mismatched or broken motions are errors and NaN values an infinite error") {
  const double inf = std::numeric_limits<double>::infinity();
  const Motion a = metrics_motion();
  auto kind_of = [&](const Motion& b) {
    try {
      keyanim::offline::measure_error(a, b);
    } catch (const keyanim::offline::Error& e) {
      return e.kind();
    }
    FAIL("no error");
    return keyanim::offline::ErrorKind::io;
  };
  Motion fewer_frames = a;
  fewer_frames.frame_count = 2;
  fewer_frames.values.resize(2 * 13);
  CHECK(kind_of(fewer_frames) == keyanim::offline::ErrorKind::invalid_argument);

  Motion more_channels = a;
  more_channels.skeleton.joints[5].channels.push_back(kXr);
  more_channels.skeleton.assign_channel_columns();
  more_channels.values.assign(3 * 14, 0.0);
  CHECK(kind_of(more_channels) == keyanim::offline::ErrorKind::invalid_argument);

  Motion short_values = a;
  short_values.values.resize(20);
  CHECK(kind_of(short_values) == keyanim::offline::ErrorKind::invalid_argument);

  Motion nan = a;
  set(nan, 1, 6, std::numeric_limits<double>::quiet_NaN());
  const auto rn = keyanim::offline::measure_error(a, nan);
  CHECK(rn.max_error == inf);
  CHECK(rn.worst_frame == 1);
  CHECK(rn.channel_max[6] == inf);

  for (double shell : {-1.0, std::numeric_limits<double>::quiet_NaN(), inf})
    CHECK_THROWS_AS(keyanim::offline::measure_error(a, a, shell), keyanim::offline::Error);
}

}  // TEST_SUITE

TEST_CASE("metrics: an accumulator fed two frames at a time reports what one frame at a time does") {
  // add_frames is two add_frame calls to the bit, including which of equal errors is the worst
  // (the first): the position-channel motion below has equal errors on all four frames and both
  // readings; the CMU take's decoding is perturbed by a pseudo-random amount on every channel.
  Motion ties;
  ties.skeleton = skeleton_of({joint("Hips", -1, {0, 0, 0}, {kZr}), joint("Arm", 0, {0, 5, 0}, {kXp, kYp, kZp, kZr}),
                               end_site(1, {3, 0, 0})});
  ties.frame_count = 4;
  ties.values.assign(4 * 5, 0.0);
  Motion ties_decoded = ties;
  for (uint32_t f = 0; f < 4; ++f) ties_decoded.values[f * 5] = 2.0;
  Motion clip = keyanim::offline::read_bvh_file(KEYANIM_REPO_DATA_DIR "/cmu_131_03_hop.bvh");
  Motion clip_decoded = clip;
  uint32_t state = 12345;
  for (double& v : clip_decoded.values) {
    state = state * 1664525u + 1013904223u;
    v += double(state >> 8) / double(1u << 24) * 0.2 - 0.1;
  }
  for (const auto& [original, decoded] : {std::pair{&ties, &ties_decoded}, std::pair{&clip, &clip_decoded}}) {
    const size_t n_ch = original->values.size() / original->frame_count;
    const double shell = keyanim::offline::default_shell(*original);
    keyanim::offline::ErrorAccumulator one(original->skeleton, shell), two(original->skeleton, shell);
    auto row = [&](const Motion* m, uint32_t f) { return m->values.data() + f * n_ch; };
    for (uint32_t f = 0; f < original->frame_count; ++f) one.add_frame(f, row(original, f), row(decoded, f));
    uint32_t f = 0;
    for (; f + 1 < original->frame_count; f += 2)
      two.add_frames(f, {row(original, f), row(decoded, f), row(original, f + 1), row(decoded, f + 1)});
    if (f < original->frame_count) two.add_frame(f, row(original, f), row(decoded, f));
    const auto a = one.report(original->frame_count), b = two.report(original->frame_count);
    CHECK(a.max_error > 0.0);
    CHECK(a.both_readings == (original == &ties));
    keyanim::test::check_same_report(b, a);
  }
}
