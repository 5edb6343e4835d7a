// BVH reader and writer. Expected structures and values below were written by hand from the
// fixture files in tests/data/bvh/ (see the README there); error positions were counted by hand
// and checked with grep -n.
#include <doctest/doctest.h>

#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "keyanim/offline/bvh.h"
#include "motion_compare.h"

using keyanim::ChannelType;
using keyanim::Joint;
using keyanim::offline::Error;
using keyanim::offline::ErrorKind;
using keyanim::offline::BvhReadOptions;
using keyanim::offline::Motion;
using keyanim::offline::read_bvh;
using keyanim::offline::read_bvh_file;
using keyanim::offline::write_bvh;

namespace {

constexpr ChannelType Xp = ChannelType::x_position;
constexpr ChannelType Yp = ChannelType::y_position;
constexpr ChannelType Zp = ChannelType::z_position;
constexpr ChannelType Xr = ChannelType::x_rotation;
constexpr ChannelType Yr = ChannelType::y_rotation;
constexpr ChannelType Zr = ChannelType::z_rotation;

std::string fixture(const std::string& name) { return std::string(KEYANIM_TEST_DATA_DIR) + "/bvh/" + name; }

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

Motion read_good(const std::string& name, std::vector<std::string>* warnings = nullptr) {
  return read_bvh_file(fixture(name), warnings);
}

// The error reading `text` throws (the test fails if it does not).
Error read_bad_text(std::string_view text, const BvhReadOptions& options = {}) {
  try {
    read_bvh(text, "text.bvh", nullptr, options);
  } catch (const Error& e) {
    return e;
  }
  FAIL("read_bvh accepted the text");
  return Error(ErrorKind::invalid_argument, "");
}

Motion read_good_text(std::string_view text, std::vector<std::string>* warnings = nullptr) {
  return read_bvh(text, "text.bvh", warnings);
}

void check_joint(const Joint& j, const std::string& name, int parent, std::array<double, 3> offset,
                 std::vector<ChannelType> channels, bool end_site, uint32_t first_channel) {
  INFO("joint '", name, "'");
  CHECK(j.name == name);
  CHECK(j.parent == parent);
  CHECK(j.offset == offset);
  CHECK(j.channels == channels);
  CHECK(j.end_site == end_site);
  CHECK(j.first_channel == first_channel);
}

void check_error(const Error& e, uint32_t line, uint32_t column, const std::string& part) {
  INFO(e.what());
  CHECK(e.line() == line);
  CHECK(e.column() == column);
  CHECK(e.message().find(part) != std::string::npos);
  CHECK(e.section().empty());
}

// The skeleton of zero_frames.bvh and one_frame.bvh.
void check_hips_spine(const Motion& m) {
  REQUIRE(m.skeleton.joints.size() == 3);
  check_joint(m.skeleton.joints[0], "Hips", -1, {1.5, 90, -2}, {Xp, Yp, Zp, Zr, Xr, Yr}, false, 0);
  check_joint(m.skeleton.joints[1], "Spine", 0, {0, 10.25, 0}, {Zr, Xr, Yr}, false, 6);
  check_joint(m.skeleton.joints[2], "", 1, {0, 5, 0}, {}, true, 9);
  CHECK(m.channel_count() == 9);
}

// The small 3-channel skeleton shared by the frame-count and value fixtures.
constexpr const char* kSmallHead =
    "HIERARCHY\nROOT Root\n{\n\tOFFSET 0 0 0\n\tCHANNELS 3 Xposition Yposition Zposition\n"
    "\tEnd Site\n\t{\n\t\tOFFSET 0 1 0\n\t}\n}\nMOTION\n";
// Four lines of hierarchy prefix (the ROOT block is still open), for syntax error cases.
constexpr const char* kHead = "HIERARCHY\nROOT A\n{\n\tOFFSET 0 0 0\n";

const std::vector<std::string> kGoodFixtures = {
    "zero_frames.bvh",          "one_frame.bvh",
    "crlf.bvh",                 "lone_cr.bvh",
    "tabs.bvh",                 "mixed_rotation_orders.bvh",
    "six_channels_all_joints.bvh", "names_with_spaces_colons.bvh",
    "multi_root.bvh",           "frames_more_lines.bvh",
    "no_end_site.bvh"};

}  // namespace

