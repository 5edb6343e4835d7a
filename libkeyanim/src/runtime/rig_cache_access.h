// The runtime's way into a RigCache (keyanim/clip.h), which keeps its state private.
#pragma once
#include <memory>

#include "keyanim/clip.h"
#include "runtime/rig.h"

namespace keyanim::internal {

struct RigCacheAccess {
  // The cache's rig equal to `skeleton` if it holds one in use, else a new one it then holds.
  static std::shared_ptr<const Rig> intern(RigCache& cache, Skeleton&& skeleton);
};

}  // namespace keyanim::internal
