// The progress callbacks of the BVH reader, the encoder and the glTF export (what keyanim's
// progress bar is built on): their stages in order, fractions from 0 to 1 that never go back within a stage, calls on
// the caller's thread only, and results that do not depend on them.
#include <doctest/doctest.h>

#include <thread>
#include <vector>

#include "keyanim/offline/bvh.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/gltf.h"

using namespace keyanim::offline;

namespace {

Motion walk(std::vector<double>* parse_fractions = nullptr) {
  BvhReadOptions options;
  if (parse_fractions) options.progress = [parse_fractions](double f) { parse_fractions->push_back(f); };
  return read_bvh_file(KEYANIM_REPO_DATA_DIR "/cmu_131_03_hop.bvh", nullptr, options);
}

struct Call {
  EncodeStage stage;
  double fraction;
};

// Encodes with a callback recording every call (and checking the thread it comes on).
std::vector<Call> encode_recording(const Motion& m, EncodeSettings s, EncodeResult& r) {
  std::vector<Call> calls;
  const std::thread::id caller = std::this_thread::get_id();
  bool other_thread = false;
  s.progress = [&](EncodeStage stage, double f) {
    other_thread |= std::this_thread::get_id() != caller;
    calls.push_back({stage, f});
  };
  r = encode(m, s);
  CHECK_FALSE(other_thread);
  return calls;
}

// Splits the calls into runs of one stage (stages alternate, so a run ends where the stage
// changes); each run's fractions stay in [0, 1], never go back, and end at 1. Returns the stages
// of the runs.
std::vector<EncodeStage> runs_of(const std::vector<Call>& calls) {
  std::vector<EncodeStage> runs;
  for (size_t i = 0; i < calls.size(); ++i) {
    const bool first = i == 0 || calls[i - 1].stage != calls[i].stage;
    if (first) runs.push_back(calls[i].stage);
    CHECK(calls[i].fraction >= 0.0);
    CHECK(calls[i].fraction <= 1.0);
    if (!first) CHECK(calls[i].fraction >= calls[i - 1].fraction);
    const bool last = i + 1 == calls.size() || calls[i + 1].stage != calls[i].stage;
    if (last) CHECK(calls[i].fraction == 1.0);
  }
  return runs;
}

}  // namespace

TEST_CASE("the BVH reader reports the motion text read, up to 1") {
  std::vector<double> f;
  const Motion m = walk(&f);
  REQUIRE(f.size() >= 2);  // 1102 frames: at the start, and at the end
  CHECK(f.front() == 0.0);
  CHECK(f.back() == 1.0);
  for (size_t i = 1; i < f.size(); ++i) CHECK(f[i] >= f[i - 1]);
  CHECK(m.frame_count == 1102);
}

TEST_CASE("error mode: rounds of fitting and verifying, then measuring, on the caller's thread") {
  const Motion m = walk();
  for (unsigned threads : {1u, 4u}) {
    CAPTURE(threads);
    EncodeSettings s;
    s.threads = threads;
    EncodeResult with;
    const std::vector<EncodeStage> runs = runs_of(encode_recording(m, s, with));
    REQUIRE(runs.size() == 2 * with.iterations + 1);
    for (uint32_t r = 0; r < with.iterations; ++r) {
      CHECK(runs[2 * r] == EncodeStage::fitting);
      CHECK(runs[2 * r + 1] == EncodeStage::verifying);
    }
    CHECK(runs.back() == EncodeStage::measuring);
    const EncodeResult without = encode(m, s);
    CHECK(write_kanim(with.clip) == write_kanim(without.clip));  // the callback changes nothing
  }
}

TEST_CASE("fixed key modes: fitting once, then measuring") {
  const Motion m = walk();
  EncodeSettings s;
  s.key_mode = KeyMode::uniform;
  s.uniform_interval = 8;
  EncodeResult r;
  const std::vector<EncodeStage> runs = runs_of(encode_recording(m, s, r));
  CHECK(runs == std::vector<EncodeStage>{EncodeStage::fitting, EncodeStage::measuring});
}

TEST_CASE("glTF export: rounds of fitting and verifying, then measuring, and the same asset") {
  const Motion m = walk();
  const EncodeResult r = encode(m, {});
  keyanim::Clip clip;
  REQUIRE(keyanim::Clip::load(write_kanim(r.clip), clip) == keyanim::Status::ok);
  GltfOptions options;
  std::vector<Call> calls;
  options.progress = [&](EncodeStage stage, double f) { calls.push_back({stage, f}); };
  const GltfOutput with = export_gltf(clip, options);
  const GltfReport& report = with.report;
  const std::vector<EncodeStage> runs = runs_of(calls);
  REQUIRE(runs.size() == 2 * report.rounds + 1);
  for (uint32_t i = 0; i < report.rounds; ++i) {
    CHECK(runs[2 * i] == EncodeStage::fitting);
    CHECK(runs[2 * i + 1] == EncodeStage::verifying);
  }
  CHECK(runs.back() == EncodeStage::measuring);
  options.progress = nullptr;
  const GltfOutput without = export_gltf(clip, options);
  CHECK(with.main == without.main);
}