TEST_SUITE("bvh") {

TEST_CASE("zero_frames.bvh is a pose-only file") {
  const Motion m = read_good("zero_frames.bvh");
  check_hips_spine(m);
  CHECK(m.frame_count == 0);
  CHECK(m.values.empty());
  CHECK(m.frame_time == 0.0333333);
}

TEST_CASE("one_frame.bvh has one frame") {
  const Motion m = read_good("one_frame.bvh");
  check_hips_spine(m);
  CHECK(m.frame_count == 1);
  CHECK(m.frame_time == 0.0083333);
  CHECK(m.values == std::vector<double>{1.5, 90.25, -2, 10, -20, 30.5, 0.125, -0.5, 45});
}

TEST_CASE("crlf.bvh and lone_cr.bvh read like LF") {
  for (const char* name : {"crlf.bvh", "lone_cr.bvh"}) {
    INFO(name);
    const Motion m = read_good(name);
    REQUIRE(m.skeleton.joints.size() == 3);
    check_joint(m.skeleton.joints[0], "Root", -1, {0, 0, 0}, {Xp, Yp, Zp}, false, 0);
    check_joint(m.skeleton.joints[1], "Arm", 0, {1, 0, 0}, {Zr}, false, 3);
    check_joint(m.skeleton.joints[2], "", 1, {2, 0, 0}, {}, true, 4);
    CHECK(m.frame_count == 2);
    CHECK(m.frame_time == 0.5);
    if (std::string(name) == "crlf.bvh") CHECK(m.values == std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8});
    else CHECK(m.values == std::vector<double>{1, 2, 3, 4, -1, -2, -3, -4});
  }
}

TEST_CASE("the CR fixtures are byte-exact") {
  // Guards against a checkout that converted line endings (tests/data/.gitattributes says -text).
  const std::string crlf = slurp(fixture("crlf.bvh"));
  const std::string cr = slurp(fixture("lone_cr.bvh"));
  CHECK(crlf.substr(0, 11) == "HIERARCHY\r\n");
  CHECK(cr.substr(0, 10) == "HIERARCHY\r");
  CHECK(cr.find('\n') == std::string::npos);
}

TEST_CASE("tabs.bvh separates everything with tabs") {
  const Motion m = read_good("tabs.bvh");
  REQUIRE(m.skeleton.joints.size() == 3);
  check_joint(m.skeleton.joints[0], "Pelvis", -1, {0, 0, 0}, {Xp, Yp, Zp, Zr, Yr, Xr}, false, 0);
  check_joint(m.skeleton.joints[1], "Leg", 0, {0.5, -4, 0}, {Zr, Yr, Xr}, false, 6);
  check_joint(m.skeleton.joints[2], "", 1, {0, -3.5, 0}, {}, true, 9);
  CHECK(m.frame_count == 2);
  CHECK(m.frame_time == 0.0083333);
  CHECK(m.values == std::vector<double>{0.1, 0.2, 0.3, 1, 2, 3, 4, 5, 6, -0.1, -0.2, -0.3, -1, -2, -3, -4, -5, -6});
}

TEST_CASE("mixed_rotation_orders.bvh keeps each joint's order") {
  const Motion m = read_good("mixed_rotation_orders.bvh");
  const auto& j = m.skeleton.joints;
  REQUIRE(j.size() == 7);
  check_joint(j[0], "Hips", -1, {0, 0, 0}, {Xp, Yp, Zp, Zr, Yr, Xr}, false, 0);
  check_joint(j[1], "Chest", 0, {0, 5, 0}, {Zr, Xr, Yr}, false, 6);
  check_joint(j[2], "Neck", 1, {0, 5, 0}, {Yr, Xr, Zr}, false, 9);
  check_joint(j[3], "", 2, {0, 2, 0}, {}, true, 12);
  check_joint(j[4], "Leg", 0, {1, -1, 0}, {Xr, Yr, Zr}, false, 12);
  check_joint(j[5], "Foot", 4, {0, -4, 0}, {Yr, Xr}, false, 15);
  check_joint(j[6], "", 5, {0, 0, 1}, {}, true, 17);
  CHECK(m.channel_count() == 17);
  CHECK(m.frame_count == 2);
  CHECK(m.frame_time == 0.033333);
  CHECK(m.values == std::vector<double>{0, 1, 2, 10, 20, 30, 11, 21, 31, 12, 22, 32, 13, 23, 33, 14, 24,
                                        0, 1, 2, -10, -20, -30, -11, -21, -31, -12, -22, -32, -13, -23, -33, -14, -24});
  CHECK(m.value(1, 16) == -24);
}

