// Helpers shared by the fuzz targets: a check that aborts (so libFuzzer and the replay tests
// report it as a crash), and the checksum repair that lets mutated .kanim files reach the
// section parsers instead of stopping at checksum_mismatch.
#pragma once
#include <zlib.h>
#define XXH_INLINE_ALL  // xxHash compiled in, as the library does (no libxxhash to link)
#include <xxhash.h>

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

// Whether the bytes are a runtime-profile file (spec/FORMAT.md section 9): Major_Version >= 4
// and Header_Flags bit 0.
inline bool is_runtime_profile(const uint8_t* data, size_t size) {
  if (size < 24) return false;
  const uint32_t major = uint32_t(data[8]) | uint32_t(data[9]) << 8;
  return major >= 4 && (data[12] & 1u) != 0;
}

// The checksum at the end recomputed over every earlier byte, in place: the XXH64 (seed 0) of
// the last 8 bytes of a runtime-profile file (section 9.1), else the CRC-32 of the last 4
// (.kanim archive files). Inputs shorter than a header and its checksum are left unchanged.
inline void fix_checksum(uint8_t* p, size_t size) {
  if (is_runtime_profile(p, size)) {
    if (size < 32) return;
    const uint64_t h = XXH64(p, size - 8, 0);
    for (int i = 0; i < 8; ++i) p[size - 8 + static_cast<size_t>(i)] = static_cast<uint8_t>(h >> (8 * i));
    return;
  }
  if (size < 28) return;
  uLong crc = crc32(0L, Z_NULL, 0);
  crc = crc32(crc, p, static_cast<uInt>(size - 4));
  const uint32_t c = static_cast<uint32_t>(crc);
  for (int i = 0; i < 4; ++i) p[size - 4 + static_cast<size_t>(i)] = static_cast<uint8_t>(c >> (8 * i));
}

// A copy of the bytes with their checksum recomputed (fix_checksum).
inline std::vector<uint8_t> with_fixed_checksum(const uint8_t* data, size_t size) {
  std::vector<uint8_t> out(data, data + size);
  fix_checksum(out.data(), size);
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
