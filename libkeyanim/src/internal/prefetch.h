// Asking for cache lines ahead of use: a cold pose reads a few hundred lines, and its misses
// overlap only if they are asked for together (the loops that use them read a few curves or
// nodes at a time). Internal to the runtime.
#pragma once
#include <cstddef>
#include <cstdint>

namespace keyanim::internal {

// Every cache line of [p, p + bytes), for reading (or for writing with kWrite), four lines an
// iteration (on a warm pose the lines are there already, and a loop of one line an iteration
// cost as many instructions as its prefetches): up to three lines after the range are asked
// for too, which is harmless. Addresses are handled as integers, so no pointer outside the
// array is formed; a prefetch never faults.
template <bool kWrite = false>
[[gnu::always_inline]] inline void prefetch_bytes(const void* p, size_t bytes) noexcept {
  constexpr int kRw = kWrite ? 1 : 0;
  const uintptr_t first = reinterpret_cast<uintptr_t>(p) & ~uintptr_t(63);
  const uintptr_t end = reinterpret_cast<uintptr_t>(p) + bytes;
  for (uintptr_t a = first; a < end; a += 256) {
    __builtin_prefetch(reinterpret_cast<const void*>(a), kRw);
    __builtin_prefetch(reinterpret_cast<const void*>(a + 64), kRw);
    __builtin_prefetch(reinterpret_cast<const void*>(a + 128), kRw);
    __builtin_prefetch(reinterpret_cast<const void*>(a + 192), kRw);
  }
}

// The same for the elements p[0 .. count - 1].
template <bool kWrite = false, class T>
[[gnu::always_inline]] inline void prefetch_array(const T* p, size_t count) noexcept {
  prefetch_bytes<kWrite>(p, count * sizeof(T));
}

}  // namespace keyanim::internal
