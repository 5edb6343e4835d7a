// The runtime's way into a RigCache (keyanim/clip.h), which keeps its state private.
#pragma once
#include <cstdint>
#include <memory>
#include <span>

#include "keyanim/clip.h"
#include "runtime/rig.h"

namespace keyanim::internal {

struct RigCacheAccess {
  // The cache's rig equal to `skeleton` if it holds one in use, else a new one it then holds.
  static std::shared_ptr<const Rig> intern(RigCache& cache, Skeleton&& skeleton);
  // The rig of a runtime-profile file whose SKEL section is exactly `skel`, if the cache saw
  // one in use (remember_skel), else null: found without parsing SKEL.
  static std::shared_ptr<const Rig> find_skel(RigCache& cache, std::span<const uint8_t> skel);
  static void remember_skel(RigCache& cache, const std::shared_ptr<const Rig>& rig, std::span<const uint8_t> skel);
};

}  // namespace keyanim::internal
