// Helpers shared by the fuzz targets: a check that aborts (so libFuzzer and the replay tests
// report it as a crash), and the checksum repair that lets mutated .kanim files reach the
// section parsers instead of stopping at checksum_mismatch.
#pragma once
#include <zlib.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#define FUZZ_CHECK(cond)                                                                  \
  do {                                                                                    \
    if (!(cond)) {                                                                        \
      std::fprintf(stderr, "FUZZ_CHECK failed: %s (%s:%d)\n", #cond, __FILE__, __LINE__); \
      std::abort();                                                                       \
    }                                                                                     \
  } while (0)

namespace keyanim::fuzz {

// The same bytes with the trailing CRC-32 recomputed over everything before it (.kanim files end
// with the CRC-32 of every earlier byte). Inputs shorter than a header are returned unchanged.
inline std::vector<uint8_t> with_fixed_checksum(const uint8_t* data, size_t size) {
  std::vector<uint8_t> out(data, data + size);
  if (size < 28) return out;
  uLong crc = crc32(0L, Z_NULL, 0);
  crc = crc32(crc, out.data(), static_cast<uInt>(size - 4));
  const uint32_t c = static_cast<uint32_t>(crc);
  for (int i = 0; i < 4; ++i) out[size - 4 + static_cast<size_t>(i)] = static_cast<uint8_t>(c >> (8 * i));
  return out;
}

// Bit-exact float equality that also treats any two NaNs as equal.
inline bool same_float(float a, float b) {
  if (a != a && b != b) return true;
  uint32_t x, y;
  std::memcpy(&x, &a, 4);
  std::memcpy(&y, &b, 4);
  return x == y;
}

inline bool same_double(double a, double b) {
  uint64_t x, y;
  std::memcpy(&x, &a, 8);
  std::memcpy(&y, &b, 8);
  return x == y;
}

}  // namespace keyanim::fuzz