TEST_CASE("six_channels_all_joints.bvh keeps positions on every joint in any order") {
  const Motion m = read_good("six_channels_all_joints.bvh");
  const auto& j = m.skeleton.joints;
  REQUIRE(j.size() == 4);
  check_joint(j[0], "joint_Root", -1, {0, 90, 0}, {Xp, Yp, Zp, Zr, Xr, Yr}, false, 0);
  check_joint(j[1], "Spine", 0, {0, 10, 0}, {Zr, Xr, Yr, Xp, Yp, Zp}, false, 6);
  check_joint(j[2], "Head", 1, {0, 20, 0}, {Xp, Zr, Yp, Xr, Zp, Yr}, false, 12);
  check_joint(j[3], "", 2, {0, 8, 0}, {}, true, 18);
  CHECK(m.frame_count == 2);
  CHECK(m.values == std::vector<double>{0.5, 90.5, -1.25, 10.1, 20.2, 30.3, 1.1, 2.2, 3.3, 0, 10, 0, 0.01, 4.4, 20,
                                        5.5, 0, 6.6, -0.5, -90.5, 1.25, -10.1, -20.2, -30.3, -1.1, -2.2, -3.3, -0.0,
                                        -10, -0.0, -0.01, -4.4, -20, -5.5, -0.0, -6.6});
  CHECK(std::signbit(m.value(1, 9)));  // "-0" stays negative zero
}

TEST_CASE("names_with_spaces_colons.bvh keeps names exactly") {
  const Motion m = read_good("names_with_spaces_colons.bvh");
  const auto& j = m.skeleton.joints;
  REQUIRE(j.size() == 6);
  check_joint(j[0], "mixamorig:Hips", -1, {0, 0, 0}, {Xp, Yp, Zp}, false, 0);
  check_joint(j[1], "Bip01 Neck", 0, {0, 1, 0}, {Yr}, false, 3);
  check_joint(j[2], "Model.Left Arm", 1, {1, 0, 0}, {Zr}, false, 4);  // trailing " \t " trimmed
  check_joint(j[3], "LeftHandEnd", 2, {1, 0, 0}, {}, true, 5);         // name after End Site
  check_joint(j[4], "Bip01  R:Hand.001", 0, {-1, 0, 0}, {Xr}, false, 5);  // two spaces kept
  check_joint(j[5], "", 4, {-1, 0, 0}, {}, true, 6);
  CHECK(m.values == std::vector<double>{0, 0, 0, 1, 2, 3});
}

TEST_CASE("multi_root.bvh is a forest") {
  const Motion m = read_good("multi_root.bvh");
  const auto& j = m.skeleton.joints;
  REQUIRE(j.size() == 5);
  check_joint(j[0], "Body", -1, {0, 0, 0}, {Xp, Yp, Zp}, false, 0);
  check_joint(j[1], "Head", 0, {0, 1, 0}, {Xr}, false, 3);
  check_joint(j[2], "", 1, {0, 1, 0}, {}, true, 4);
  check_joint(j[3], "Prop", -1, {5, 0, 0}, {Xp, Yp, Zp, Yr, Xr, Zr}, false, 4);
  check_joint(j[4], "", 3, {0, 0, 1}, {}, true, 10);
  CHECK(m.frame_count == 2);
  CHECK(m.frame_time == 0.05);
  CHECK(m.values == std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20});
}

TEST_CASE("no_end_site.bvh has childless joints and a joint with zero channels") {
  const Motion m = read_good("no_end_site.bvh");
  const auto& j = m.skeleton.joints;
  REQUIRE(j.size() == 3);
  check_joint(j[0], "Hips", -1, {0, 0, 0}, {Zr, Yr, Xr}, false, 0);
  check_joint(j[1], "Leaf", 0, {0, 3, 0}, {Zr, Yr, Xr}, false, 3);
  check_joint(j[2], "Other", 0, {1, 0, 0}, {}, false, 6);
  CHECK(m.values == std::vector<double>{1, 2, 3, 4, 5, 6});
}

TEST_CASE("frames_more_lines.bvh keeps every line and warns") {
  std::vector<std::string> warnings;
  const Motion m = read_good("frames_more_lines.bvh", &warnings);
  CHECK(m.frame_count == 3);
  CHECK(m.values == std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9});
  REQUIRE(warnings.size() == 1);
  INFO(warnings[0]);
  CHECK(warnings[0].find("frames_more_lines.bvh:12:9:") != std::string::npos);
  CHECK(warnings[0].find("declares 2 frames, but 3 motion lines") != std::string::npos);
}

