// An upper bound on what a zstd frame can decompress to, read from its block headers
// (RFC 8878, section 3.1.1). The frame header's Frame_Content_Size is only a claim: a 60-byte
// file may declare a gigabyte. Each block, though, can produce at most its own size (Raw),
// its Block_Size (RLE, from one byte) or 128 KiB (Compressed), so the sum of those is a bound
// that costs the attacker bytes. The loader allocates only after Raw_Size passes this bound.
#pragma once
#include <cstddef>
#include <cstdint>
#include <optional>

namespace keyanim::internal {

// Returns nullopt when the headers do not describe one complete frame within `size` bytes.
inline std::optional<uint64_t> zstd_frame_output_bound(const uint8_t* p, size_t size) noexcept {
  constexpr uint64_t kBlockSizeMax = 128u * 1024u;
  if (size < 5) return std::nullopt;  // magic + descriptor
  const uint8_t descriptor = p[4];
  const unsigned fcs_flag = descriptor >> 6;
  const bool single_segment = (descriptor >> 5) & 1u;
  const unsigned dict_flag = descriptor & 3u;
  static constexpr size_t kDictBytes[4] = {0, 1, 2, 4};
  static constexpr size_t kFcsBytes[4] = {0, 2, 4, 8};
  const size_t fcs_bytes = (fcs_flag == 0 && single_segment) ? 1 : kFcsBytes[fcs_flag];
  size_t pos = 5 + (single_segment ? 0 : 1) + kDictBytes[dict_flag] + fcs_bytes;
  uint64_t bound = 0;
  for (;;) {
    if (pos > size || size - pos < 3) return std::nullopt;
    const uint32_t header = uint32_t(p[pos]) | uint32_t(p[pos + 1]) << 8 | uint32_t(p[pos + 2]) << 16;
    pos += 3;
    const bool last = header & 1u;
    const unsigned type = (header >> 1) & 3u;
    const uint32_t block_size = header >> 3;
    // No valid block produces more than Block_Maximum_Size <= 128 KiB; zstd rejects the others.
    const uint64_t produced = block_size < kBlockSizeMax ? block_size : kBlockSizeMax;
    size_t content = 0;
    switch (type) {
      case 0: content = block_size; bound += produced; break;       // Raw
      case 1: content = 1; bound += produced; break;                // RLE
      case 2: content = block_size; bound += kBlockSizeMax; break;  // Compressed
      default: return std::nullopt;                                 // Reserved
    }
    if (size - pos < content) return std::nullopt;
    pos += content;
    if (last) return bound;
  }
}

}  // namespace keyanim::internal
