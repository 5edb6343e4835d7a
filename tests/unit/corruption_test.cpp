// Damaged inputs: every single-byte change, every truncation and appended garbage of committed
// .kanim files must be refused by Clip::load (spec/FORMAT.md section 7: the table checks, then
// the CRC-32, which detects every error confined to one byte); crafted files declaring huge
// counts must be refused before anything large is allocated; truncated and token-damaged BVH
// text must be refused with a line and column inside the text, or read consistently.
//
// Expected statuses follow from the spec's check order alone, not from running the loader:
// a byte changed after the table can only be caught by the checksum; a prefix of a valid file is
// `truncated`; bytes after the checksum are `trailing_bytes`.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <new>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "keyanim/clip.h"
#include "clip_reference.h"
#include "keyanim/version.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/encode.h"
#include "internal/xxh64.h"

// ---------------------------------------------------------------------------------------------
// Allocation probe: the largest single allocation while `g_probe_on` is set. Under
// AddressSanitizer its allocator hooks see every allocation; otherwise a replaced operator new
// does (weak, so that another test file replacing operator new wins: the probe then reports
// itself inactive through probe_works(), and the tests that need it say so instead of passing).
namespace {
std::atomic<bool> g_probe_on{false};
std::atomic<size_t> g_probe_max{0};

void probe_record(size_t n) {
  if (!g_probe_on.load(std::memory_order_relaxed)) return;
  size_t m = g_probe_max.load(std::memory_order_relaxed);
  while (n > m && !g_probe_max.compare_exchange_weak(m, n)) {
  }
}
}  // namespace

#if defined(__SANITIZE_ADDRESS__)
#define KEYANIM_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define KEYANIM_TEST_ASAN 1
#endif
#endif

#ifdef KEYANIM_TEST_ASAN
// From <sanitizer/allocator_interface.h>, which GCC does not ship; both runtimes export it.
extern "C" int __sanitizer_install_malloc_and_free_hooks(void (*malloc_hook)(const volatile void*, size_t),
                                                         void (*free_hook)(const volatile void*));
