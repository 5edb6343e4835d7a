// Budgets through the hierarchy: first budgets from the reach below each node, tightening of
// exactly the channels that move an over-budget node, the quantization step, and which channels
// and frames come back for refitting. Expected values are worked out by hand.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>

#include "offline/encode/budget.h"

using namespace keyanim;
using namespace keyanim::offline;

namespace {

constexpr ChannelType kXp = ChannelType::x_position, kYp = ChannelType::y_position, kZp = ChannelType::z_position;
constexpr ChannelType kXr = ChannelType::x_rotation, kYr = ChannelType::y_rotation, kZr = ChannelType::z_rotation;

// Hips (position + rotation) -> Spine (rotation, 3 up) -> End Site (4 up); Hips -> Leg
// (rotation, 5 down) -> End Site (0). Channels: Hips 0-5, Spine 6-8, Leg 9-11.
Motion tree(uint32_t frames) {
  Motion m;
  m.skeleton.joints = {
      {"Hips", -1, {0, 0, 0}, {kXp, kYp, kZp, kZr, kXr, kYr}},
      {"Spine", 0, {0, 3, 0}, {kZr, kXr, kYr}},
      {"", 1, {0, 4, 0}, {}, true},
      {"Leg", 0, {0, -5, 0}, {kZr, kXr, kYr}},
      {"", 3, {0, 0, 0}, {}, true},
  };
  m.skeleton.assign_channel_columns();
  m.frame_count = frames;
  m.frame_time = 1.0 / 30.0;
  m.values.assign(size_t(frames) * 12, 0.0);
  return m;
}

}  // namespace