TEST_CASE("bad fixtures report the exact place") {
  struct Case {
    const char* file;
    uint32_t line, column;
    const char* message;
  };
  const Case cases[] = {
      {"frames_fewer_lines.bvh", 12, 9, "expected 4 motion lines (Frames: 4), found 3"},
      {"truncated_motion_line.bvh", 15, 4, "expected 3 values on this motion line, found 2 (end of file)"},
      {"non_numeric.bvh", 15, 3, "expected a number, found '0.0-7.5'"},
      {"nan_value.bvh", 14, 3, "expected a finite number, found 'nan'"},
      {"inf_value.bvh", 15, 5, "expected a finite number, found '-inf'"},
      {"too_many_values.bvh", 15, 7, "expected end of line after 3 values, found '7'"},
      {"missing_brace.bvh", 15, 1, "expected JOINT, End Site or '}', found 'MOTION'"},
  };
  for (const Case& c : cases) {
    INFO(c.file);
    try {
      read_bvh_file(fixture(c.file));
      FAIL("accepted");
    } catch (const Error& e) {
      CHECK(e.file() == fixture(c.file));
      CHECK(e.kind() == ErrorKind::malformed);
      check_error(e, c.line, c.column, c.message);
      CHECK(std::string(e.what()) == fixture(c.file) + ":" + std::to_string(c.line) + ":" + std::to_string(c.column) +
                                         ": " + e.message());
    }
  }
}

TEST_CASE("keywords are case-insensitive") {
  const Motion m = read_good_text(
      "hierarchy\nroot A\n{\n offset 1 2 3\n channels 2 XPOSITION zRotation\n end site\n {\n  Offset 0 0 1\n }\n}\n"
      "motion\nframes: 1\nframe time: 0.5\n7 8\n");
  REQUIRE(m.skeleton.joints.size() == 2);
  check_joint(m.skeleton.joints[0], "A", -1, {1, 2, 3}, {Xp, Zr}, false, 0);
  check_joint(m.skeleton.joints[1], "", 0, {0, 0, 1}, {}, true, 2);
  CHECK(m.values == std::vector<double>{7, 8});
}

TEST_CASE("BOM, blank lines anywhere and trailing blank lines") {
  const Motion m = read_good_text(
      "\xEF\xBB\xBF\n\nHIERARCHY\n\nROOT A\n\n{\n\n\tOFFSET 0 0 0\n  \t \n\tCHANNELS 1 Xposition\n\n}\n\nMOTION\n\n"
      "Frames: 2\n\nFrame Time: 0.25\n\n1\n   \n\n2  \n\n\n");
  CHECK(m.frame_count == 2);
  CHECK(m.values == std::vector<double>{1, 2});
  // Columns on the first line count from after the BOM.
  check_error(read_bad_text("\xEF\xBB\xBFHIERARCH\n"), 1, 1, "expected HIERARCHY, found 'HIERARCH'");
}

TEST_CASE("line numbers count LF CRLF and lone CR alike") {
  check_error(read_bad_text("HIERARCHY\r\nROOT A\r{\n\tOFFSET 0 0 x\n"), 4, 13, "expected a number, found 'x'");
  check_error(read_bad_text("HIERARCHY\r\rROOT A\r\n\r\n{\r\tOFFSET 0 0 0\r\tCHANNELS 1 Xposition\r}\rMOTION\r"
                            "Frames: 1\rFrame Time: 1\r\r1 2\r"),
              13, 3, "expected end of line after 1 values, found '2'");
}