namespace {
void probe_malloc_hook(const volatile void*, size_t n) { probe_record(n); }
void probe_free_hook(const volatile void*) {}
const bool g_hooks_installed = __sanitizer_install_malloc_and_free_hooks(probe_malloc_hook, probe_free_hook) != 0;
}  // namespace
#else
__attribute__((weak)) void* operator new(std::size_t n) {
  probe_record(n);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
__attribute__((weak)) void operator delete(void* p) noexcept { std::free(p); }
__attribute__((weak)) void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#endif

namespace {

using keyanim::Clip;
using keyanim::DecodeLimits;
using keyanim::ErrorInfo;
using keyanim::Status;

struct Probe {
  Probe() {
    g_probe_max = 0;
    g_probe_on = true;
  }
  ~Probe() { g_probe_on = false; }
  size_t largest() const { return g_probe_max.load(); }
};

bool probe_works() {
  Probe p;
  std::vector<uint8_t>* v = new std::vector<uint8_t>(123457);
  const bool seen = p.largest() >= 123457;
  delete v;
  return seen;
}

std::vector<uint8_t> read_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  REQUIRE_MESSAGE(in.good(), "cannot open " << p.string());
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Independent CRC-32 (ISO-HDLC, bitwise): the spec's check value is crc("123456789") = CBF43926.
uint32_t crc32_of(const uint8_t* p, size_t n) {
  uint32_t c = 0xFFFFFFFFu;
  for (size_t i = 0; i < n; ++i) {
    c ^= p[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  return ~c;
}

void put_u16(std::vector<uint8_t>& b, uint16_t v) {
  for (int i = 0; i < 2; ++i) b.push_back(uint8_t(v >> (8 * i)));
}
void put_u32(std::vector<uint8_t>& b, uint32_t v) {
  for (int i = 0; i < 4; ++i) b.push_back(uint8_t(v >> (8 * i)));
}
void put_u64(std::vector<uint8_t>& b, uint64_t v) {
  for (int i = 0; i < 8; ++i) b.push_back(uint8_t(v >> (8 * i)));
}
void put_f64(std::vector<uint8_t>& b, double d) {
  uint64_t v;
  std::memcpy(&v, &d, 8);
  put_u64(b, v);
}

// The checksum of spec 3.3, or of 9.1 (XXH64, 8 bytes) for a runtime-profile file (version 4,
// Header_Flags bit 0).
void fix_checksum(std::vector<uint8_t>& f) {
  if (f.size() >= 24 && (f[8] == 4 || f[8] == 5) && f[9] == 0 && (f[12] & 1)) {  // the runtime profile's XXH64
    const uint64_t x = keyanim::internal::xxh64_of(f.data(), f.size() - 8);
    for (int i = 0; i < 8; ++i) f[f.size() - 8 + size_t(i)] = uint8_t(x >> (8 * i));
    return;
  }
  const uint32_t c = crc32_of(f.data(), f.size() - 4);
  for (int i = 0; i < 4; ++i) f[f.size() - 4 + size_t(i)] = uint8_t(c >> (8 * i));
}

// Offset where the sections start: 24 + 24 x Section_Count (spec 3.1).
size_t table_end(const std::vector<uint8_t>& f) {
  uint32_t count = 0;
  for (int i = 0; i < 4; ++i) count |= uint32_t(f[16 + size_t(i)]) << (8 * i);
  return 24 + 24 * size_t(count);
}

struct Section {
  const char* tag;
  uint32_t flags;  // bit 0 compressed, bit 1 ancillary
  std::vector<uint8_t> stored;
  uint64_t raw;    // Raw_Size as declared
};

// A whole file from sections, by the spec's layout (section 1), with a correct CRC-32.
std::vector<uint8_t> build_file(const std::vector<Section>& sections) {
  std::vector<uint8_t> f = {0x89, 'K', 'A', 'N', 0x0D, 0x0A, 0x1A, 0x0A};
  put_u16(f, 1);
  put_u16(f, 0);
  put_u32(f, 0);
  put_u32(f, uint32_t(sections.size()));
  put_u32(f, 0);
  for (const Section& s : sections) {
    f.insert(f.end(), s.tag, s.tag + 4);
    put_u32(f, s.flags);
    put_u64(f, s.stored.size());
    put_u64(f, s.raw);
  }
  for (const Section& s : sections) f.insert(f.end(), s.stored.begin(), s.stored.end());
  put_u32(f, 0);
  fix_checksum(f);
  return f;
}

Section raw_section(const char* tag, std::vector<uint8_t> bytes) {
  const uint64_t n = bytes.size();
  return Section{tag, 0, std::move(bytes), n};
}

std::vector<uint8_t> clip_section(uint32_t frames, uint32_t nodes, uint32_t channels, uint64_t keys) {
  std::vector<uint8_t> b;
  put_u32(b, frames);
  put_u32(b, nodes);
  put_u32(b, channels);
  b.push_back(1);  // step_adjusted
  b.push_back(0);
  put_u16(b, 0);
  put_f64(b, 1.0 / 120.0);
  put_u64(b, keys);
  return b;
}

// A chain of `nodes` nodes (each the parent of the next) with `channels` (<= 6) channels each.
std::vector<uint8_t> skel_chain(uint32_t nodes, uint8_t channels) {
  std::vector<uint8_t> b;
  for (uint32_t i = 0; i < nodes; ++i) {
    put_u32(b, 1);
    b.push_back('j');
    put_u32(b, i == 0 ? 0xFFFFFFFFu : i - 1);  // parent
    for (int k = 0; k < 3; ++k) put_f64(b, 1.0);
    b.push_back(0);
    b.push_back(channels);
    for (uint8_t c = 0; c < channels; ++c) b.push_back(c);
  }
  return b;
}

// CHAN for channels with the given key counts: cardinal, tension 0, step 1.
std::vector<uint8_t> chan_section(const std::vector<uint32_t>& key_counts) {
  std::vector<uint8_t> b(key_counts.size(), 0);
  for (size_t c = 0; c < key_counts.size(); ++c) put_u32(b, 0);  // f32 0.0
  for (size_t c = 0; c < key_counts.size(); ++c) put_f64(b, 1.0);
  for (uint32_t n : key_counts) put_u32(b, n);
  return b;
}

// Loads `f` expecting failure; returns the status. The clip must come back empty and the error
// must point inside the file.
Status load_fails(const std::vector<uint8_t>& f, const DecodeLimits& limits = {}) {
  Clip clip;
  ErrorInfo err;
  const Status s = Clip::load(f, clip, &err, limits);
  CHECK(s != Status::ok);
  CHECK(err.status == s);
  CHECK(err.byte_offset <= f.size());
  CHECK(clip.channel_count() == 0);
  CHECK(clip.total_keys() == 0);
  CHECK(clip.memory_bytes() == Clip{}.memory_bytes());
  return s;
}

std::vector<std::filesystem::path> test_vectors() {
  std::vector<std::filesystem::path> v;
  for (const auto& e : std::filesystem::directory_iterator(KEYANIM_SPEC_DIR "/test-vectors"))
    if (e.path().extension() == ".kanim") v.push_back(e.path());
  std::sort(v.begin(), v.end());
  return v;
}

// The byte positions the loops below damage (or cut a file at): all of a small file; of a large one (v4_blocks,
// 245 KB of runtime profile) the first 2 KB (header, table, IMAG's header and first arrays),
// the last 64 bytes and every 251st byte between, so that a loop stays linear, not quadratic, in
// the vectors' bytes (fuzz_view covers the runtime profile's bytes at random).
bool damaged_position(size_t i, size_t size) {
  return size <= 16384 || i < 2048 || i + 64 >= size || i % 251 == 0;
}

// The walk clip of data/, encoded with the default settings.
const std::vector<uint8_t>& walk_kanim() {
  static const std::vector<uint8_t> bytes = [] {
    const keyanim::offline::Motion m = keyanim::offline::read_bvh_file(KEYANIM_REPO_DATA_DIR "/cmu_02_01_walk.bvh");
    return keyanim::offline::write_kanim(keyanim::offline::encode(m, {}).clip);
  }();
  return bytes;
}

// Every change of byte i to each value in `values` (XOR masks): refused, and after the table
// refused by the checksum.
void check_flips(const std::vector<uint8_t>& file, size_t i, std::initializer_list<uint8_t> masks) {
  std::vector<uint8_t> f = file;
  const size_t sections_at = table_end(file);
  for (uint8_t m : masks) {
    f[i] ^= m;
    const Status s = load_fails(f);
    if (i >= sections_at) CHECK_MESSAGE(s == Status::checksum_mismatch, "byte " << i << " ^ " << int(m));
    f[i] ^= m;
  }
}

}  // namespace

TEST_SUITE("corruption") {

TEST_CASE("the allocation probe and the CRC-32 of the spec's check value") {
  CHECK(crc32_of(reinterpret_cast<const uint8_t*>("123456789"), 9) == 0xCBF43926u);
  if (!probe_works()) MESSAGE("operator new is replaced elsewhere: allocation sizes are not checked here");
}

TEST_CASE("test vectors: byte changes are refused") {
  // Every value of every byte of the header, the table, the first 32 bytes of the sections and
  // the checksum; every single-bit change and the complement of every other byte.
  for (const auto& path : test_vectors()) {
    const std::vector<uint8_t> file = read_bytes(path);
    INFO(path.filename().string());
    {
      Clip clip;
      REQUIRE(Clip::load(file, clip) == Status::ok);
    }
    std::vector<uint8_t> f = file;
    const size_t sections_at = table_end(file);
    static const int kBits[] = {0x01, 0x02, 0x04, 0x08, 0x10, 0x20, 0x40, 0x80, 0xFF};
    for (size_t i = 0; i < f.size(); ++i) {
      if (!damaged_position(i, f.size())) continue;
      const bool every = i < sections_at + 32 || i + 8 >= f.size();
      for (int k = 0; k < (every ? 255 : 9); ++k) {
        const int m = every ? k + 1 : kBits[k];
        f[i] = uint8_t(file[i] ^ m);
        Clip clip;
        const Status s = Clip::load(f, clip);
        if (s == Status::ok || (i >= sections_at && s != Status::checksum_mismatch)) {
          FAIL_CHECK("byte " << i << " ^ " << m << ": " << keyanim::status_string(s));
        }
        if (clip.channel_count() != 0) FAIL_CHECK("a failed load left a clip");
      }
      f[i] = file[i];
    }
  }
}

TEST_CASE("test vectors: every truncation and appended bytes") {
  for (const auto& path : test_vectors()) {
    const std::vector<uint8_t> file = read_bytes(path);
    INFO(path.filename().string());
    for (size_t n = 0; n < file.size(); ++n) {
      if (!damaged_position(n, file.size())) continue;  // every length of a small file
      const std::vector<uint8_t> cut(file.begin(), file.begin() + std::ptrdiff_t(n));
      CHECK_MESSAGE(load_fails(cut) == Status::truncated, "length " << n);
    }
    std::mt19937 rng(7);
    for (size_t extra : {1, 2, 3, 4, 5, 17, 64, 1000}) {
      std::vector<uint8_t> f = file;
      for (size_t k = 0; k < extra; ++k) f.push_back(uint8_t(rng()));
      CHECK_MESSAGE(load_fails(f) == Status::trailing_bytes, extra << " bytes appended");
      std::vector<uint8_t> zeros = file;
      zeros.resize(file.size() + extra, 0);
      CHECK(load_fails(zeros) == Status::trailing_bytes);
    }
    std::vector<uint8_t> twice = file;
    twice.insert(twice.end(), file.begin(), file.end());
    CHECK(load_fails(twice) == Status::trailing_bytes);
  }
}

TEST_CASE("test vectors: versions") {
  for (const auto& path : test_vectors()) {
    INFO(path.filename().string());
    std::vector<uint8_t> f = read_bytes(path);
    const uint8_t major = f[8];
    f[8] = uint8_t(keyanim::kNewestFormatVersionMajor + 1);  // a later major: refused whatever the checksum says
    CHECK(load_fails(f) == Status::unsupported_version);
    fix_checksum(f);
    CHECK(load_fails(f) == Status::unsupported_version);
    f[8] = 0;
    fix_checksum(f);
    CHECK(load_fails(f) == Status::unsupported_version);
    f[8] = major;
    f[10] = 7;  // Minor_Version 7: an x.y decoder accepts any minor version of its major
    fix_checksum(f);
    Clip clip;
    CHECK(Clip::load(f, clip) == Status::ok);
    CHECK(clip.version_minor() == 7);
  }
}

TEST_CASE("test vectors: damage behind a repaired checksum never crashes") {
  // With the CRC-32 recomputed, the section parsers see the damage. Any status may come back
  // (a change may even leave the file valid), but a clip that loads keeps the sampler's rules.
  for (const auto& path : test_vectors()) {
    const std::vector<uint8_t> file = read_bytes(path);
    INFO(path.filename().string());
    std::vector<uint8_t> f = file;
    size_t loaded = 0;
    // A runtime-profile file's content rules are checked too, so that a clip that loads holds
    // keys as the spec defines them (without them, view() samples whatever the records say).
    keyanim::DecodeLimits limits;
    limits.check_content = true;
    for (size_t i = 0; i + 4 < f.size(); ++i) {
      if (!damaged_position(i, f.size())) continue;
      for (int m : {0x01, 0x02, 0x10, 0x80, 0xFF}) {
        f[i] = uint8_t(file[i] ^ m);
        fix_checksum(f);
        Clip clip;
        if (Clip::load(f, clip, nullptr, limits) != Status::ok) continue;
        ++loaded;
        for (uint32_t c = 0; c < clip.channel_count(); ++c) {
          const keyanim::test::ChannelKeys keys = keyanim::test::channel_keys(clip, c);
          REQUIRE(keys.frames.size() == clip.channel(c).key_count);
          for (size_t k = 0; k < keys.frames.size(); ++k) {
            REQUIRE(keys.frames[k] < clip.frame_count());
            if (k > 0) REQUIRE(keys.frames[k] > keys.frames[k - 1]);
            REQUIRE(std::isfinite(keys.values[k]));
          }
        }
        std::vector<float> pose(clip.channel_count());
        CHECK(clip.sample(0.5, pose) == Status::ok);
      }
      f[i] = file[i];
    }
    MESSAGE(path.filename().string() << ": " << loaded << " damaged files still valid");
  }
}

TEST_CASE("an encoded CMU walk: flips, truncations, appended bytes") {
  const std::vector<uint8_t>& file = walk_kanim();
  REQUIRE(file.size() > 1000);
  {
    Clip clip;
    REQUIRE(Clip::load(file, clip) == Status::ok);
  }
  const size_t sections_at = table_end(file);
  // Header and table: every value of every byte; the rest: two changes per byte, and every
  // single-bit change of every 61st byte (the checksum must catch each).
  for (size_t i = 0; i < file.size(); ++i) {
    if (i < sections_at) {
      std::vector<uint8_t> f = file;
      for (int m = 1; m < 256; ++m) {
        f[i] = uint8_t(file[i] ^ m);
        Clip clip;
        if (Clip::load(f, clip) == Status::ok) FAIL_CHECK("byte " << i << " ^ " << m << " loads");
      }
    } else if (i % 61 == 0) {
      check_flips(file, i, {0x01, 0x02, 0x04, 0x08, 0x10, 0x20, 0x40, 0x80, 0xFF});
    } else {
      check_flips(file, i, {0x01, 0xFF});
    }
  }
  // Truncations: every length in the header, table and first section, then a stride.
  for (size_t n = 0; n < file.size(); n += (n < sections_at + 200 ? 1 : 13)) {
    const std::vector<uint8_t> cut(file.begin(), file.begin() + std::ptrdiff_t(n));
    CHECK_MESSAGE(load_fails(cut) == Status::truncated, "length " << n);
  }
  for (size_t n = file.size() - 8; n < file.size(); ++n) {
    const std::vector<uint8_t> cut(file.begin(), file.begin() + std::ptrdiff_t(n));
    CHECK(load_fails(cut) == Status::truncated);
  }
  std::vector<uint8_t> f = file;
  f.push_back(0);
  CHECK(load_fails(f) == Status::trailing_bytes);
}

TEST_CASE("crafted counts are refused before any large allocation") {
  const bool probing = probe_works();
  struct Case {
    const char* what;
    std::vector<Section> sections;
    DecodeLimits limits;
    std::vector<Status> allowed;
  };
  const std::vector<uint8_t> skel = skel_chain(1, 3);
  const std::vector<uint8_t> chan3 = chan_section({0, 0, 0});
  auto five = [&](std::vector<uint8_t> clip, std::vector<uint8_t> sk, std::vector<uint8_t> ch, std::vector<uint8_t> kt,
                  std::vector<uint8_t> kv) {
    return std::vector<Section>{raw_section("CLIP", std::move(clip)), raw_section("SKEL", std::move(sk)),
                                raw_section("CHAN", std::move(ch)), raw_section("KTIM", std::move(kt)),
                                raw_section("KVAL", std::move(kv))};
  };
  DecodeLimits small;
  small.max_frames = 1000;
  small.max_joints = 100;
  small.max_channels = 600;
  small.max_keys = 10000;
  small.max_decompressed_bytes = 1 << 20;

  std::vector<Case> cases;
  // At the default limits exactly: 2^24 frames, 2^18 channels, 2^28 keys, 1 node of 3 channels.
  cases.push_back({"huge counts, tiny sections", five(clip_section(1u << 24, 1, 1u << 18, 1ull << 28), skel, chan3, {0}, {0}),
                   {}, {Status::corrupt}});
  cases.push_back({"2^16 nodes in a 40-byte SKEL", five(clip_section(1u << 24, 1u << 16, 3, 3), skel, chan3, {0}, {0}),
                   {}, {Status::corrupt}});
  {
    // 18 channels, 16 of them with 2^24 keys: a consistent CLIP, SKEL and CHAN declaring 2^28
    // keys, whose KTIM and KVAL hold one byte each.
    std::vector<uint32_t> counts(18, 1u << 24);
    counts[16] = counts[17] = 0;
    cases.push_back({"2^28 keys in a 1-byte KTIM", five(clip_section(1u << 24, 3, 18, 1ull << 28), skel_chain(3, 6),
                                                        chan_section(counts), {0}, {0}),
                     {}, {Status::corrupt}});
  }
  cases.push_back({"beyond the default limits", five(clip_section(UINT32_MAX, UINT32_MAX, UINT32_MAX, UINT64_MAX), skel,
                                                     chan3, {0}, {0}),
                   {}, {Status::limit_exceeded}});
  cases.push_back({"frames above a small limit", five(clip_section(1u << 24, 1, 3, 3), skel, chan3, {0}, {0}), small,
                   {Status::limit_exceeded}});
  cases.push_back({"channels above a small limit", five(clip_section(10, 1, 1u << 18, 3), skel, chan3, {0}, {0}), small,
                   {Status::limit_exceeded}});
  cases.push_back({"keys above a small limit", five(clip_section(10, 1, 3, 1ull << 28), skel, chan3, {0}, {0}), small,
                   {Status::limit_exceeded, Status::corrupt}});
  cases.push_back({"nodes above a small limit", five(clip_section(10, 1u << 16, 3, 3), skel, chan3, {0}, {0}), small,
                   {Status::limit_exceeded}});
  {
    // Raw_Size of 2^40 and 1 GiB + 1 for 8 stored bytes: refused by the raw-size limit before
    // any decompression.
    auto s = five(clip_section(10, 1, 3, 0), skel, chan3, {}, {});
    s[1].flags = 1;
    s[1].raw = 1ull << 40;
    cases.push_back({"Raw_Size 2^40", s, {}, {Status::limit_exceeded}});
    s[1].raw = (1ull << 30) + 1;
    cases.push_back({"Raw_Size above 1 GiB", s, {}, {Status::limit_exceeded}});
    s[1].raw = 1ull << 20;
    cases.push_back({"Raw_Size above a small limit", s, small, {Status::limit_exceeded}});
  }
  {
    // A section table of 2^32 - 1 entries in a 60-byte file.
    std::vector<uint8_t> f = build_file({});
    f[16] = f[17] = f[18] = f[19] = 0xFF;
    fix_checksum(f);
    Probe p;
    CHECK(load_fails(f) == Status::truncated);
    if (probing) CHECK(p.largest() < 4096);
  }
  for (const Case& c : cases) {
    INFO(c.what);
    const std::vector<uint8_t> f = build_file(c.sections);
    Probe p;
    const Status s = load_fails(f, c.limits);
    bool allowed = false;
    for (Status a : c.allowed) allowed = allowed || s == a;
    CHECK_MESSAGE(allowed, "status " << keyanim::status_string(s));
    // Nothing larger than a few times the file (the small vectors of the loader itself).
    if (probing) CHECK_MESSAGE(p.largest() < 4096, "largest allocation " << p.largest() << " bytes");
  }
}

// A zstd frame header may declare any content size; the loader must not allocate it before
// the frame's blocks show they can produce it (internal/zstd_bound.h).
TEST_CASE("a tiny zstd frame declaring a 1 GiB section is refused without a large allocation") {
  const bool probing = probe_works();
  // RFC 8878 frame: magic, descriptor 0xA0 (single segment, 4-byte content size), the content
  // size, then one last RLE block of 100 bytes of 'x' (block header: last 1, type 1, size 100).
  const uint64_t declared = (1ull << 30) - 1024;
  std::vector<uint8_t> frame = {0x28, 0xB5, 0x2F, 0xFD, 0xA0};
  put_u32(frame, uint32_t(declared));
  const uint32_t block = 1u | (1u << 1) | (100u << 3);
  frame.insert(frame.end(), {uint8_t(block), uint8_t(block >> 8), uint8_t(block >> 16), 'x'});
  std::vector<Section> s = {raw_section("CLIP", clip_section(10, 1, 3, 0)), Section{"SKEL", 1, frame, declared},
                            raw_section("CHAN", chan_section({0, 0, 0})), raw_section("KTIM", {}),
                            raw_section("KVAL", {})};
  const std::vector<uint8_t> f = build_file(s);
  Probe p;
  CHECK(load_fails(f) == Status::zstd_error);
  if (probing) CHECK_MESSAGE(p.largest() < 4096, "largest allocation " << p.largest() << " bytes");
}

TEST_CASE("BVH: every truncation of a fixture") {
  using namespace keyanim::offline;
  for (const char* name : {"mixed_rotation_orders.bvh", "crlf.bvh", "lone_cr.bvh", "names_with_spaces_colons.bvh"}) {
    INFO(name);
    const std::vector<uint8_t> bytes = read_bytes(std::filesystem::path(KEYANIM_TEST_DATA_DIR) / "bvh" / name);
    const std::string text(bytes.begin(), bytes.end());
    const Motion full = read_bvh(text, name);
    for (size_t n = 0; n < text.size(); ++n) {
      const std::string prefix = text.substr(0, n);
      uint32_t line = 0, column = 0;
      try {
        const Motion m = read_bvh(prefix, name);
        // Only a cut inside the last motion line's last number (or its line end) can read.
        CHECK_MESSAGE(m.frame_count == full.frame_count, "length " << n);
        CHECK(m.skeleton.joints.size() == full.skeleton.joints.size());
        continue;
      } catch (const Error& e) {
        line = e.line(), column = e.column();
      }
      // The error is at a line and column of the prefix: count its lines as the reader does.
      uint32_t lines = 1;
      size_t last_start = 0;
      for (size_t i = 0; i < prefix.size(); ++i) {
        if (prefix[i] == '\r' && i + 1 < prefix.size() && prefix[i + 1] == '\n') ++i;
        if (prefix[i] == '\n' || prefix[i] == '\r') ++lines, last_start = i + 1;
      }
      CHECK_MESSAGE(line >= 1, "length " << n);
      CHECK_MESSAGE(line <= lines, "length " << n << ": line " << line);
      CHECK(column >= 1);
      if (line == lines) CHECK_MESSAGE(column <= prefix.size() - last_start + 1, "length " << n);
    }
  }
}

TEST_CASE("BVH: random token damage") {
  using namespace keyanim::offline;
  const std::string kTokens[] = {"{", "}", "ROOT", "JOINT", "End", "Site", "OFFSET", "CHANNELS", "6", "3",
                                 "0", "-1", "1e999", "nan", "inf", "Xrotation", "Zposition", "MOTION",
                                 "Frames:", "Frame", "Time:", "\n", "\r", "\t", "x", "+", ".", "1e-400",
                                 "99999999999999999999", std::string("\0", 1)};
  std::mt19937 rng(20261122);
  size_t valid = 0, invalid = 0;
  for (const char* name : {"mixed_rotation_orders.bvh", "multi_root.bvh", "six_channels_all_joints.bvh",
                           "names_with_spaces_colons.bvh", "tabs.bvh"}) {
    INFO(name);
    const std::vector<uint8_t> bytes = read_bytes(std::filesystem::path(KEYANIM_TEST_DATA_DIR) / "bvh" / name);
    const std::string text(bytes.begin(), bytes.end());
    // Token boundaries: [start, end) of every run of non-blank bytes.
    std::vector<std::pair<size_t, size_t>> tokens;
    for (size_t i = 0; i < text.size();) {
      while (i < text.size() && std::isspace(uint8_t(text[i]))) ++i;
      const size_t s = i;
      while (i < text.size() && !std::isspace(uint8_t(text[i]))) ++i;
      if (i > s) tokens.emplace_back(s, i);
    }
    REQUIRE(tokens.size() > 10);
    for (int trial = 0; trial < 1500; ++trial) {
      std::string t = text;
      // One to three damages, applied from the end so that earlier boundaries stay valid.
      const int count = 1 + int(rng() % 3);
      std::vector<size_t> picks;
      for (int k = 0; k < count; ++k) picks.push_back(rng() % tokens.size());
      std::sort(picks.rbegin(), picks.rend());
      for (size_t k : picks) {
        const auto [s, e] = tokens[k];
        const std::string& other = kTokens[rng() % std::size(kTokens)];
        switch (rng() % 5) {
          case 0: t.erase(s, e - s); break;                                         // delete
          case 1: t.replace(s, e - s, other); break;                                // replace
          case 2: t.insert(s, other + " "); break;                                  // insert
          case 3: t.insert(e, text.substr(s, e - s)); break;                        // glue a copy
          default: t[s + rng() % (e - s)] = char(rng() % 256); break;               // one byte
        }
      }
      Motion m;
      try {
        m = read_bvh(t, "damaged.bvh");
      } catch (const Error& err) {
        ++invalid;
        uint32_t lines = 1;
        for (size_t i = 0; i < t.size(); ++i) {
          if (t[i] == '\r' && i + 1 < t.size() && t[i + 1] == '\n') ++i;
          if (t[i] == '\n' || t[i] == '\r') ++lines;
        }
        if (!(err.line() >= 1 && err.line() <= lines && err.column() >= 1))
          FAIL_CHECK("trial " << trial << ": " << err.what() << " outside " << lines << " lines");
        continue;
      }
      ++valid;
      // Still valid: consistent, and written text reads back bit for bit.
      REQUIRE(m.values.size() == size_t(m.frame_count) * m.channel_count());
      const Motion back = read_bvh(write_bvh(m), "written.bvh");
      CHECK(back.frame_count == m.frame_count);
      CHECK(back.values == m.values);
      CHECK(back.skeleton.joints.size() == m.skeleton.joints.size());
    }
  }
  MESSAGE(valid << " damaged texts still read, " << invalid << " refused");
  CHECK(invalid > valid);
}

}  // TEST_SUITE
