// Crafted .kanim files for the decoder-obligation tests: a small builder with its own CRC-32
// (not the writer, so that a writer bug cannot hide a loader bug), hand-made zstd frames, and
// CHECK_FAILS (a load that fails with the expected status at the expected offset).
#pragma once
#include "clips.h"

namespace container_test {

inline uint32_t crc32_ref(const uint8_t* p, size_t n) {
  uint32_t crc = 0xFFFFFFFFu;
  for (size_t i = 0; i < n; ++i) {
    crc ^= p[i];
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return crc ^ 0xFFFFFFFFu;
}

template <typename T>
void put(std::vector<uint8_t>& v, T x) {
  // resize + memcpy, not insert from a local array: GCC 12 warns falsely (-Warray-bounds) on
  // the insert once this is inlined into RawFile::build. The test machines are little-endian
  // (checked in roundtrip_test.cpp).
  const size_t at = v.size();
  v.resize(at + sizeof(T));
  std::memcpy(v.data() + at, &x, sizeof(T));
}
template <typename T>
void poke(std::vector<uint8_t>& v, size_t at, T x) {
  std::memcpy(v.data() + at, &x, sizeof(T));
}

struct RawSection {
  std::string tag;
  uint32_t flags = 0;
  std::vector<uint8_t> stored;
  uint64_t raw_size = 0;  // for compressed sections; else stored.size()
};

struct RawFile {
  uint16_t major = 1, minor = 0;
  uint32_t header_flags = 0, reserved = 0;
  std::vector<RawSection> sections;

  // Offset of section i's stored bytes in build().
  size_t data_offset(size_t i) const {
    size_t off = 24 + 24 * sections.size();
    for (size_t k = 0; k < i; ++k) off += sections[k].stored.size();
    return off;
  }
  RawSection& get(const std::string& tag) {
    for (auto& s : sections)
      if (s.tag == tag) return s;
    FAIL("no section " << tag);
    return sections[0];
  }
  size_t offset_of(const std::string& tag) const {
    for (size_t i = 0; i < sections.size(); ++i)
      if (sections[i].tag == tag) return data_offset(i);
    return 0;
  }
  std::vector<uint8_t> build() const {
    std::vector<uint8_t> f = {0x89, 'K', 'A', 'N', 0x0D, 0x0A, 0x1A, 0x0A};
    put(f, major);
    put(f, minor);
    put(f, header_flags);
    put(f, uint32_t(sections.size()));
    put(f, reserved);
    for (const auto& s : sections) {
      f.insert(f.end(), s.tag.begin(), s.tag.begin() + 4);
      put(f, s.flags);
      put(f, uint64_t(s.stored.size()));
      put(f, (s.flags & 1) ? s.raw_size : uint64_t(s.stored.size()));
    }
    for (const auto& s : sections) f.insert(f.end(), s.stored.begin(), s.stored.end());
    put(f, crc32_ref(f.data(), f.size()));
    return f;
  }
};

// Splits a file whose sections are all stored uncompressed (small clips are).
inline RawFile split(const std::vector<uint8_t>& f) {
  RawFile r;
  uint32_t count = 0;
  std::memcpy(&r.major, &f[8], 2);
  std::memcpy(&r.minor, &f[10], 2);
  std::memcpy(&count, &f[16], 4);
  size_t data = 24 + 24 * size_t(count);
  for (uint32_t i = 0; i < count; ++i) {
    RawSection s;
    const uint8_t* e = &f[24 + 24 * i];
    s.tag.assign(reinterpret_cast<const char*>(e), 4);
    std::memcpy(&s.flags, e + 4, 4);
    uint64_t stored = 0;
    std::memcpy(&stored, e + 8, 8);
    std::memcpy(&s.raw_size, e + 16, 8);
    s.stored.assign(f.begin() + long(data), f.begin() + long(data + stored));
    data += stored;
    r.sections.push_back(std::move(s));
  }
  return r;
}

// A zstd frame made by hand (RFC 8878): one raw block. `fcs` < 0: no content size field.
inline std::vector<uint8_t> zstd_raw_frame(const std::vector<uint8_t>& content, int fcs) {
  std::vector<uint8_t> z = {0x28, 0xB5, 0x2F, 0xFD};
  if (fcs < 0) {
    z.push_back(0x00);  // FHD: no FCS, not single segment, no checksum
    z.push_back(0x58);  // Window_Descriptor: exponent 11 -> 2^21 bytes
  } else {
    z.push_back(0x20);  // FHD: single segment, 1-byte FCS
    z.push_back(uint8_t(fcs));
  }
  const uint32_t header = 1u | (0u << 1) | (uint32_t(content.size()) << 3);  // last, raw
  z.push_back(uint8_t(header));
  z.push_back(uint8_t(header >> 8));
  z.push_back(uint8_t(header >> 16));
  z.insert(z.end(), content.begin(), content.end());
  return z;
}

// A zstd frame of `size` bytes of `byte` made of RLE blocks of 128 KiB (4 bytes each): a few
// KB that declare and can produce a large section (a zip bomb's shape).
inline std::vector<uint8_t> zstd_rle_frame(uint64_t size, uint8_t byte) {
  std::vector<uint8_t> z = {0x28, 0xB5, 0x2F, 0xFD, 0xE0};  // FHD: single segment, 8-byte FCS
  for (int k = 0; k < 8; ++k) z.push_back(uint8_t(size >> (8 * k)));
  for (uint64_t done = 0; done < size;) {
    const uint32_t n = uint32_t(std::min<uint64_t>(size - done, 128 * 1024));
    done += n;
    const uint32_t header = (done == size ? 1u : 0u) | (1u << 1) | (n << 3);  // RLE
    z.push_back(uint8_t(header));
    z.push_back(uint8_t(header >> 8));
    z.push_back(uint8_t(header >> 16));
    z.push_back(byte);
  }
  return z;
}

struct Loaded {
  Status status;
  ErrorInfo err;
  Clip clip;
};

inline Loaded load(const std::vector<uint8_t>& bytes, const keyanim::DecodeLimits& limits = {}) {
  Loaded l;
  l.status = Clip::load(bytes, l.clip, &l.err, limits);
  return l;
}

#define CHECK_FAILS(bytes_expr, expected_status, expected_offset)                         \
  do {                                                                                    \
    const Loaded l_ = load(bytes_expr);                                                   \
    CHECK_MESSAGE(l_.status == (expected_status),                                         \
                  keyanim::status_string(l_.status) << " " << l_.err.section << ": " << l_.err.detail); \
    CHECK(l_.err.status == l_.status);                                                    \
    CHECK(l_.err.byte_offset == uint64_t(expected_offset));                               \
    CHECK(!l_.err.detail.empty());                                                        \
    CHECK(l_.clip.channel_count() == 0);                                                  \
  } while (0)

// The small, fully uncompressed file most crafted files start from.
inline RawFile base_file() {
  const auto bytes = keyanim::offline::write_kanim(vector_uniform(), 0);
  RawFile r = split(bytes);
  for (const auto& s : r.sections) REQUIRE((s.flags & 1) == 0);  // crafting needs raw sections
  REQUIRE(r.build() == bytes);  // the builder reproduces the writer byte for byte
  return r;
}

}  // namespace container_test