TEST_CASE("number forms: plus sign, leading dot, exponents, underflow") {
  const Motion m = read_good_text(std::string(kHead) +
                                  "\tCHANNELS 6 Xposition Yposition Zposition Xrotation Yrotation Zrotation\n}\n"
                                  "MOTION\nFrames: 1\nFrame Time: +.0083333\n"
                                  "+1.5 .25 -.5 4.0020632E-7 1e-400 -1e-400\n");
  CHECK(m.frame_time == 0.0083333);
  REQUIRE(m.values.size() == 6);
  CHECK(m.values[0] == 1.5);
  CHECK(m.values[1] == 0.25);
  CHECK(m.values[2] == -0.5);
  CHECK(m.values[3] == 4.0020632E-7);
  CHECK(m.values[4] == 0.0);  // below the smallest subnormal: rounds to zero, as strtod does
  CHECK_FALSE(std::signbit(m.values[4]));
  CHECK(std::signbit(m.values[5]));

  const std::string frame_head = std::string(kHead) + "\tCHANNELS 2 Xposition Yposition\n}\nMOTION\nFrames: 1\nFrame Time: 1\n";
  check_error(read_bad_text(frame_head + "1 1e400\n"), 10, 3, "expected a finite number, found '1e400'");
  check_error(read_bad_text(frame_head + "1 +-2\n"), 10, 3, "expected a number, found '+-2'");
  check_error(read_bad_text(frame_head + "1 ++2\n"), 10, 3, "expected a number, found '++2'");
  check_error(read_bad_text(frame_head + "1 1e\n"), 10, 3, "expected a number, found '1e'");
  check_error(read_bad_text(frame_head + "1 0x10\n"), 10, 3, "expected a number, found '0x10'");
  check_error(read_bad_text(frame_head + "1 INF\n"), 10, 3, "expected a finite number, found 'INF'");
  check_error(read_bad_text(frame_head + "1 -NaN\n"), 10, 3, "expected a finite number, found '-NaN'");
  check_error(read_bad_text(std::string(kHead) + "\tCHANNELS 0\n\tJOINT B\n\t{\n\t\tOFFSET 0 nan 0\n"), 8, 12,
              "expected a finite number, found 'nan'");
}

TEST_CASE("the values of a frame must be on one line") {
  const std::string head = std::string(kSmallHead) + "Frames: 1\nFrame Time: 1\n";
  check_error(read_bad_text(head + "1 2\n3\n"), 14, 4, "expected 3 values on this motion line, found 2 (end of line)");
}

TEST_CASE("truncated headers report end of file") {
  check_error(read_bad_text("HIERARCHY\nROOT A\n{\n\tOFFSET 0 0"), 4, 12, "expected a number, found end of file");
  check_error(read_bad_text("HIERARCHY\nROOT A\n{\n\tOFFSET 0 0 0\n"), 5, 1,
              "expected CHANNELS, JOINT, End Site or '}', found end of file");
  check_error(read_bad_text(std::string(kSmallHead) + "Frames: 1\nFrame"), 13, 1, "expected 'Frame Time:'");
  check_error(read_bad_text(std::string(kSmallHead) + "Frames: 1\nFrame Time:"), 13, 12,
              "expected a frame time, found end of file");
  check_error(read_bad_text(""), 1, 1, "expected HIERARCHY, found end of file");
}

TEST_CASE("syntax errors in the hierarchy") {
  const std::string head = kHead;
  check_error(read_bad_text("HIERARCHYX\n"), 1, 1, "expected HIERARCHY, found 'HIERARCHYX'");
  check_error(read_bad_text("HIERARCHY\nMOTION\n"), 2, 1, "expected ROOT, found 'MOTION'");
  check_error(read_bad_text("HIERARCHY\nROOT A\n\tOFFSET 0 0 0\n"), 3, 2, "expected '{', found 'OFFSET'");
  check_error(read_bad_text("HIERARCHY\nROOT A\n{\n\tCHANNELS 0\n\tJOINT B\n"), 5, 2, "expected OFFSET, found 'JOINT'");
  check_error(read_bad_text(head + "\tCHANNELS 7 Xposition\n"), 5, 11, "expected a channel count from 0 to 6, found '7'");
  check_error(read_bad_text(head + "\tCHANNELS two\n"), 5, 11, "expected a channel count from 0 to 6, found 'two'");
  check_error(read_bad_text(head + "\tCHANNELS 2 Xposition Wrotation\n"), 5, 23, "expected a channel name");
  check_error(read_bad_text(head + "\tCHANNELS 2 Xrotation Xrotation\n"), 5, 23,
              "expected each channel once, found 'Xrotation' twice");
  check_error(read_bad_text(head + "\tCHANNELS 2 Xrotation\n\tJOINT B\n"), 6, 2,
              "expected a channel name (Xposition ... Zrotation, 2 in all), found 'JOINT'");
  check_error(read_bad_text(head + "\tJOINT\n\t{\n"), 5, 7, "expected a joint name, found end of line");
  check_error(read_bad_text(head + "\tEnd Site{\t{\n"), 5, 10, "expected one '{' after the name, found another '{'");
  check_error(read_bad_text(head + "\tJOINT B { {\n"), 5, 10, "expected one '{' after the name, found another '{'");
  check_error(read_bad_text(head + "\tEnd Sight\n"), 5, 6, "expected 'Site' after 'End', found 'Sight'");
  check_error(read_bad_text(head + "\tEnd Site\n\t{\n\t\tOFFSET 0 0 0\n\t\tCHANNELS 1 Xposition\n"), 8, 3,
              "expected '}', found 'CHANNELS'");
  check_error(read_bad_text(head + "\tOFFSET 0 0 0\n"), 5, 2, "expected CHANNELS, JOINT, End Site or '}', found 'OFFSET'");
  check_error(read_bad_text(head + "\tJOINT B\n\t{\n\t\tOFFSET 1 2 }\n"), 7, 14, "expected a number, found '}'");
  check_error(read_bad_text(head + "}\nJOINT B\n"), 6, 1, "expected ROOT or MOTION, found 'JOINT'");
  const std::string skel = head + "\tCHANNELS 1 Xposition\n}\nMOTION\n";
  check_error(read_bad_text(skel + "Frame Time: 0.1\n"), 8, 1, "expected 'Frames:', found 'Frame'");
  check_error(read_bad_text(skel + "Frames 3\n"), 8, 8, "expected ':' after 'Frames', found '3'");
  check_error(read_bad_text(skel + "Frames: -3\n"), 8, 9, "expected a frame count, found '-3'");
  check_error(read_bad_text(skel + "Frames: 1\nFrame Time: -0.1\n1\n"), 9, 13, "expected a frame time >= 0, found '-0.1'");
  check_error(read_bad_text(skel + "Frames: 1\nFrame Time: 0.1 x\n1\n"), 9, 17,
              "expected end of line after the frame time, found 'x'");
}

