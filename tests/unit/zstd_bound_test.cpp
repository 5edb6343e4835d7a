// The loader's zip-bomb guard must never refuse a frame zstd itself produced: its bound has to
// cover the real content of every frame, whatever block types zstd chose.
#include <doctest/doctest.h>
#include <zstd.h>

#include <cstdint>
#include <random>
#include <vector>

#include "internal/zstd_bound.h"

namespace {

std::vector<uint8_t> compress(const std::vector<uint8_t>& in, int level) {
  std::vector<uint8_t> out(ZSTD_compressBound(in.size()));
  const size_t n = ZSTD_compress(out.data(), out.size(), in.data(), in.size(), level);
  REQUIRE(!ZSTD_isError(n));
  out.resize(n);
  return out;
}

}  // namespace

TEST_CASE("zstd output bound covers the content of real frames") {
  std::mt19937 rng(7);
  for (size_t size : {size_t(0), size_t(1), size_t(1000), size_t(131072), size_t(131073), size_t(1) << 20}) {
    std::vector<uint8_t> zeros(size, 0), noise(size), text(size);
    for (auto& b : noise) b = uint8_t(rng());
    for (size_t i = 0; i < size; ++i) text[i] = uint8_t("JOINT Hips OFFSET 0.0 {\n"[i % 24] ^ ((i / 4096) & 1));
    for (const auto* data : {&zeros, &noise, &text}) {
      for (int level : {1, 19}) {
        CAPTURE(size);
        CAPTURE(level);
        const std::vector<uint8_t> frame = compress(*data, level);
        const auto bound = keyanim::internal::zstd_frame_output_bound(frame.data(), frame.size());
        REQUIRE(bound.has_value());
        CHECK(*bound >= size);
        // Cut frames are not one complete frame.
        if (frame.size() > 8)
          CHECK_FALSE(keyanim::internal::zstd_frame_output_bound(frame.data(), frame.size() - 1).has_value());
      }
    }
  }
}

TEST_CASE("zstd output bound of a hand-made RLE frame is its block size") {
  // Magic, descriptor 0x20 (single segment, 1-byte content size 100), one last RLE block of 100.
  const uint32_t block = 1u | (1u << 1) | (100u << 3);
  const std::vector<uint8_t> frame = {0x28, 0xB5, 0x2F, 0xFD, 0x20, 100, uint8_t(block), uint8_t(block >> 8),
                                      uint8_t(block >> 16), 'x'};
  const auto bound = keyanim::internal::zstd_frame_output_bound(frame.data(), frame.size());
  REQUIRE(bound.has_value());
  CHECK(*bound == 100);
  std::vector<char> out(100);
  CHECK(ZSTD_decompress(out.data(), out.size(), frame.data(), frame.size()) == 100);  // zstd agrees it is valid
}
