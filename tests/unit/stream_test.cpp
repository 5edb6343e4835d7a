// Streaming output: BvhWriter (BVH text in bounded chunks, indentation capped so that the text
// stays linear in a hierarchy's depth) and FrameDecoder (decoded frames one at a time, counted
// before any is made). Expected texts are the hand-written canonical fixtures of tests/data/bvh;
// expected frames come from Clip::sample at the documented positions.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "keyanim/offline/bvh.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/decode.h"
#include "keyanim/offline/encode.h"
#include "motion_compare.h"

using namespace keyanim;
using namespace keyanim::offline;

namespace {

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  REQUIRE(in);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

Motion read_text(const std::string& text) { return read_bvh(text, "text"); }

// All of a motion through a BvhWriter; `chunks` gets the size of every piece the sink saw.
std::string stream(const Motion& m, std::vector<size_t>& chunks) {
  std::string text;
  BvhWriter w(m.skeleton, m.frame_count, m.frame_time, [&](std::string_view c) {
    chunks.push_back(c.size());
    text.append(c);
  });
  for (uint32_t f = 0; f < m.frame_count; ++f) w.frame(m.frame(f));
  CHECK_NOTHROW(w.finish());
  return text;
}

// A chain of `depth` joints, one Zrotation channel each, ending in an End Site.
Motion chain(uint32_t depth, uint32_t frames) {
  Motion m;
  for (uint32_t i = 0; i < depth; ++i)
    m.skeleton.joints.push_back(Joint{"j" + std::to_string(i), int32_t(i) - 1, {0, 1, 0}, {ChannelType::z_rotation}});
  m.skeleton.joints.push_back(Joint{"", int32_t(depth) - 1, {0, 1, 0}, {}, true});
  m.skeleton.assign_channel_columns();
  m.frame_count = frames;
  m.frame_time = 0.125;
  for (uint32_t f = 0; f < frames; ++f)
    for (uint32_t c = 0; c < depth; ++c) m.values.push_back(0.5 * f + 0.25 * c);
  return m;
}

// A 3-joint chain encoded with keys every 4th frame, loaded.
Clip encoded_chain(uint32_t frames) {
  Motion m = chain(3, frames);
  EncodeSettings s;
  s.key_mode = KeyMode::uniform;
  s.uniform_interval = 4;
  EncodeResult r = encode(m, s);
  Clip clip;
  REQUIRE(Clip::load(write_kanim(r.clip), clip) == Status::ok);
  return clip;
}

size_t max_leading_tabs(const std::string& text) {
  size_t most = 0;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    most = std::max(most, line.find_first_not_of('\t') == std::string::npos ? line.size() : line.find_first_not_of('\t'));
  return most;
}

}  // namespace

