// The promise on real data: every corpus file goes BVH -> .kanim bytes -> motion with the
// hierarchy identical, frame count and time preserved, and the world-space error within the
// default tolerance, measured by FK on what a decoder makes of the bytes.
#include <doctest/doctest.h>

#include <cstring>

#include "corpus_files.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/decode.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/fk.h"
#include "keyanim/offline/metrics.h"

using namespace keyanim;
using namespace keyanim::offline;

namespace {

bool same_skeleton(const Skeleton& a, const Skeleton& b) {
  if (a.joints.size() != b.joints.size()) return false;
  for (size_t i = 0; i < a.joints.size(); ++i) {
    const Joint& x = a.joints[i];
    const Joint& y = b.joints[i];
    if (x.name != y.name || x.parent != y.parent || x.channels != y.channels || x.end_site != y.end_site ||
        x.first_channel != y.first_channel || std::memcmp(x.offset.data(), y.offset.data(), sizeof x.offset) != 0)
      return false;
  }
  return true;
}

}  // namespace

TEST_SUITE("corpus") {
  TEST_CASE("every corpus file round-trips through .kanim within the default tolerance") {
    const auto files = keyanim::test::corpus_bvh_files();
    if (files.empty()) {
      KEYANIM_SKIP_CORPUS_TEST(keyanim::test::corpus_dir().string());
      return;
    }
    for (const auto& path : files) {
      CAPTURE(path.filename().string());
      Motion m;
      BvhError err;
      REQUIRE(read_bvh_file(path.string(), m, err));
      EncodeSettings settings;  // 0.05% of the skeleton size, error mode
      EncodeResult r;
      std::string why;
      REQUIRE(encode(m, settings, r, why));
      const std::vector<uint8_t> bytes = write_kanim(r.clip);
      Clip clip;
      ErrorInfo info;
      REQUIRE(Clip::load(bytes, clip, &info) == Status::ok);
      Motion back;
      REQUIRE(decode_motion(clip, {}, back, why));
      CHECK(same_skeleton(m.skeleton, back.skeleton));
      CHECK(back.frame_count == m.frame_count);
      CHECK(back.frame_time == m.frame_time);
      const ErrorReport e = measure_error(m, back);
      CHECK(e.max_error <= r.tolerance_units);
      CHECK(r.tolerance_units == doctest::Approx(0.0005 * reference_size(m)));
      if (skeleton_size(m.skeleton) > 0.0) CHECK(reference_size(m) == skeleton_size(m.skeleton));
    }
  }
}
