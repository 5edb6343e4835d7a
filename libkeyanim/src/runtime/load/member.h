// The loader's door for a bank (runtime/bank/): one member read with the bank's skeleton and
// dictionary (spec/FORMAT.md section 10.5).
#pragma once
#include <memory>
#include <span>

#include "keyanim/clip.h"
#include "runtime/load/loader.h"

namespace keyanim::internal {

// Checks and builds member `bytes` as Clip::view does a file (an archive member is decoded, a
// runtime member viewed in place, `storage` keeping its bytes alive; null: the caller does),
// with `m`'s skeleton and dictionary. Failures are reported at offsets from the bank's start.
Status load_member(std::span<const uint8_t> bytes, const MemberContext& m, std::shared_ptr<const void> storage,
                   const DecodeLimits& limits, RigCache* rigs, Clip& out, ErrorInfo* err);

}  // namespace keyanim::internal
