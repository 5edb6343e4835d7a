// LEB128 varints and zigzag (spec/FORMAT.md section 6). Decoding rejects over-long encodings,
// so every value has exactly one encoding and a file has one meaning.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

namespace keyanim::internal {

inline void put_varint(std::vector<uint8_t>& out, uint64_t v) {
  while (v >= 0x80) {
    out.push_back(static_cast<uint8_t>(v | 0x80));
    v >>= 7;
  }
  out.push_back(static_cast<uint8_t>(v));
}

// Bytes put_varint writes for v.
inline size_t varint_size(uint64_t v) noexcept {
  size_t n = 1;
  for (; v >= 0x80; v >>= 7) ++n;
  return n;
}

inline uint64_t zigzag_encode(int64_t d) noexcept {
  return (static_cast<uint64_t>(d) << 1) ^ static_cast<uint64_t>(d >> 63);
}
inline int64_t zigzag_decode(uint64_t u) noexcept {
  return static_cast<int64_t>(u >> 1) ^ -static_cast<int64_t>(u & 1);
}

enum class VarintError : uint8_t { none, cut, overlong, too_big };

// Decodes one varint of at most `max_bytes` bytes from p[pos..size) and advances pos. For
// max_bytes = 5 the value must fit 32 bits, for 10 it must fit 64 bits.
inline VarintError get_varint(const uint8_t* p, size_t size, size_t& pos, uint32_t max_bytes,
                              uint64_t& out) noexcept {
  uint64_t v = 0;
  for (uint32_t i = 0; i < max_bytes; ++i) {
    if (pos + i >= size) return VarintError::cut;
    const uint8_t b = p[pos + i];
    const uint32_t shift = 7 * i;
    const uint64_t bits = b & 0x7Fu;
    if (i + 1 == max_bytes) {
      // Last allowed byte: no continuation, and no bits beyond the value's width.
      const uint32_t width = max_bytes == 5 ? 32 : 64;
      if ((b & 0x80u) || (bits >> (width - shift)) != 0) return VarintError::too_big;
    }
    v |= bits << shift;
    if (!(b & 0x80u)) {
      if (b == 0 && i > 0) return VarintError::overlong;
      pos += i + 1;
      out = v;
      return VarintError::none;
    }
  }
  return VarintError::too_big;
}

}  // namespace keyanim::internal
