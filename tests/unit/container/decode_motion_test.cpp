// decode_motion: a loaded clip back to a motion at the source rate, at another rate, with
// in-betweens and over a range.
#include <doctest/doctest.h>
#include <zstd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "keyanim/cardinal.h"
#include "keyanim/clip.h"
#include "clip_reference.h"
#include "keyanim/version.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/decode.h"

#include "crafted.h"

using namespace container_test;

TEST_SUITE("container") {

TEST_CASE("decode_motion at the source rate at another fps with inbetweens and a range") {
  using keyanim::offline::decode_motion;
  using keyanim::offline::Motion;
  using keyanim::offline::ResampleOptions;
  const Clip clip = keyanim::offline::to_clip(vector_long());  // 240 frames at 120 fps
  const uint32_t C = clip.channel_count();
  std::vector<float> pose(C);
  auto row_is = [&](const Motion& m, uint32_t row, double position) {
    REQUIRE(clip.sample(position, pose) == Status::ok);
    for (uint32_t c = 0; c < C; ++c)
      if (m.value(row, c) != double(pose[c])) return false;
    return true;
  };
  Motion m = decode_motion(clip);
  CHECK(m.frame_count == 240);
  CHECK(m.frame_time == 1.0 / 120.0);
  CHECK(m.values.size() == 240 * C);
  CHECK(m.skeleton.joints.size() == 3);
  CHECK(row_is(m, 0, 0));
  CHECK(row_is(m, 137, 137));
  CHECK(row_is(m, 239, 239));

  ResampleOptions o;
  o.fps = 30;  // 239 / 120 s = 1.9917 s: frames at 0, 1/30 .. 59/30 (frame 236)
  m = decode_motion(clip, o);
  CHECK(m.frame_count == 60);
  CHECK(m.frame_time == 1.0 / 30.0);
  CHECK(row_is(m, 1, 4));
  CHECK(row_is(m, 59, 236));

  o.fps = 50;  // every 2.4 source frames: 0, 2.4 .. 237.6 (99 x 2.4)
  m = decode_motion(clip, o);
  CHECK(m.frame_count == 100);
  CHECK(row_is(m, 3, 3.0 / 50.0 / (1.0 / 120.0)));

  o = {};
  o.inbetweens = 3;
  m = decode_motion(clip, o);
  CHECK(m.frame_count == 239 * 4 + 1);
  CHECK(m.frame_time == (1.0 / 120.0) / 4.0);
  CHECK(row_is(m, 8, 2));
  CHECK(row_is(m, 9, 2.25));
  CHECK(row_is(m, 10, 2.5));
  CHECK(row_is(m, 956, 239));

  o = {};
  o.first_frame = 5;
  o.last_frame = 20;
  m = decode_motion(clip, o);
  CHECK(m.frame_count == 16);
  CHECK(row_is(m, 0, 5));
  CHECK(row_is(m, 15, 20));
  o.fps = 60;  // 15 source frames at 120 fps = 0.125 s: 8 frames, the range's end included
  m = decode_motion(clip, o);
  CHECK(m.frame_count == 8);
  CHECK(row_is(m, 7, 19));
  o.fps = 40;  // every 3 source frames: 5, 8 .. 20, the end lands exactly
  m = decode_motion(clip, o);
  CHECK(m.frame_count == 6);
  CHECK(row_is(m, 5, 20));
  o.fps = 0;
  o.inbetweens = 1;
  m = decode_motion(clip, o);
  CHECK(m.frame_count == 31);
  CHECK(row_is(m, 1, 5.5));

  // Nonsense options.
  auto fails = [&](ResampleOptions bad) {
    try {
      decode_motion(clip, bad);
      FAIL_CHECK("accepted");
    } catch (const keyanim::offline::Error& e) {
      CHECK(e.kind() == keyanim::offline::ErrorKind::invalid_argument);
      CHECK(!e.message().empty());
    }
  };
  o = {};
  o.fps = 30;
  o.inbetweens = 2;
  fails(o);
  o = {};
  o.fps = -1;
  fails(o);
  o.fps = std::nan("");
  fails(o);
  o = {};
  o.first_frame = 10;
  o.last_frame = 9;
  fails(o);
  o.first_frame = 0;
  o.last_frame = 240;
  fails(o);
  o.first_frame = 240;
  o.last_frame = UINT32_MAX;
  fails(o);

  // A single-frame clip with Frame_Time 0 decodes to one frame at any rate.
  const Clip single = keyanim::offline::to_clip(vector_single());
  o = {};
  o.fps = 24;
  m = decode_motion(single, o);
  CHECK(m.frame_count == 1);
  CHECK(m.value(0, 0) == double(float(95250 * 0.001)));
}

TEST_CASE("a rate within rounding of the clip's own reproduces its frames and in-betweens") {
  using keyanim::offline::decode_motion;
  using keyanim::offline::Motion;
  using keyanim::offline::rate_map;
  using keyanim::offline::ResampleOptions;
  // BVH stores Frame Time rounded: .0083333 for 1/120 s, 0.0333333 for 1/30 s.
  EncodedClip e = vector_long();  // 240 frames
  e.frame_time = 0.0083333;
  const Clip clip = keyanim::offline::to_clip(e);
  const uint32_t C = clip.channel_count();
  auto same_rows = [&](const Motion& a, uint64_t ra, const Motion& b, uint64_t rb) {
    for (uint32_t c = 0; c < C; ++c)
      if (a.value(uint32_t(ra), c) != b.value(uint32_t(rb), c)) return false;
    return true;
  };
  const Motion source = decode_motion(clip);
  ResampleOptions o;
  o.fps = 120;  // 239 x 0.0083333 x 120 = 238.999: the old rule's floor made 239 frames, not 240
  Motion m = decode_motion(clip, o);
  REQUIRE(m.frame_count == 240);
  for (uint32_t f : {0u, 1u, 117u, 239u}) CHECK(same_rows(m, f, source, f));
  o.fps = 240;  // a multiple: the in-betweens, exactly as --inbetweens 1 places them
  m = decode_motion(clip, o);
  ResampleOptions ib;
  ib.inbetweens = 1;
  const Motion between = decode_motion(clip, ib);
  REQUIRE(m.frame_count == between.frame_count);
  CHECK(m.frame_count == 479);
  for (uint64_t f : {0ull, 1ull, 300ull, 478ull}) CHECK(same_rows(m, f, between, f));
  o.fps = 40;  // a divisor: every 3rd source frame, the last one (237) included
  m = decode_motion(clip, o);
  REQUIRE(m.frame_count == 80);
  CHECK(same_rows(m, 79, source, 237));
  o.fps = 119;  // neither: frames every 1/119 s up to the end
  m = decode_motion(clip, o);
  CHECK(m.frame_count == uint32_t(std::floor(239 * 0.0083333 * 119 + 1e-6)) + 1);
  CHECK(m.frame_time == 1.0 / 119.0);

  // The snap is 0.01%: 30 fps against 0.0333333 s snaps, 29.99 does not; 120 against 1/120 s
  // snaps to the clip's own frames whatever the rounding direction.
  CHECK(rate_map(194, 0.0333333, 30).per == 1);
  CHECK(rate_map(194, 0.0333333, 30).count == 195);
  CHECK(rate_map(194, 0.0333333, 60).per == 2);
  CHECK(rate_map(194, 0.0333333, 15).every == 2);
  CHECK(rate_map(194, 0.0333333, 15).count == 98);
  CHECK(rate_map(194, 0.0333333, 29.99).per == 0);
  CHECK(rate_map(194, 0.0333333, 29.99).every == 0);
  CHECK(rate_map(343, 0.00833334, 120).count == 344);
  CHECK(rate_map(0, 0.0, 30).count == 1);
  CHECK(rate_map(0, 0.0, 30).position(0) == 0.0);
}

}  // TEST_SUITE("container")
