// The encoder's input: what it refuses and why, and each channel as the fitter sees it.
#include <doctest/doctest.h>

#include <cmath>

#include "keyanim/offline/encode.h"
#include "offline/encode/rotations.h"
#include "offline/encode/signals.h"

using namespace keyanim;
using namespace keyanim::offline;

namespace {

Motion two_nodes(uint32_t frames) {
  Motion m;
  m.skeleton.joints = {{"Root", -1, {0, 0, 0}, {ChannelType::x_position, ChannelType::z_rotation}},
                       {"", 0, {0, 2, 0}, {}, true}};
  m.skeleton.assign_channel_columns();
  m.frame_count = frames;
  m.frame_time = 0.1;
  m.values.assign(size_t(frames) * 2, 0.0);
  return m;
}

}  // namespace

TEST_SUITE("signals") {
  TEST_CASE("check_motion accepts a plain motion and names what it refuses") {
    // The kind and message check_motion throws, or "" for none.
    auto refusal = [](const Motion& m, unsigned threads) -> std::string {
      try {
        check_motion(m, threads);
      } catch (const Error& e) {
        return std::string(error_kind_string(e.kind())) + ": " + e.message();
      }
      return "";
    };
    Motion m = two_nodes(300);
    for (unsigned threads : {1u, 2u}) CHECK(refusal(m, threads).empty());
    m.values.pop_back();
    CHECK(refusal(m, 1).find("invalid_argument: ") == 0);
    CHECK(refusal(m, 1).find("expected frames x channels") != std::string::npos);
    m = two_nodes(300);
    m.values[7] = 2e37;
    CHECK(refusal(m, 1) ==
          "malformed: channel 1 (Root Zrotation) of frame 3 is 2e+37, beyond what binary32 keys can hold (|v| > 1e37)");
    // NaN and infinities are said as what they are, not as too large.
    m = two_nodes(300);
    m.values[7] = NAN;
    CHECK(refusal(m, 1) == "malformed: channel 1 (Root Zrotation) of frame 3 is NaN (not a number): a key cannot hold it");
    m.values[7] = 0.0;
    m.values[8] = -INFINITY;
    CHECK(refusal(m, 1) == "malformed: channel 0 (Root Xposition) of frame 4 is -inf: a key cannot hold it");
    // Values in range whose sum is not: a position beyond 1e37, found by FK at frame 299.
    m = two_nodes(300);
    m.skeleton.joints[1].offset = {9e36, 0, 0};
    m.values[299 * 2] = 9e36;
    for (unsigned threads : {1u, 2u}) CHECK(refusal(m, threads).find("overflow") != std::string::npos);
    // Reaches that could add up beyond it but do not at any frame: accepted (FK says so, not the bound).
    m.values[299 * 2] = 0.0;
    m.values[5 * 2] = -9e36;
    for (unsigned threads : {1u, 2u}) CHECK(refusal(m, threads).empty());
    m.values[5 * 2 + 1] = 180.0;  // the same translation, turned to point the End Site back: 1.8e37 away
    for (unsigned threads : {1u, 2u}) CHECK(refusal(m, threads).find("overflow") != std::string::npos);
  }

  TEST_CASE("channel layout and signals: a column, unwrapped when it is an angle") {
    Motion m = two_nodes(4);
    const double x[4] = {1.0, 2.0, 3.0, 4.0}, z[4] = {170.0, -170.0, -150.0, 179.0};
    for (uint32_t f = 0; f < 4; ++f) m.values[f * 2] = x[f], m.values[f * 2 + 1] = z[f];
    const ChannelLayout layout = channel_layout(m.skeleton);
    CHECK(layout.node == std::vector<uint32_t>{0, 0});
    CHECK(layout.rotation == std::vector<uint8_t>{0, 1});
    std::vector<double> y;
    channel_signal(m, layout, 0, y);
    CHECK(y == std::vector<double>{1.0, 2.0, 3.0, 4.0});
    channel_signal(m, layout, 1, y);
    REQUIRE(y.size() == 4);
    CHECK(y[0] == 170.0);
    CHECK(y[1] == doctest::Approx(190.0));
    CHECK(y[2] == doctest::Approx(210.0));
    CHECK(y[3] == doctest::Approx(179.0));
  }

  TEST_CASE("signals held for the rounds are channel_signal's, held or not") {
    // A motion whose angle wraps and whose two channels differ at every frame: a held copy
    // read at the wrong column or frame, or not unwrapped, gives other values.
    Motion m = two_nodes(200);
    for (uint32_t f = 0; f < 200; ++f) m.values[f * 2] = 0.5 * f, m.values[f * 2 + 1] = std::fmod(7.0 * f, 360.0) - 180.0;
    const ChannelLayout layout = channel_layout(m.skeleton);
    for (const size_t budget : {size_t(1) << 20, size_t(100)}) {  // held; over the budget: read again
      CAPTURE(budget);
      for (int clip = 0; clip < 2; ++clip) {  // the second takes the first one's storage
        const Signals signals(m, layout, budget, 2);
        for (uint32_t c = 0; c < 2; ++c) {
          std::vector<double> want, got;
          channel_signal(m, layout, c, want);
          signals.get(m, layout, c, got);
          CHECK(got == want);
        }
      }
    }
  }

  TEST_CASE("a quaternion node's signals are the same held or read again, w included") {
    // One node turning about all three axes; its w rebuilt from x, y, z and quat_signals' own
    // w differ in the last bit at some frames, which changed a clip's bytes when its signals
    // outgrew the budget.
    Motion m;
    m.skeleton.joints = {{"Root", -1, {0, 0, 0}, {ChannelType::z_rotation, ChannelType::x_rotation, ChannelType::y_rotation}},
                         {"", 0, {0, 2, 0}, {}, true}};
    m.skeleton.assign_channel_columns();
    m.frame_count = 500;
    m.frame_time = 0.1;
    for (uint32_t f = 0; f < m.frame_count; ++f)
      for (double a : {40.0 * std::sin(0.05 * f), 30.0 * std::cos(0.031 * f), 0.137 * f - 20.0}) m.values.push_back(a);
    const ChannelLayout layout = channel_layout(m.skeleton, {QuatNode{0, {0, 0, 0}}});
    std::array<std::vector<double>, 4> held, again;
    Signals(m, layout, size_t(1) << 20, 1).get_quat(m, layout, 0, held);
    Signals(m, layout, 0, 1).get_quat(m, layout, 0, again);
    for (size_t k = 0; k < 4; ++k) CHECK(held[k] == again[k]);
    std::array<std::vector<double>, 4> own;  // the node's rotation itself, w within rounding
    quat_signals(m, layout.quats[0], own);
    for (uint32_t f = 0; f < m.frame_count; ++f) CHECK(again[3][f] == doctest::Approx(own[3][f]).epsilon(1e-12));
  }

  TEST_CASE("unwrapping takes the shorter way at exactly 180 degrees as round() does") {
    std::vector<double> y{0.0, 180.0, 359.0, -1.0};
    unwrap_degrees(y);
    // +180 rounds away from zero: -180; then +179; then -360 wraps to 0 (step 0).
    CHECK(y == std::vector<double>{0.0, 0.0 + 180.0 - 360.0, -180.0 + 179.0, -1.0});
  }

  TEST_CASE("reference size falls back to the swept box of a skeleton with no extent") {
    Motion m = two_nodes(3);
    CHECK(reference_size(m) == 2.0);  // the rest pose: the End Site 2 above the root
    m.skeleton.joints.pop_back();
    m.values = {0.0, 0.0, 5.0, 0.0, -1.0, 0.0};  // the lone root moves from x -1 to 5
    CHECK(reference_size(m) == 6.0);
  }
}