TEST_SUITE("stream") {
  TEST_CASE("BvhWriter writes the canonical fixtures byte for byte") {
    for (const char* name : {"zero_frames.bvh", "one_frame.bvh", "mixed_rotation_orders.bvh",
                             "six_channels_all_joints.bvh", "multi_root.bvh", "no_end_site.bvh"}) {
      INFO(name);
      const std::string file = slurp(std::string(KEYANIM_TEST_DATA_DIR) + "/bvh/" + name);
      std::vector<size_t> chunks;
      CHECK(stream(read_text(file), chunks) == file);
      CHECK(chunks.size() == 1);  // small: one piece, at finish()
    }
  }

  TEST_CASE("BvhWriter hands long motions over in bounded chunks that read back exactly") {
    // 30000 frames of 60 channels: about 9 MB of text.
    const Motion m = chain(60, 30000);
    std::vector<size_t> chunks;
    const std::string text = stream(m, chunks);
    CHECK(chunks.size() >= 8);
    const size_t row_bound = 60 * 25 + 1;
    for (size_t c : chunks) CHECK(c <= (size_t(1) << 20) + row_bound);
    CHECK(keyanim::test::motion_difference(m, read_text(text)) == "");
  }

  TEST_CASE("BvhWriter::finish reports a frame count that differs from the declared one") {
    const Motion m = chain(2, 3);
    BvhWriter w(m.skeleton, 3, m.frame_time, [](std::string_view) {});
    w.frame(m.frame(0));
    w.frame(m.frame(1));
    CHECK_THROWS_WITH_AS(w.finish(), "BVH writer: 2 frames given, 3 declared", Error);
    BvhWriter w2(m.skeleton, 1, m.frame_time, [](std::string_view) {});
    w2.frame(m.frame(0));
    w2.frame(m.frame(1));
    CHECK_THROWS_AS(w2.finish(), Error);
  }

  TEST_CASE("a deep chain's text is linear in its depth and reads back exactly") {
    // Indented one tab per level, 20000 levels would take about 20000^2 * 2 = 800 MB of tabs.
    const Motion m = chain(20000, 2);
    std::vector<size_t> chunks;
    const std::string text = stream(m, chunks);
    CHECK(max_leading_tabs(text) == kMaxIndent);
    // Five lines a node (name, braces, OFFSET, CHANNELS) of at most kMaxIndent tabs and a few
    // words each, and two frames of at most 25 characters a value.
    CHECK(text.size() < 20001 * (5 * kMaxIndent + 60) + 2 * 20000 * 25);
    CHECK(keyanim::test::motion_difference(m, read_text(text)) == "");
    CHECK(write_bvh(m) == text);
  }

  TEST_CASE("FrameDecoder counts frames before making any, past what a Motion can hold") {
    const Clip clip = encoded_chain(9);  // 8 frame times of 0.125 s: 1 s
    FrameDecoder d;
    ResampleOptions o;
    o.fps = 1e10;  // 1e10 + 1 frames: counted, not made
    d.start(clip, o);
    CHECK(d.frame_count() == 10000000001ull);
    CHECK(d.frame_time() == 1e-10);
    try {
      decode_motion(clip, o);
      FAIL("made");
    } catch (const Error& e) {
      CHECK(e.kind() == ErrorKind::limit);
      CHECK(e.message().find("too many output frames") != std::string::npos);
    }
    o.fps = 1e300;  // saturates instead of overflowing
    d.start(clip, o);
    CHECK(d.frame_count() == UINT64_MAX);
    o = {};
    o.inbetweens = UINT32_MAX;
    d.start(clip, o);
    CHECK(d.frame_count() == 8ull * (uint64_t(UINT32_MAX) + 1) + 1);
  }

  TEST_CASE("FrameDecoder frames are the clip's samples at the documented positions") {
    const Clip clip = encoded_chain(9);
    const uint32_t C = clip.channel_count();
    std::vector<float> pose(C);
    std::vector<double> row(C);
    auto check_frames = [&](const ResampleOptions& o, uint64_t count, auto position_of) {
      FrameDecoder d;
      d.start(clip, o);
      REQUIRE(d.frame_count() == count);
      for (uint64_t i = 0; i < count; ++i) {
        d.frame(i, row);
        REQUIRE(clip.sample(position_of(i), pose) == Status::ok);
        for (uint32_t c = 0; c < C; ++c) CHECK(row[c] == double(pose[c]));
      }
    };
    check_frames({}, 9, [](uint64_t i) { return double(i); });
    ResampleOptions o;
    o.inbetweens = 2;
    check_frames(o, 25, [](uint64_t i) { return double(i) / 3.0; });
    o = {};
    o.fps = 20;  // every 0.4 source frames over 1 s: 21 frames
    check_frames(o, 21, [](uint64_t i) { return (double(i) / 20.0) / 0.125; });
    o = {};
    o.first_frame = 2;
    o.last_frame = 5;
    check_frames(o, 4, [](uint64_t i) { return 2.0 + double(i); });
  }

  TEST_CASE("FrameDecoder refuses what decode_motion refuses") {
    const Clip clip = encoded_chain(9);
    FrameDecoder d;
    auto refused = [&](const ResampleOptions& o) {
      try {
        d.start(clip, o);
      } catch (const Error& e) {
        return e.kind() == ErrorKind::invalid_argument && !e.message().empty();
      }
      return false;
    };
    for (const double fps : {-1.0, std::nan(""), double(INFINITY)}) {
      ResampleOptions o;
      o.fps = fps;
      CHECK(refused(o));
    }
    ResampleOptions o;
    o.first_frame = 5;
    o.last_frame = 3;
    CHECK(refused(o));
    o.last_frame = 9;
    CHECK(refused(o));
    o = {};
    o.fps = 30;
    o.inbetweens = 1;
    CHECK(refused(o));
  }
}
