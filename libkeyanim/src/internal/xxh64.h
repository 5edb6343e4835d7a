// XXH64, the runtime profile's checksum (spec/FORMAT.md section 9.1), from xxHash's header
// (libxxhash-dev): compiled inline, so the library needs xxHash to build, not to run.
#pragma once
#include <cstddef>
#include <cstdint>

#define XXH_INLINE_ALL
#include <xxhash.h>

namespace keyanim::internal {

inline uint64_t xxh64_of(const uint8_t* p, size_t n) noexcept { return XXH64(p, n, 0); }

}  // namespace keyanim::internal