TEST_CASE("accepted variations in the hierarchy") {
  // Braces on the keyword's line, CHANNELS before OFFSET, a missing CHANNELS line (no channels),
  // a forest, "Frames :" with a blank, and a glued "Frames:2".
  const Motion m = read_good_text(
      "HIERARCHY\nROOT A {\n\tCHANNELS 1 Yrotation\n\tOFFSET 0 0 0\n\tJOINT B {\n\t\tOFFSET 1 0 0\n\t}\n\t"
      "End Site {\n\t\tOFFSET 0 0 0}}\nMOTION\nFrames :2\nFrame   Time:0.1\n5\n6\n");
  const auto& j = m.skeleton.joints;
  REQUIRE(j.size() == 3);
  check_joint(j[0], "A", -1, {0, 0, 0}, {Yr}, false, 0);
  check_joint(j[1], "B", 0, {1, 0, 0}, {}, false, 1);
  check_joint(j[2], "", 0, {0, 0, 0}, {}, true, 1);
  CHECK(m.values == std::vector<double>{5, 6});
}

TEST_CASE("duplicate joint names are kept with a warning") {
  std::vector<std::string> warnings;
  const Motion m = read_good_text(
      "HIERARCHY\nROOT A\n{\n\tOFFSET 0 0 0\n\tCHANNELS 0\n\tJOINT A\n\t{\n\t\tOFFSET 0 0 0\n\t\tCHANNELS 0\n\t}\n}\n"
      "MOTION\nFrames: 0\nFrame Time: 1\n",
      &warnings);
  CHECK(m.skeleton.joints.size() == 2);
  REQUIRE(warnings.size() == 1);
  CHECK(warnings[0].find("text.bvh:6:2: duplicate joint name 'A'") == 0);
}

TEST_CASE("a skeleton without channels takes the declared frame count") {
  const std::string skel = "HIERARCHY\nROOT A\n{\n\tOFFSET 0 0 0\n\tCHANNELS 0\n}\nMOTION\nFrames: 3\nFrame Time: 1\n";
  const Motion m = read_good_text(skel + "\n\n\n");
  CHECK(m.frame_count == 3);
  CHECK(m.values.empty());
  check_error(read_bad_text(skel + "1\n"), 10, 1, "expected an empty line (the skeleton has no channels), found '1'");
}

