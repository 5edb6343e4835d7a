// Clips of one rig loaded through one RigCache share a single skeleton and pose tables; clips of
// other rigs (another hierarchy, or one OFFSET bit apart) do not; sharing changes no sample.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <thread>
#include <vector>

#include "keyanim/clip.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/encode.h"

using namespace keyanim;
using namespace keyanim::offline;

namespace {

std::vector<uint8_t> kanim(const Motion& m, double tolerance_percent) {
  EncodeSettings s;
  s.tolerance = tolerance_percent;
  return write_kanim(encode(m, s).clip);
}

Motion walk() { return read_bvh_file(std::string(KEYANIM_REPO_DATA_DIR) + "/cmu_02_01_walk.bvh"); }
Motion hop() { return read_bvh_file(std::string(KEYANIM_REPO_DATA_DIR) + "/cmu_131_03_hop.bvh"); }

Clip load(const std::vector<uint8_t>& bytes, RigCache* rigs) {
  Clip c;
  REQUIRE(Clip::load(bytes, c, nullptr, {}, rigs) == Status::ok);
  return c;
}

}  // namespace

TEST_SUITE("rig cache") {

TEST_CASE("clips of one rig share it, other rigs do not, and poses are the same bits") {
  const Motion w = walk();
  Motion moved = w;  // the same hierarchy with one OFFSET one bit apart: another rig
  moved.skeleton.joints[3].offset[1] = std::nextafter(moved.skeleton.joints[3].offset[1], 1e9);
  const auto fine = kanim(w, 0.05), coarse = kanim(w, 0.5), other = kanim(hop(), 0.05), bit = kanim(moved, 0.05);
  RigCache rigs;
  const Clip a = load(fine, &rigs), b = load(coarse, &rigs), h = load(other, &rigs), m = load(bit, &rigs);
  CHECK(a.shares_rig(b));
  CHECK(&a.skeleton() == &b.skeleton());
  CHECK_FALSE(a.shares_rig(h));
  CHECK_FALSE(a.shares_rig(m));
  CHECK(a.rig_hash() == b.rig_hash());
  CHECK(a.rig_hash() != m.rig_hash());
  CHECK(a.rig_hash() != h.rig_hash());
  CHECK(rigs.rig_count() == 3);
  // Without the cache: the same hash, a rig of its own, and the same poses bit for bit.
  const Clip alone = load(fine, nullptr);
  CHECK(alone.rig_hash() == a.rig_hash());
  CHECK_FALSE(alone.shares_rig(a));
  CHECK(alone.skeleton_bytes() == a.skeleton_bytes());
  std::vector<Transform> p(a.skeleton().joints.size()), q(p.size());
  for (double f = 0; f < a.frame_count(); f += 3.7) {
    REQUIRE(a.sample_model(f, p) == Status::ok);
    REQUIRE(alone.sample_model(f, q) == Status::ok);
    CHECK(std::memcmp(p.data(), q.data(), p.size() * sizeof p[0]) == 0);
  }
}

TEST_CASE("the cache holds rigs weakly and outlives or predeceases its clips") {
  const auto bytes = kanim(walk(), 0.05);
  auto rigs = std::make_unique<RigCache>();
  {
    const Clip a = load(bytes, rigs.get());
    CHECK(rigs->rig_count() == 1);
  }
  CHECK(rigs->rig_count() == 0);  // no clip uses it: gone
  const Clip b = load(bytes, rigs.get());
  rigs.reset();  // the clip keeps its rig
  std::vector<Transform> p(b.skeleton().joints.size());
  CHECK(b.sample_local(10.5, p) == Status::ok);
  CHECK(b.skeleton().joints.size() > 1);
}

TEST_CASE("loading through one cache from several threads gives one rig") {
  const auto bytes = kanim(walk(), 0.05);
  RigCache rigs;
  std::vector<Clip> clips(8);
  std::vector<std::thread> threads;
  for (size_t t = 0; t < clips.size(); ++t)
    threads.emplace_back([&, t] { Clip::load(bytes, clips[t], nullptr, {}, &rigs); });
  for (auto& t : threads) t.join();
  CHECK(rigs.rig_count() == 1);
  for (const Clip& c : clips) CHECK(c.shares_rig(clips[0]));
}

}  // TEST_SUITE
