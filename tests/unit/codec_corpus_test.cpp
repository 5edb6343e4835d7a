// The promise on real data: every corpus file goes BVH -> .kanim bytes -> motion with the
// hierarchy identical, frame count and time preserved, and the world-space error within the
// default tolerance on every joint, End Site and shell point (2% of the skeleton size), under
// both readings of position channels where the file has them below the root, measured on what a
// decoder makes of the bytes by an independent forward kinematics (shell_reference.h). The same
// clip through format 4's runtime profile (loaded, viewed, converted back) decodes to the same
// values bit for bit, and converted back to the archive profile it decodes to them again. The
// whole corpus packed into one bank, in either profile, decodes to those values again, clip by
// clip (so every clip of the bank is within the tolerance checked here).
#include <doctest/doctest.h>

#include <cstring>

#include "corpus_files.h"
#include "keyanim/bank.h"
#include "keyanim/offline/bank.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/decode.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/fk.h"
#include "keyanim/offline/metrics.h"
#include "shell_reference.h"

using namespace keyanim;
using namespace keyanim::offline;
namespace fs = std::filesystem;

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

// The largest distance over every measured point, frame and reading, by the reference FK.
bool same_values(const Motion& a, const Motion& b) {
  return a.values.size() == b.values.size() &&
         std::memcmp(a.values.data(), b.values.data(), a.values.size() * sizeof(double)) == 0;
}

// The archive file `archive` (loaded as `clip`) through the runtime profile: what Clip::load and
// Clip::view make of it decodes to `back`'s values bit for bit; converted back to the archive
// profile it decodes to them too. (Those bytes may differ from the encoder's: conversion codes a
// channel's single key as q = ±1, spec section 9.3; converting from the archive gives the
// same bytes.)
void check_runtime_profile(const std::vector<uint8_t>& archive, const Clip& clip, const Motion& back) {
  const std::vector<uint8_t> runtime = write_kanim_runtime(clip);
  std::vector<uint64_t> aligned((runtime.size() + 7) / 8);  // view() wants 8-aligned bytes
  std::memcpy(aligned.data(), runtime.data(), runtime.size());
  const std::span<const uint8_t> in_place(reinterpret_cast<const uint8_t*>(aligned.data()), runtime.size());
  Clip loaded, viewed;
  DecodeLimits limits;
  limits.check_content = true;
  REQUIRE(Clip::load(runtime, loaded, nullptr, limits) == Status::ok);
  REQUIRE(Clip::view(in_place, viewed, nullptr, limits) == Status::ok);
  CHECK(loaded.runtime_profile());
  CHECK(viewed.runtime_profile());
  CHECK(same_values(decode_motion(loaded), back));
  CHECK(same_values(decode_motion(viewed), back));
  const std::vector<uint8_t> again = write_kanim(encoded_clip(viewed));
  CHECK(again == write_kanim(encoded_clip(clip)));
  Clip archived;
  REQUIRE(Clip::load(again, archived) == Status::ok);
  CHECK(!archived.runtime_profile());
  CHECK(same_values(decode_motion(archived), back));
  (void)archive;
}

// FNV-1a of a motion's values' bytes: what a bank's clip must decode to, without keeping every
// decoded corpus motion in memory.
uint64_t values_hash(const Motion& m) {
  uint64_t h = 0xcbf29ce484222325ull;
  const auto* p = reinterpret_cast<const uint8_t*>(m.values.data());
  for (size_t i = 0; i < m.values.size() * sizeof(double); ++i) h = (h ^ p[i]) * 0x100000001b3ull;
  return h;
}

// The corpus's clips in one bank of each profile: each decodes to the values its own file did.
void check_corpus_bank(const std::vector<BankInput>& clips, const std::vector<uint64_t>& hashes) {
  for (const bool runtime : {false, true}) {
    CAPTURE(runtime);
    BankOptions o;
    o.runtime = runtime;
    const WrittenBank w = write_bank(clips, o);
    Bank bank;
    REQUIRE(Bank::open(w.bytes, bank) == Status::ok);
    REQUIRE(bank.clip_count() == clips.size());
    CHECK(w.skeletons < clips.size());  // the corpus shares skeletons (CMU's, Bandai's)
    for (uint32_t i = 0; i < bank.clip_count(); ++i) {
      CAPTURE(clips[i].name);
      const std::optional<uint32_t> at = bank.find(clips[i].name);
      REQUIRE(at == i);
      Clip clip;
      REQUIRE(bank.clip(i, clip) == Status::ok);
      CHECK(values_hash(decode_motion(clip)) == hashes[i]);
    }
  }
}

long double reference_error(const Motion& a, const Motion& b, long double shell, uint32_t& readings) {
  long double worst = 0;
  readings = 0;
  for (const test::Reading r : {test::Reading::replace, test::Reading::add}) {
    if (r == test::Reading::add && !test::has_position_channels(a.skeleton)) continue;
    ++readings;
    for (uint32_t f = 0; f < a.frame_count; ++f)
      for (const test::NodeError& e : test::node_errors(a.skeleton, a.frame(f), b.frame(f), shell, r))
        worst = std::max(worst, e.all);
  }
  return worst;
}

}  // namespace

TEST_SUITE("corpus") {
  TEST_CASE("every corpus file round-trips through .kanim within the default tolerance") {
    const auto files = keyanim::test::corpus_bvh_files();
    if (files.empty()) {
      KEYANIM_SKIP_CORPUS_TEST(keyanim::test::corpus_dir().string());
      return;
    }
    std::vector<BankInput> bank;
    std::vector<uint64_t> hashes;
    for (const auto& path : files) {
      CAPTURE(path.filename().string());
      const Motion m = read_bvh_file(path.string());
      const EncodeSettings settings;  // 0.05% of the skeleton size, error mode
      const EncodeResult r = encode(m, settings);
      const std::vector<uint8_t> bytes = write_kanim(r.clip);
      Clip clip;
      ErrorInfo info;
      REQUIRE(Clip::load(bytes, clip, &info) == Status::ok);
      const Motion back = decode_motion(clip);
      check_runtime_profile(bytes, clip, back);
      CHECK(same_skeleton(m.skeleton, back.skeleton));
      CHECK(back.frame_count == m.frame_count);
      CHECK(back.frame_time == m.frame_time);
      const ErrorReport e = measure_error(m, back);
      CHECK(e.max_error <= r.tolerance_units);
      // The guarantee, checked by code that shares nothing with the encoder's FK: binary64
      // against long double rounding may differ by a few ulps of the skeleton's extent.
      const double size = reference_size(m);
      CHECK(r.shell_units == doctest::Approx(0.02 * size).epsilon(1e-12));
      uint32_t readings = 0;
      const long double ref = reference_error(m, back, r.shell_units, readings);
      CHECK(double(ref) <= r.tolerance_units + 1e-12 * size);
      CHECK(std::fabs(double(ref) - e.max_error) <= 1e-12 * size);
      CHECK(readings == (e.both_readings ? 2u : 1u));
      CHECK(r.tolerance_units == doctest::Approx(0.0005 * reference_size(m)));
      if (skeleton_size(m.skeleton) > 0.0) CHECK(reference_size(m) == skeleton_size(m.skeleton));
      fs::path name = path.lexically_relative(keyanim::test::corpus_dir());
      bank.push_back({name.replace_extension().generic_string(), r.clip});
      hashes.push_back(values_hash(back));
    }
    check_corpus_bank(bank, hashes);
  }
}