TEST_CASE("limits are enforced") {
  const std::string one_frame = slurp(fixture("one_frame.bvh"));
  BvhReadOptions joints_limit;
  joints_limit.max_joints = 2;
  check_error(read_bad_text(one_frame, joints_limit), 10, 3, "expected at most 2 nodes (max_joints), found more");
  CHECK(read_bad_text(one_frame, joints_limit).kind() == ErrorKind::limit);

  const std::string more = slurp(fixture("frames_more_lines.bvh"));  // Frames: 2, three lines
  BvhReadOptions frames_limit;
  frames_limit.max_frames = 1;
  check_error(read_bad_text(more, frames_limit), 12, 9, "expected at most 1 frames (max_frames), found 2");
  frames_limit.max_frames = 2;
  check_error(read_bad_text(more, frames_limit), 16, 1, "expected at most 2 motion lines (max_frames), found more");
  CHECK(read_bad_text(more, frames_limit).kind() == ErrorKind::limit);

  // The default limit, and a huge declared count that the data does not back.
  check_error(read_bad_text(std::string(kSmallHead) + "Frames: 99999999999\nFrame Time: 1\n1 2 3\n"), 12, 9,
              "expected at most 16777216 frames (max_frames), found 99999999999");
  check_error(read_bad_text(std::string(kSmallHead) + "Frames: 16000000\nFrame Time: 1\n1 2 3\n"), 12, 9,
              "expected 16000000 motion lines (Frames: 16000000), found 1");
}

TEST_CASE("read_bvh_file reports I/O errors with errno, at line 0") {
  const std::string path = fixture("does_not_exist.bvh");
  try {
    read_bvh_file(path);
    FAIL("accepted");
  } catch (const Error& e) {
    CHECK(e.kind() == ErrorKind::io);
    CHECK(e.file() == path);
    CHECK(e.line() == 0);
    CHECK(e.column() == 0);
    CHECK(e.system_error() == ENOENT);
    CHECK(e.message().find("No such file or directory") != std::string::npos);
    CHECK(std::string(e.what()) == path + ": " + e.message());
  }
  try {
    read_bvh_file(KEYANIM_TEST_DATA_DIR);  // a directory cannot be read
    FAIL("accepted");
  } catch (const Error& e) {
    CHECK(e.line() == 0);
    CHECK(e.system_error() == EISDIR);
    CHECK(e.message().find("Is a directory") != std::string::npos);
  }
}

TEST_CASE("writer output of canonical fixtures is byte-identical to the file") {
  // These fixtures were written by hand in the writer's layout (tabs, shortest numbers).
  for (const char* name : {"zero_frames.bvh", "one_frame.bvh", "mixed_rotation_orders.bvh",
                           "six_channels_all_joints.bvh", "multi_root.bvh", "no_end_site.bvh"}) {
    INFO(name);
    CHECK(write_bvh(read_good(name)) == slurp(fixture(name)));
  }
}

TEST_CASE("writer round trip on every good fixture") {
  for (const std::string& name : kGoodFixtures) {
    INFO(name);
    const Motion m = read_good(name);
    const std::string text = write_bvh(m);
    const Motion back = read_bvh(text, "written");
    CHECK(keyanim::test::motion_difference(m, back) == "");
    CHECK(write_bvh(back) == text);
  }
}

TEST_CASE("writer names End Sites and writes every root") {
  const std::string text = write_bvh(read_good("names_with_spaces_colons.bvh"));
  CHECK(text.find("\t\t\tEnd Site LeftHandEnd\n") != std::string::npos);
  CHECK(text.find("\t\tEnd Site\n") != std::string::npos);
  CHECK(text.find("\n\t\tJOINT Model.Left Arm\n") != std::string::npos);  // trailing blanks trimmed
  CHECK(text.find("\n\tJOINT Bip01  R:Hand.001\n") != std::string::npos);
  const std::string forest = write_bvh(read_good("multi_root.bvh"));
  CHECK(forest.find("\n}\nROOT Prop\n{\n") != std::string::npos);
}

TEST_CASE("writer is bit-exact for arbitrary finite doubles") {
  std::vector<double> values = {0.0,
                                -0.0,
                                0.1,
                                1.0 / 3.0,
                                0.1 + 0.2,
                                std::numeric_limits<double>::denorm_min(),
                                -std::numeric_limits<double>::denorm_min(),
                                std::numeric_limits<double>::min(),
                                std::numeric_limits<double>::max(),
                                std::numeric_limits<double>::lowest(),
                                std::numeric_limits<double>::epsilon(),
                                1e22,
                                1e23,
                                123456789012345680.0};
  std::mt19937_64 rng(12345);
  while (values.size() < 6000) {
    const uint64_t bits = rng();
    double d;
    std::memcpy(&d, &bits, sizeof d);
    if (std::isfinite(d)) values.push_back(d);
  }
  Motion m;
  Joint root;
  root.name = "R";
  root.channels = {Xp, Yp, Zp, Zr, Xr, Yr};
  root.offset = {values[5], values[9], values[3]};
  m.skeleton.joints.push_back(root);
  m.skeleton.assign_channel_columns();
  m.frame_count = uint32_t(values.size() / 6);
  m.frame_time = 1.0 / 120.0;
  m.values = values;
  const std::string text = write_bvh(m);
  const Motion back = read_bvh(text, "written");
  CHECK(keyanim::test::motion_difference(m, back) == "");
}