TEST_SUITE("budget") {
  TEST_CASE("reach below is the longest chain of translations under each node, to a point or a shell point") {
    Motion m = tree(3);
    m.values[2 * 12 + 1] = 7.0;  // Hips' Yposition at frame 2: its own translation, not below it
    std::vector<double> down = reach_below(m, 0.0);
    CHECK(down[0] == 7.0);  // Spine 3 + End 4 beats Leg 5 + End 0
    CHECK(down[1] == 4.0);
    CHECK(down[2] == 0.0);
    CHECK(down[3] == 0.0);
    down = reach_below(m, 1.5);  // shell points 1.5 from every joint
    CHECK(down[0] == 7.0);       // Spine's End Site (7) beats Spine's shell (3 + 1.5) and Leg's (5 + 1.5)
    CHECK(down[1] == 4.0);
    CHECK(down[2] == 0.0);
    CHECK(down[3] == 1.5);  // its own shell points
    down = reach_below(m, 3.0);
    CHECK(down[0] == 8.0);  // Leg's shell: 5 + 3
    CHECK(down[1] == 4.0);
  }

  TEST_CASE("reach below takes the longer of both readings of a position channel below the root") {
    Motion m = tree(2);
    m.skeleton.joints[1].channels.push_back(kYp);  // Spine: Yposition, OFFSET y 3
    m.skeleton.assign_channel_columns();
    m.values.assign(2 * 13, 0.0);
    m.values[1 * 13 + 9] = 2.0;  // frame 1: Spine's Yposition 2 -> replace 2, add 5
    const std::vector<double> down = reach_below(m, 0.0);
    CHECK(down[0] == 9.0);  // add: 3 + 2, then the End Site's 4
  }

  TEST_CASE("first budgets: the tolerance for translations, its angle at the reach for rotations") {
    const Motion m = tree(2);
    const double tol = 0.1, shell = 0.5, deg = 180.0 / std::numbers::pi;
    const std::vector<double> base = base_tolerances(m, tol, shell);
    REQUIRE(base.size() == 12);
    for (int c = 0; c < 3; ++c) CHECK(base[c] == tol);
    for (int c = 3; c < 6; ++c) CHECK(base[c] == doctest::Approx(tol / 7.0 * deg));
    for (int c = 6; c < 9; ++c) CHECK(base[c] == doctest::Approx(tol / 4.0 * deg));
    for (int c = 9; c < 12; ++c) CHECK(base[c] == doctest::Approx(tol / shell * deg));  // nothing below: the shell
    // Without a shell, a rotation that moves no measured point gets the largest budget.
    const std::vector<double> no_shell = base_tolerances(m, tol, 0.0);
    for (int c = 9; c < 12; ++c) CHECK(no_shell[c] == 180.0);
  }

  TEST_CASE("an over node tightens exactly the channels that move it, by the smallest ratio") {
    const Motion m = tree(4);
    Budgets b(m.skeleton, std::vector<double>(12, 1.0), 4);
    CHECK(b.take_dirty().size() == 12);  // everything is fitted first
    // Frame 2: Spine's End Site over (ratio 0.5) and Spine itself over (ratio 0.8).
    b.tighten(2, {{2, 0.5}, {1, 0.8}});
    for (uint32_t c : {0u, 1u, 2u, 3u, 4u, 5u}) CHECK(b.tolerance(c).at(2) == 0.5);  // Hips moves both
    for (uint32_t c : {6u, 7u, 8u}) CHECK(b.tolerance(c).at(2) == 0.5);  // Spine's rotation moves its End Site only
    for (uint32_t c : {9u, 10u, 11u}) CHECK(b.tolerance(c).at(2) == 1.0);  // Leg moves neither
    for (uint32_t c = 0; c < 12; ++c) CHECK(b.tolerance(c).at(1) == 1.0);   // other frames untouched
    // Frame 3: Spine over alone: its own rotation does not move it; Hips' channels do.
    b.tighten(3, {{1, 0.25}});
    CHECK(b.tolerance(6).at(3) == 1.0);
    CHECK(b.tolerance(0).at(3) == 0.25);
    CHECK(b.tolerance(3).at(3) == 0.25);
    const std::vector<uint32_t> dirty = b.take_dirty();
    CHECK(dirty == std::vector<uint32_t>{0, 1, 2, 3, 4, 5, 6, 7, 8});
    std::vector<uint32_t> frames;
    b.changed_frames(0, frames);
    CHECK(frames == std::vector<uint32_t>{2, 3});
    b.changed_frames(6, frames);
    CHECK(frames == std::vector<uint32_t>{2});
    CHECK(b.take_dirty().empty());
    // A later tightening starts a new list of changed frames for that channel.
    b.tighten(1, {{4, 0.9}});  // Leg's End Site: Leg's rotations and Hips
    CHECK(b.take_dirty() == std::vector<uint32_t>{0, 1, 2, 3, 4, 5, 9, 10, 11});
    b.changed_frames(0, frames);
    CHECK(frames == std::vector<uint32_t>{1});
    CHECK(b.tolerance(9).at(1) == doctest::Approx(0.9));
    // A shell point of Leg over: its own rotation moves it, with Hips' channels.
    b.tighten(0, {{3, 0.6, true}});
    CHECK(b.take_dirty() == std::vector<uint32_t>{0, 1, 2, 3, 4, 5, 9, 10, 11});
    CHECK(b.tolerance(9).at(0) == doctest::Approx(0.6));
    CHECK(b.tolerance(6).at(0) == 1.0);
  }

  TEST_CASE("tolerances are stored rounded down, never looser than computed") {
    const Motion m = tree(1);
    Budgets b(m.skeleton, std::vector<double>(12, 0.3), 1);
    const double ratio = 0.7123456789;
    b.tighten(0, {{0, ratio}});
    const double t = b.tolerance(0).at(0);
    CHECK(t <= 0.3 * ratio);
    CHECK(t == doctest::Approx(0.3 * ratio).epsilon(1e-7));
    CHECK(b.min_tolerance(0) == t);
    CHECK(b.min_tolerance(9) == 0.3);
  }

  TEST_CASE("the step is the largest power of 2^(1/4) within the fraction of the smallest tolerance, or the one held") {
    const Motion m = tree(3);
    Budgets b(m.skeleton, std::vector<double>(12, 1.0), 3);
    // Limit 1.5: 2^(2/4) = 1.414 (2^(3/4) = 1.682 is over it).
    CHECK(b.step(0, 1.5) == std::sqrt(2.0));
    CHECK(b.step(0, 2.0) == 2.0);  // a power of it: itself
    // Smallest tolerance of Hips' channels 0.3, limit 0.45: 2^(-5/4) = 0.4204 (2^(-4/4) = 0.5 is over).
    b.tighten(1, {{0, 0.3}});
    CHECK(b.step(0, 1.5) == doctest::Approx(std::exp2(-5.0 / 4.0)).epsilon(1e-15));
    CHECK(b.step(0, 1.5) <= 0.45);
    CHECK(b.step(9, 1.5) == std::sqrt(2.0));  // untouched
    // Held while the step would stay above half of it; otherwise the step follows the tolerance.
    CHECK(b.step(0, 1.5, 0.8) == 0.8);  // 0.4204 > 0.4
    CHECK(b.step(0, 1.5, 0.84) == 0.84);
    CHECK(b.step(0, 1.5, 0.85) == doctest::Approx(std::exp2(-5.0 / 4.0)).epsilon(1e-15));  // 0.4204 < 0.425
    CHECK(b.step(0, 1.5, std::sqrt(2.0)) == doctest::Approx(std::exp2(-5.0 / 4.0)).epsilon(1e-15));
    CHECK(b.step(0, 1.5, 0.3) == doctest::Approx(std::exp2(-5.0 / 4.0)).epsilon(1e-15));  // never finer than needed
  }
}
