// Rigs: the hash and comparison that make two skeletons one rig, the pose tables, and the
// cache through which clips of one rig share them.
#include "runtime/rig.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <mutex>
#include <unordered_map>
#include <vector>

#include "internal/xxh64.h"

#include "keyanim/clip.h"
#include "runtime/rig_cache_access.h"

namespace keyanim::internal {
namespace {

struct Fnv {
  uint64_t h = 0xcbf29ce484222325ull;
  void bytes(const void* p, size_t n) noexcept {
    const auto* b = static_cast<const uint8_t*>(p);
    for (size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 0x100000001b3ull;
  }
  void u64(uint64_t x) noexcept { bytes(&x, sizeof x); }  // little-endian hosts, as the loader
};

// The pose tables (Rig::node_offset, moves; the Euler groups: euler_groups).
void build_pose_tables(Rig& rig) {
  const auto& joints = rig.skeleton.joints;
  for (uint32_t node = 0; node < joints.size(); ++node) {
    const Joint& j = joints[node];
    for (double o : j.offset) rig.node_offset.push_back(static_cast<float>(o));
    rig.node_offset.push_back(0.0f);
    for (size_t k = 0; k < j.channels.size(); ++k)
      if (!is_rotation(j.channels[k]))
        rig.moves.push_back({node, j.first_channel + static_cast<uint32_t>(k), static_cast<uint32_t>(channel_axis(j.channels[k]))});
  }
  rig.euler = euler_groups(rig.skeleton);
}

// The skeleton's nodes: the array, names beyond the small-string buffer, channel lists.
size_t joints_bytes(const Skeleton& skeleton) noexcept {
  size_t n = skeleton.joints.capacity() * sizeof(Joint);
  for (const Joint& j : skeleton.joints) {
    n += j.name.capacity() > 15 ? j.name.capacity() : 0;
    n += j.channels.capacity() * sizeof(ChannelType);
  }
  return n;
}

void shrink(Rig& rig) {
  rig.skeleton.joints.shrink_to_fit();
  for (Joint& j : rig.skeleton.joints) j.name.shrink_to_fit(), j.channels.shrink_to_fit();
  rig.node_offset.shrink_to_fit();
  rig.moves.shrink_to_fit();
}

}  // namespace

// Nodes grouped by their rotation axes in order of first appearance, each group's columns step
// by step.
EulerGroups euler_groups(const Skeleton& skeleton, const std::vector<uint8_t>* skip) {
  EulerGroups out;
  std::vector<std::vector<uint32_t>> members;  // per group, its nodes
  std::unordered_map<uint32_t, uint32_t> group_of;
  const auto& joints = skeleton.joints;
  for (uint32_t node = 0; node < joints.size(); ++node) {
    if (skip != nullptr && (*skip)[node]) continue;
    const Joint& j = joints[node];
    EulerGroups::Group key{};
    for (size_t k = 0; k < j.channels.size(); ++k)
      if (is_rotation(j.channels[k])) key.axis[key.steps++] = static_cast<uint8_t>(channel_axis(j.channels[k]));
    uint32_t code = key.steps;  // the axis sequence as a number: one lookup per node
    for (uint32_t k = 0; k < key.steps; ++k) code = code * 3 + key.axis[k];
    const auto [at, added] = group_of.try_emplace(code, static_cast<uint32_t>(out.groups.size()));
    if (added) {
      out.groups.push_back(key);
      members.emplace_back();
    }
    members[at->second].push_back(node);
  }
  for (size_t i = 0; i < out.groups.size(); ++i) {
    EulerGroups::Group& g = out.groups[i];
    g.node_first = static_cast<uint32_t>(out.node.size());
    g.node_count = static_cast<uint32_t>(members[i].size());
    g.column_first = static_cast<uint32_t>(out.column.size());
    out.node.insert(out.node.end(), members[i].begin(), members[i].end());
    for (uint32_t k = 0; k < g.steps; ++k)
      for (uint32_t node : members[i]) {
        const Joint& j = joints[node];
        uint32_t seen = 0;  // the node's k-th rotation channel
        for (size_t c = 0; c < j.channels.size(); ++c)
          if (is_rotation(j.channels[c]) && seen++ == k) out.column.push_back(j.first_channel + uint32_t(c));
      }
  }
  out.groups.shrink_to_fit(), out.node.shrink_to_fit(), out.column.shrink_to_fit();
  return out;
}

size_t EulerGroups::bytes() const noexcept {
  return groups.capacity() * sizeof(Group) + (node.capacity() + column.capacity()) * sizeof(uint32_t);
}

uint64_t rig_hash(const Skeleton& skeleton) noexcept {
  Fnv f;
  f.u64(skeleton.joints.size());
  for (const Joint& j : skeleton.joints) {
    f.u64(j.name.size());
    f.bytes(j.name.data(), j.name.size());
    f.u64(static_cast<uint64_t>(static_cast<int64_t>(j.parent)));
    for (double o : j.offset) f.u64(std::bit_cast<uint64_t>(o));
    f.u64(j.end_site);
    f.u64(j.channels.size());
    f.bytes(j.channels.data(), j.channels.size());
  }
  return f.h;
}

bool same_rig(const Skeleton& a, const Skeleton& b) noexcept {
  auto same = [](const Joint& x, const Joint& y) {
    return x.name == y.name && x.parent == y.parent && x.end_site == y.end_site && x.channels == y.channels &&
           std::memcmp(x.offset.data(), y.offset.data(), sizeof x.offset) == 0;  // bits, as the hash
  };
  return std::equal(a.joints.begin(), a.joints.end(), b.joints.begin(), b.joints.end(), same);
}

// The skeleton's nodes, the pose tables and the rig itself.
size_t Rig::bytes() const noexcept {
  size_t plan_bytes = 0;
  {
    const std::lock_guard<std::mutex> lock(plans_mutex);
    for (const QuatPlan& p : plans) plan_bytes += p.quat_nodes.capacity() * sizeof(uint32_t) + sizeof(EulerGroups) + p.euler->bytes();
    plan_bytes += plans.capacity() * sizeof(QuatPlan);
  }
  return sizeof(Rig) + joints_bytes(skeleton) + node_offset.capacity() * sizeof(float) + euler.bytes() +
         moves.capacity() * sizeof(Move) + plan_bytes;
}

std::shared_ptr<const Rig> make_rig(Skeleton&& skeleton) {
  auto rig = std::make_shared<Rig>();
  rig->skeleton = std::move(skeleton);
  rig->hash = rig_hash(rig->skeleton);
  build_pose_tables(*rig);
  shrink(*rig);
  return rig;
}

}  // namespace keyanim::internal

namespace keyanim {

// Rigs by hash, held weakly (a rig lives as long as a clip uses it); expired entries are
// dropped when a rig of the same hash is looked up, and by rig_count().
struct RigCache::State {
  mutable std::mutex mutex;
  mutable std::unordered_multimap<uint64_t, std::weak_ptr<const internal::Rig>> rigs;
  // The same rigs by the XXH64 of a runtime-profile file's SKEL bytes, with those bytes: a
  // file whose SKEL equals one seen finds its rig without parsing it (spec section 9).
  struct BySkel {
    std::weak_ptr<const internal::Rig> rig;
    std::vector<uint8_t> skel;
  };
  mutable std::unordered_multimap<uint64_t, BySkel> by_skel;
};

RigCache::RigCache() : state_(std::make_unique<State>()) {}
RigCache::~RigCache() = default;

size_t RigCache::rig_count() const noexcept {
  const std::lock_guard<std::mutex> lock(state_->mutex);
  std::erase_if(state_->rigs, [](const auto& e) { return e.second.expired(); });
  std::erase_if(state_->by_skel, [](const auto& e) { return e.second.rig.expired(); });
  return state_->rigs.size();
}

}  // namespace keyanim

namespace keyanim::internal {

std::shared_ptr<const Rig> RigCacheAccess::intern(RigCache& cache, Skeleton&& skeleton) {
  const uint64_t h = rig_hash(skeleton);
  RigCache::State& st = *cache.state_;
  const std::lock_guard<std::mutex> lock(st.mutex);
  auto [it, end] = st.rigs.equal_range(h);
  while (it != end) {
    std::shared_ptr<const Rig> rig = it->second.lock();
    if (rig == nullptr) {
      it = st.rigs.erase(it);
    } else {
      if (same_rig(rig->skeleton, skeleton)) return rig;
      ++it;
    }
  }
  std::shared_ptr<const Rig> rig = make_rig(std::move(skeleton));
  st.rigs.emplace(h, rig);
  return rig;
}

std::shared_ptr<const Rig> RigCacheAccess::find_skel(RigCache& cache, std::span<const uint8_t> skel) {
  const uint64_t h = xxh64_of(skel.data(), skel.size());
  RigCache::State& st = *cache.state_;
  const std::lock_guard<std::mutex> lock(st.mutex);
  auto [it, end] = st.by_skel.equal_range(h);
  while (it != end) {
    std::shared_ptr<const Rig> rig = it->second.rig.lock();
    if (rig == nullptr) {
      it = st.by_skel.erase(it);
      continue;
    }
    if (std::equal(skel.begin(), skel.end(), it->second.skel.begin(), it->second.skel.end())) return rig;
    ++it;
  }
  return nullptr;
}

void RigCacheAccess::remember_skel(RigCache& cache, const std::shared_ptr<const Rig>& rig, std::span<const uint8_t> skel) {
  const uint64_t h = xxh64_of(skel.data(), skel.size());
  RigCache::State& st = *cache.state_;
  const std::lock_guard<std::mutex> lock(st.mutex);
  st.by_skel.emplace(h, RigCache::State::BySkel{rig, {skel.begin(), skel.end()}});
}

}  // namespace keyanim::internal