TEST_CASE("writer prints each number exactly as std::to_chars does") {
  // The writer has its own fast path for short decimals; its text must be identical to the
  // standard shortest form, so compare line by line against std::to_chars.
  std::vector<double> values = {0.0, -0.0, 1.0, -1.0, 10.0, 100000.0, 1000000.0, 1200000.0, 123456.0, 0.5, 0.1,
                                0.0001, 0.00001, 0.000322201, 0.0000322201, 5.1072e-06, 1e-9, 1.5e-9, 999999.999999999,
                                4194303.999999999, 4194304.0, 4194304.5, 4194303.0, -4194303.75, 0.0083333,
                                0.1 + 0.2, 1.0 / 3.0, 123.456789012, 9.999999999, 99999.99999};
  std::mt19937_64 rng(99);
  const double scales[] = {1, 10, 100, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10};
  while (values.size() < 400000) {
    const double scale = scales[rng() % std::size(scales)];
    const int64_t m = int64_t(rng() % 20000000000ull) - 10000000000ll;
    const double v = double(m) / scale / double(1 + rng() % 2 * 9);  // some m * 10^-k, some not
    values.push_back(v);
    values.push_back(std::nextafter(v, 1e300));   // neighbours: must fall back to the slow path
    values.push_back(std::nextafter(v, -1e300));
  }
  Motion m;
  Joint root;
  root.name = "R";
  root.channels = {Xp};
  m.skeleton.joints.push_back(root);
  m.skeleton.assign_channel_columns();
  m.frame_count = uint32_t(values.size());
  m.values = values;
  const std::string text = write_bvh(m);
  size_t pos = text.find("Frame Time: 0\n");
  REQUIRE(pos != std::string::npos);
  pos += 14;
  size_t mismatches = 0;
  for (double v : values) {
    const size_t eol = text.find('\n', pos);
    if (eol == std::string::npos) {
      FAIL("the text ends early");
      break;
    }
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    const std::string_view expected(buf, size_t(r.ptr - buf));
    if (std::string_view(text).substr(pos, eol - pos) != expected && ++mismatches <= 5)
      CHECK(std::string_view(text).substr(pos, eol - pos) == expected);
    pos = eol + 1;
  }
  CHECK(mismatches == 0);
  CHECK(pos == text.size());
}

TEST_CASE("writer follows depth-first order even if nodes are stored breadth-first") {
  // R has children A and B; A has child A1 (with an End Site). Stored R, A, B, A1, End: columns
  // R=0, A=1, B=2, A1=3. Written depth-first: R, A, A1, End, B, so a line reads R A A1 B.
  Motion m;
  auto add = [&](const char* name, int parent, std::vector<ChannelType> ch, bool end_site) {
    Joint j;
    j.name = name;
    j.parent = parent;
    j.channels = std::move(ch);
    j.end_site = end_site;
    m.skeleton.joints.push_back(j);  // first_channel left at 0: the writer must not rely on it
  };
  add("R", -1, {Xp}, false);
  add("A", 0, {Xr}, false);
  add("B", 0, {Yr}, false);
  add("A1", 1, {Zr}, false);
  add("", 3, {}, true);
  m.frame_count = 2;
  m.frame_time = 0.5;
  m.values = {10, 11, 12, 13, 20, 21, 22, 23};
  const std::string text = write_bvh(m);
  CHECK(text.find("\n10 11 13 12\n20 21 23 22\n") != std::string::npos);
  const Motion back = read_good_text(text);
  const auto& j = back.skeleton.joints;
  REQUIRE(j.size() == 5);
  check_joint(j[0], "R", -1, {0, 0, 0}, {Xp}, false, 0);
  check_joint(j[1], "A", 0, {0, 0, 0}, {Xr}, false, 1);
  check_joint(j[2], "A1", 1, {0, 0, 0}, {Zr}, false, 2);
  check_joint(j[3], "", 2, {0, 0, 0}, {}, true, 3);
  check_joint(j[4], "B", 0, {0, 0, 0}, {Yr}, false, 3);
  CHECK(back.values == std::vector<double>{10, 11, 13, 12, 20, 21, 23, 22});
}

}  // TEST_SUITE("bvh")
