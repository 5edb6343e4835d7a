// Reading and patching little-endian fields of a file's bytes by offset, as the tests that break
// one rule at a time do (bounds-checked: a wrong offset in a test fails, it does not corrupt).
#pragma once
#include <cstdint>
#include <vector>

namespace container_test {

inline uint64_t get_le(const std::vector<uint8_t>& b, uint64_t at, int n) {
  uint64_t v = 0;
  for (int i = n - 1; i >= 0; --i) v = (v << 8) | b.at(at + uint64_t(i));
  return v;
}
inline void put_le(std::vector<uint8_t>& b, uint64_t at, int n, uint64_t v) {
  for (int i = 0; i < n; ++i) b.at(at + uint64_t(i)) = uint8_t(v >> (8 * i));
}

}  // namespace container_test
