// Asking for cache lines ahead of use: a cold pose reads a few hundred lines, and its misses
// overlap only if they are asked for together (the loops that use them read a few curves or
// nodes at a time). Internal to the runtime.
#pragma once
#include <cstddef>
#include <cstdint>

namespace keyanim::internal {

// Every cache line of [p, p + bytes), for reading (or for writing with kWrite). Addresses are
// handled as integers, so no pointer outside the array is formed; a prefetch never faults.
template <bool kWrite = false>
[[gnu::always_inline]] inline void prefetch_bytes(const void* p, size_t bytes) noexcept {
  if (bytes == 0) return;
  const uintptr_t first = reinterpret_cast<uintptr_t>(p), last = first + bytes - 1;
  for (uintptr_t a = first; a < last; a += 64) __builtin_prefetch(reinterpret_cast<const void*>(a), kWrite ? 1 : 0);
  __builtin_prefetch(reinterpret_cast<const void*>(last), kWrite ? 1 : 0);  // when p is not at a line's start
}

// The same for the elements p[0 .. count - 1].
template <bool kWrite = false, class T>
[[gnu::always_inline]] inline void prefetch_array(const T* p, size_t count) noexcept {
  prefetch_bytes<kWrite>(p, count * sizeof(T));
}

}  // namespace keyanim::internal
