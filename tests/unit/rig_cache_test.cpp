// Clips of one rig loaded through one RigCache share a single skeleton and pose tables; clips of
// other rigs (another hierarchy, or one OFFSET bit apart) do not; sharing changes no sample.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "keyanim/clip.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/encode.h"
#include "runtime/image.h"

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


// Version 5: the Euler groups of the nodes a clip does not store as quaternions are made once
// per set of quaternion nodes and kept by the rig (Rig::plans): clips of one set share them, a
// new set adds one, and past Rig::kMaxQuatPlans sets a clip makes its own. Every plan holds
// exactly the rig's Euler nodes but the set's.
TEST_CASE("a rig makes the Euler groups of each set of quaternion nodes once, up to its limit") {
  Skeleton s;
  const uint32_t joints = uint32_t(internal::Rig::kMaxQuatPlans) + 3;
  for (uint32_t j = 0; j < joints; ++j)
    s.joints.push_back({"j" + std::to_string(j), int32_t(j) - 1, {0, 1, 0},
                        {ChannelType::z_rotation, ChannelType::x_rotation, ChannelType::y_rotation}});
  s.assign_channel_columns();
  const std::shared_ptr<const internal::Rig> rig = internal::make_rig(std::move(s));
  // Image k stores node k as a quaternion node; images 0 and 1 make one set, so 0 .. joints - 2
  // make joints - 2 sets: past the limit for the last ones.
  std::vector<std::vector<uint32_t>> sets(joints - 1);
  std::vector<std::unique_ptr<internal::Image>> images;
  for (uint32_t k = 0; k + 1 < joints; ++k) {
    sets[k] = k == 1 ? std::vector<uint32_t>{0} : std::vector<uint32_t>{k};
    auto img = std::make_unique<internal::Image>();
    img->rig = rig;
    img->quat_node = sets[k];
    internal::plan_rotations(*img);
    const size_t distinct = k == 0 ? 1 : k;  // sets made so far, this one's included
    if (distinct <= internal::Rig::kMaxQuatPlans) {
      CHECK(img->euler == img->rig_euler.get());
      CHECK(img->own_euler.node.empty());
    } else {
      CHECK(img->rig_euler == nullptr);
      CHECK(img->euler == &img->own_euler);
    }
    std::vector<uint32_t> euler_nodes;  // the plan's nodes: every node but the set's
    for (const auto& g : img->euler->groups)
      euler_nodes.insert(euler_nodes.end(), img->euler->node.begin() + g.node_first, img->euler->node.begin() + g.node_first + g.node_count);
    std::sort(euler_nodes.begin(), euler_nodes.end());
    std::vector<uint32_t> want;
    for (uint32_t j = 0; j < joints; ++j)
      if (j != sets[k][0]) want.push_back(j);
    CHECK(euler_nodes == want);
    images.push_back(std::move(img));
  }
  CHECK(images[0]->rig_euler == images[1]->rig_euler);  // one set, one plan
  CHECK(images[0]->rig_euler != images[2]->rig_euler);
  CHECK(rig->plans.size() == internal::Rig::kMaxQuatPlans);
}

}  // TEST_SUITE
