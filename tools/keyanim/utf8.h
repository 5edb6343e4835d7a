// Strict UTF-8 decoding, one code point at a time: the base of every escape applied to text
// that comes from inputs (joint names, file names, encoder notes).
#pragma once
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace keyanim::utf8 {

struct CodePoint {
  int32_t value;  // -1: the byte at the position does not start a valid sequence
  size_t length;  // bytes consumed: 1 for an invalid byte
};

// The code point at text[i] (i < text.size()). Overlong forms, surrogates (U+D800..U+DFFF),
// values above U+10FFFF and truncated sequences are invalid, one byte at a time.
inline CodePoint decode(std::string_view text, size_t i) noexcept {
  const auto byte = [&](size_t k) { return i + k < text.size() ? uint8_t(text[i + k]) : 0u; };
  const uint32_t b0 = byte(0);
  if (b0 < 0x80) return {int32_t(b0), 1};
  size_t n;
  uint32_t lo = 0x80, hi = 0xBF, cp;  // range of the second byte
  if (b0 >= 0xC2 && b0 <= 0xDF) n = 2, cp = b0 & 0x1F;
  else if (b0 >= 0xE0 && b0 <= 0xEF) n = 3, cp = b0 & 0x0F, lo = b0 == 0xE0 ? 0xA0 : 0x80, hi = b0 == 0xED ? 0x9F : 0xBF;
  else if (b0 >= 0xF0 && b0 <= 0xF4) n = 4, cp = b0 & 0x07, lo = b0 == 0xF0 ? 0x90 : 0x80, hi = b0 == 0xF4 ? 0x8F : 0xBF;
  else return {-1, 1};
  for (size_t k = 1; k < n; ++k) {
    const uint32_t b = byte(k);
    if (b < (k == 1 ? lo : 0x80) || b > (k == 1 ? hi : 0xBF)) return {-1, 1};
    cp = cp << 6 | (b & 0x3F);
  }
  return {int32_t(cp), n};
}

}  // namespace keyanim::utf8
