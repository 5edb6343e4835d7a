// The runtime profile (spec/FORMAT.md section 9): write_kanim_runtime of every archive vector
// and corpus-derived file samples bit for bit as the archive clip through Clip::load and
// Clip::view and converts back to the same keys; the committed v4 vectors are what the writer
// makes; Clip::view's alignment rule; every structure rule of 9.1, 9.2 and 9.3 broken one at a
// time on v4_rules.kanim, each refused with the status 9.4 gives and the offset of the field
// broken; a content-rule break that only DecodeLimits::check_content finds; the lifetime of a
// viewed clip's bytes (clip.h).
//
// The file layout used to break fields is computed here from the spec's tables (3.1, 4.1, 9.2,
// 9.3), not from the library's image_layout.h, and the XXH64 is xxHash's own, checked against
// the two values section 9.1 gives.
#define XXH_INLINE_ALL
#include <xxhash.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "keyanim/clip.h"
#include "keyanim/offline/container.h"

#include "clips.h"
#include "le_bytes.h"

using namespace container_test;

namespace {

using keyanim::Cursor;
using keyanim::DecodeLimits;
using keyanim::Transform;

// ---------------------------------------------------------------------------------------------
// Bytes at an address that is a multiple of 8 (or `shift` past one), as Clip::view needs.

struct Aligned {
  std::vector<uint64_t> words;
  size_t shift = 0, size = 0;
  explicit Aligned(const std::vector<uint8_t>& b, size_t shift_by = 0) : words(b.size() / 8 + 2), shift(shift_by), size(b.size()) {
    if (!b.empty()) std::memcpy(data(), b.data(), b.size());
  }
  uint8_t* data() { return reinterpret_cast<uint8_t*>(words.data()) + shift; }
  std::span<const uint8_t> span() { return {data(), size}; }
};

using container_test::get_le;
using container_test::put_le;

// Section 9.1, rule 3: the last 8 bytes are the XXH64 (seed 0) of all before them.
void fix_xxh64(std::vector<uint8_t>& b) { put_le(b, b.size() - 8, 8, XXH64(b.data(), b.size() - 8, 0)); }

// ---------------------------------------------------------------------------------------------
// Where things are in a runtime-profile file (spec sections 3.1, 4.1, 9.2, 9.3).

struct RuntimeFile {
  uint64_t sections = 0, imag = 0, imag_entry = 0;  // IMAG: content offset, table entry offset
  uint64_t frames = 0, channels = 0;                 // CLIP's F and C
  uint64_t nc = 0, nb = 0, blocks = 0, list_keys = 0, payload = 0;
  // Array starts (absolute file offsets) and unpadded sizes, in 9.2's order.
  enum { interp, tension, key_count, curve_of, fixed_value, fixed_frame, fixed_channels, curves, curve_s,
         first_frame, last_frame, first_value, last_value, curve_linear, curve_channel, lists, list_frames,
         list_values, list_q, record_offset, payload_arr, kArrays };
  uint64_t at[kArrays + 1] = {}, used[kArrays] = {};

  explicit RuntimeFile(const std::vector<uint8_t>& b) {
    sections = get_le(b, 16, 4);
    const uint64_t data = 24 + 24 * sections;
    const uint64_t clip_size = get_le(b, 24 + 8, 8);
    imag_entry = 24 + 24;
    imag = data + clip_size;
    frames = get_le(b, data + 0, 4);
    channels = get_le(b, data + 8, 4);
    nc = get_le(b, imag + 4, 4), nb = get_le(b, imag + 8, 4), blocks = get_le(b, imag + 12, 4);
    list_keys = get_le(b, imag + 16, 4), payload = get_le(b, imag + 20, 4);
    const uint64_t c = channels, l = (nc + 3) / 4 * 4;
    const uint64_t sizes[kArrays] = {c,     4 * c,     4 * c,          4 * c,           4 * c,
                                     4 * c, 4 * (c - nc), 24 * nc,     4 * l,           4 * l,
                                     4 * l, 4 * l,     4 * l,          4 * l,           4 * nc,
                                     8 * (nc - nb),    4 * list_keys,  4 * list_keys,   8 * list_keys,
                                     4 * (blocks * nb + 8),            payload + 8};
    at[0] = imag + 32;
    for (int a = 0; a < kArrays; ++a) used[a] = sizes[a], at[a + 1] = at[a] + (sizes[a] + 7) / 8 * 8;
  }
  uint64_t imag_end() const { return at[kArrays]; }
  uint64_t record(const std::vector<uint8_t>& b, uint64_t r) const { return at[payload_arr] + get_le(b, at[record_offset] + 4 * r, 4); }
  uint64_t base_bits(const std::vector<uint8_t>& b, uint64_t curve) const { return get_le(b, at[curves] + 24 * curve + 16, 4); }
};

// A record's fields (9.3): Mask, Value_Bits w, Context_Bits wk, and where its Values start.
struct Record {
  uint64_t at = 0, mask = 0, w = 0, wk = 0, wc = 0, m = 0;
  uint64_t bits() const { return 80 + 4 * wk + wc + (m + 4) * w; }
  uint64_t value_bit(uint64_t j) const { return 80 + 4 * wk + wc + j * w; }
};
Record record_of(const std::vector<uint8_t>& b, const RuntimeFile& f, uint64_t block, uint64_t curve) {
  Record r;
  r.at = f.record(b, block * f.nb + curve);
  r.mask = get_le(b, r.at, 8);
  r.w = b.at(r.at + 8), r.wk = b.at(r.at + 9), r.wc = f.base_bits(b, curve);
  r.m = uint64_t(std::popcount(r.mask));
  return r;
}

// ---------------------------------------------------------------------------------------------
// Sampling two clips the same way, bit for bit.

bool same_transform(const Transform& a, const Transform& b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Positions: every quarter frame from -2 to F + 1 for short clips; for long ones the first and
// last 300 frames, both sides of every 64-frame block boundary, and a stride over the rest.
std::vector<double> positions_of(uint32_t frames) {
  std::vector<double> p;
  const double n = frames;
  if (frames <= 1200) {
    for (double x = -2.0; x <= n + 1.0; x += 0.25) p.push_back(x);
    return p;
  }
  for (double x = -2.0; x < 300.0; x += 0.25) p.push_back(x);
  for (uint32_t b = 64; b < frames; b += 64) p.insert(p.end(), {b - 0.5, b - 0.25, double(b), b + 0.25});
  for (uint32_t f = 300; f < frames; f += 97) p.push_back(f + 0.375);
  for (double x = n - 300.0; x <= n + 1.0; x += 0.25) p.push_back(x);
  return p;
}

// `b` (through a cursor for sample() and sample_local(), playing forward) against `a` (plain):
// channels, local and model transforms, and one channel subset; counts of differing values.
struct Diff {
  uint64_t values = 0, poses = 0, positions = 0;
};
Diff compare_samples(const Clip& a, const Clip& b) {
  Diff d;
  REQUIRE(a.channel_count() == b.channel_count());
  REQUIRE(a.frame_count() == b.frame_count());
  REQUIRE(a.skeleton().joints.size() == b.skeleton().joints.size());
  const uint32_t n = a.channel_count();
  const size_t nodes = a.skeleton().joints.size();
  std::vector<float> va(n), vb(n);
  std::vector<Transform> ta(nodes), tb(nodes);
  Cursor cursor, local_cursor;
  REQUIRE(cursor.prepare(b) == Status::ok);
  REQUIRE(local_cursor.prepare(b) == Status::ok);
  std::vector<double> pos = positions_of(a.frame_count());
  std::sort(pos.begin(), pos.end());  // forward playback for the cursors
  for (double x : pos) {
    ++d.positions;
    REQUIRE(a.sample(x, va) == Status::ok);
    REQUIRE(b.sample(x, vb, &cursor) == Status::ok);
    for (uint32_t c = 0; c < n; ++c) d.values += !same_bits(va[c], vb[c]);
    REQUIRE(b.sample(x, vb) == Status::ok);
    for (uint32_t c = 0; c < n; ++c) d.values += !same_bits(va[c], vb[c]);
    REQUIRE(a.sample_local(x, ta) == Status::ok);
    REQUIRE(b.sample_local(x, tb, &local_cursor) == Status::ok);
    for (size_t j = 0; j < nodes; ++j) d.poses += !same_transform(ta[j], tb[j]);
    REQUIRE(a.sample_model(x, ta) == Status::ok);
    REQUIRE(b.sample_model(x, tb) == Status::ok);
    for (size_t j = 0; j < nodes; ++j) d.poses += !same_transform(ta[j], tb[j]);
  }
  return d;
}

void check_same_everything(const Clip& archive, const Clip& other) {
  check_same_clip(archive, other);
  const Diff d = compare_samples(archive, other);
  CHECK(d.positions > 0);
  CHECK(d.values == 0);
  CHECK(d.poses == 0);
}

struct Loaded {
  Status status = Status::ok;
  ErrorInfo err;
  Clip clip;
};
Loaded load(const std::vector<uint8_t>& b, bool check_content = false) {
  Loaded l;
  DecodeLimits lim;
  lim.check_content = check_content;
  l.status = Clip::load(b, l.clip, &l.err, lim);
  return l;
}
Loaded view(Aligned& a) {
  Loaded l;
  l.status = Clip::view(a.span(), l.clip, &l.err);
  return l;
}

// The archive clip through the runtime profile and back (task (a)).
void check_runtime_round_trip(const Clip& archive, const std::string& what) {
  INFO(what);
  const std::vector<uint8_t> rt = keyanim::offline::write_kanim_runtime(archive);
  REQUIRE(get_le(rt, 8, 2) == 4);
  REQUIRE((get_le(rt, 12, 4) & 1) == 1);
  const Loaded loaded = load(rt), checked = load(rt, true);
  REQUIRE(loaded.status == Status::ok);
  REQUIRE(checked.status == Status::ok);
  Aligned bytes(rt);
  const Loaded viewed = view(bytes);
  REQUIRE(viewed.status == Status::ok);
  CHECK(viewed.clip.version_major() == 4);
  check_same_everything(archive, loaded.clip);
  check_same_everything(archive, viewed.clip);
  // Back to the archive profile, from the viewed clip and from the loaded one.
  for (const Clip* from : {&viewed.clip, &loaded.clip}) {
    const std::vector<uint8_t> back = keyanim::offline::write_kanim(keyanim::offline::encoded_clip(*from));
    const Loaded again = load(back);
    REQUIRE(again.status == Status::ok);
    CHECK(again.clip.version_major() == 3);
    check_same_everything(archive, again.clip);
    // And the runtime profile of that is the same bytes: the writer is deterministic.
    CHECK(keyanim::offline::write_kanim_runtime(again.clip) == rt);
  }
}

const char* const kV3[] = {"v3_rules", "v3_uniform", "v3_single", "v3_long", "v3_predict", "v3_blocks"};

std::vector<uint8_t> v4_rules() { return read_file(vector_path("v4_rules", ".kanim")); }

// The expected refusal of one broken rule: status, section and absolute offset.
void check_refused(const std::vector<uint8_t>& b, Status status, const std::string& section, uint64_t offset) {
  const Loaded l = load(b);
  CHECK(l.status == status);
  CHECK(l.err.status == status);
  CHECK(l.err.section == section);
  CHECK(l.err.byte_offset == offset);
  CHECK(l.clip.channel_count() == 0);
  Aligned a(b);
  const Loaded v = view(a);
  CHECK(v.status == status);
  CHECK(v.err.section == section);
  CHECK(v.err.byte_offset == offset);
}

}  // namespace

TEST_CASE("runtime profile: the XXH64 used here is section 9.1's") {
  CHECK(XXH64(nullptr, 0, 0) == 0xEF46DB3751D8E999ull);
  CHECK(XXH64("123456789", 9, 0) == 0x8CB841DB40E6AE83ull);
}

TEST_CASE("runtime profile: every v3 vector samples bit for bit through write_kanim_runtime, load, view and back") {
  for (const char* name : kV3) {
    const Loaded a = load(read_file(vector_path(name, ".kanim")));
    REQUIRE(a.status == Status::ok);
    check_runtime_round_trip(a.clip, name);
  }
}

TEST_CASE("runtime profile: corpus-derived files and random clips sample bit for bit through the runtime profile") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(KEYANIM_SPEC_DIR) / ".." / "fuzz" / "corpus" / "load";
  size_t files = 0;
  std::vector<fs::path> paths;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".kanim" && e.path().filename().string().rfind("cmu_", 0) == 0) paths.push_back(e.path());
  std::sort(paths.begin(), paths.end());
  for (const fs::path& p : paths) {
    const Loaded a = load(read_file(p.string()));
    REQUIRE(a.status == Status::ok);
    check_runtime_round_trip(a.clip, p.filename().string());
    ++files;
  }
  CHECK(files >= 28);  // 7 CMU snippets, 4 encodings each (fuzz/make_seeds.py)
  // Random clips: dense, sparse (list curves), zero and constant channels, keys away from the
  // ends, both tangent rules; frame counts around the 64-frame blocks.
  for (uint32_t frames : {1u, 2u, 63u, 64u, 65u, 129u, 700u}) {
    const Clip a = keyanim::offline::to_clip(random_clip(frames * 7 + 1, frames, 4));
    check_runtime_round_trip(a, "random clip of " + std::to_string(frames) + " frames");
  }
}

TEST_CASE("runtime profile: the v4 vectors are write_kanim_runtime of the v3 vectors, byte for byte") {
  for (const char* name : kV3) {
    INFO(name);
    const Loaded a = load(read_file(vector_path(name, ".kanim")));
    REQUIRE(a.status == Status::ok);
    const std::string v4 = std::string("v4_") + (name + 3);
    CHECK(keyanim::offline::write_kanim_runtime(a.clip) == read_file(vector_path(v4, ".kanim")));
  }
}

TEST_CASE("runtime profile: Clip::view refuses an address that is not a multiple of 8") {
  const std::vector<uint8_t> b = v4_rules();
  for (size_t shift : {1u, 2u, 4u, 7u}) {
    Aligned a(b, shift);
    Clip clip;
    ErrorInfo err;
    CHECK(Clip::view(a.span(), clip, &err) == Status::invalid_argument);
    CHECK(err.status == Status::invalid_argument);
    CHECK(err.section == "file");
    CHECK(clip.channel_count() == 0);
    // The same bytes load (Clip::load copies them to aligned memory).
    CHECK(Clip::load(a.span(), clip, &err) == Status::ok);
  }
  Aligned a(b, 0);
  Clip clip;
  CHECK(Clip::view(a.span(), clip) == Status::ok);
}

TEST_CASE("runtime profile: the file's own rules (9.1: table, checksum, size) broken one at a time") {
  const std::vector<uint8_t> good = v4_rules();
  REQUIRE(load(good).status == Status::ok);
  const RuntimeFile f(good);
  REQUIRE(get_le(good, f.imag_entry + 16, 8) == f.imag_end() - f.imag);  // this file's layout is 9.2's
  const uint64_t checksum_at = good.size() - 8;
  SUBCASE("a byte of IMAG changed, the XXH64 kept: checksum_mismatch") {
    std::vector<uint8_t> b = good;
    b[f.at[RuntimeFile::payload_arr]] ^= 1;
    check_refused(b, Status::checksum_mismatch, "checksum", checksum_at);
  }
  SUBCASE("the checksum itself changed") {
    std::vector<uint8_t> b = good;
    b[checksum_at + 7] ^= 0x80;
    check_refused(b, Status::checksum_mismatch, "checksum", checksum_at);
  }
  SUBCASE("a 4-byte checksum (the archive profile's) is truncated") {
    std::vector<uint8_t> b(good.begin(), good.end() - 4);
    check_refused(b, Status::truncated, "checksum", b.size());
  }
  SUBCASE("a byte after the checksum: trailing_bytes") {
    std::vector<uint8_t> b = good;
    b.push_back(0);
    check_refused(b, Status::trailing_bytes, "checksum", good.size());
  }
  SUBCASE("IMAG marked compressed: corrupt in the table") {
    std::vector<uint8_t> b = good;
    put_le(b, f.imag_entry + 4, 4, get_le(b, f.imag_entry + 4, 4) | 1);
    fix_xxh64(b);
    check_refused(b, Status::corrupt, "table", f.imag_entry + 4);
  }
  SUBCASE("IMAG's tag made KVAL: the runtime profile holds no KVAL") {
    std::vector<uint8_t> b = good;
    std::memcpy(&b[f.imag_entry], "KVAL", 4);
    fix_xxh64(b);
    const Loaded l = load(b);
    CHECK(l.status == Status::corrupt);
    CHECK(l.err.section == "table");
    CHECK(l.err.byte_offset == f.imag_entry);
  }
  SUBCASE("CLIP and IMAG's entries swapped") {
    std::vector<uint8_t> b = good;
    std::swap_ranges(b.begin() + 24, b.begin() + 48, b.begin() + 48);
    fix_xxh64(b);
    const Loaded l = load(b);
    CHECK(l.status == Status::corrupt);
    CHECK(l.err.section == "table");
    CHECK(l.err.byte_offset == 24);
  }
  SUBCASE("a reserved Header_Flags bit beside Runtime") {
    std::vector<uint8_t> b = good;
    b[12] |= 8;  // bits 1 and 2 are Member and Bank from version 4.1 (section 10)
    fix_xxh64(b);
    check_refused(b, Status::reserved_bits_set, "header", 12);
  }
  SUBCASE("Member set: a bank's clip read by itself (10.5)") {
    std::vector<uint8_t> b = good;
    b[12] |= 2;
    fix_xxh64(b);
    check_refused(b, Status::corrupt, "header", 12);
  }
  SUBCASE("Runtime cleared: an archive file (9), where IMAG is an unknown critical section (3.2, rule 2)") {
    std::vector<uint8_t> b = good;
    b[12] &= uint8_t(~1u);
    fix_xxh64(b);
    check_refused(b, Status::reserved_bits_set, "table", f.imag_entry);
  }
}

TEST_CASE("runtime profile: IMAG's structure rules (9.2, 9.3) broken one at a time are refused") {
  const std::vector<uint8_t> good = v4_rules();
  const RuntimeFile f(good);
  using R = RuntimeFile;
  REQUIRE(get_le(good, f.imag_entry + 16, 8) == f.imag_end() - f.imag);  // this file's layout is 9.2's
  REQUIRE(f.nb >= 1);
  REQUIRE(f.channels > f.nc);  // v4_rules has zero and constant channels
  // break_at(offset, bytes, value): one field set, the XXH64 fixed, refused at that field.
  auto broken = [&](uint64_t at, int n, uint64_t v) {
    std::vector<uint8_t> b = good;
    put_le(b, at, n, v);
    fix_xxh64(b);
    return b;
  };
  auto first_channel = [&](auto pred) {
    for (uint64_t c = 0; c < f.channels; ++c)
      if (pred(get_le(good, f.at[R::key_count] + 4 * c, 4))) return c;
    FAIL("no such channel in v4_rules");
    return uint64_t(0);
  };
  const uint64_t constant = first_channel([](uint64_t k) { return k == 1; });
  const uint64_t curve_ch = get_le(good, f.at[R::curve_channel], 4);

  SUBCASE("header: Block_Shift 5") { check_refused(broken(f.imag, 4, 5), Status::corrupt, "IMAG", f.imag); }
  SUBCASE("header: Image_Reserved") { check_refused(broken(f.imag + 28, 4, 1), Status::reserved_bits_set, "IMAG", f.imag + 24); }
  SUBCASE("header: Curve_Count above Channel_Count") { check_refused(broken(f.imag + 4, 4, f.channels + 1), Status::corrupt, "IMAG", f.imag + 4); }
  SUBCASE("header: Block_Curve_Count above Curve_Count") { check_refused(broken(f.imag + 8, 4, f.nc + 1), Status::corrupt, "IMAG", f.imag + 8); }
  SUBCASE("header: Block_Count not B") { check_refused(broken(f.imag + 12, 4, f.blocks + 1), Status::corrupt, "IMAG", f.imag + 12); }
  SUBCASE("header: List_Key_Count makes a size other than Raw_Size") {
    check_refused(broken(f.imag + 16, 4, f.list_keys + 2), Status::corrupt, "IMAG", f.imag);
  }
  SUBCASE("a Pad byte not zero") {
    REQUIRE(f.used[R::interp] % 8 != 0);
    const uint64_t pad = f.at[R::interp] + f.used[R::interp];
    check_refused(broken(pad, 1, 1), Status::corrupt, "IMAG", pad);
  }
  SUBCASE("Interpolation reserved value") {
    check_refused(broken(f.at[R::interp] + 1, 1, 2), Status::reserved_bits_set, "IMAG", f.at[R::interp] + 1);
  }
  SUBCASE("Tension above 1") {
    const float t = 1.5f;
    check_refused(broken(f.at[R::tension] + 4, 4, std::bit_cast<uint32_t>(t)), Status::corrupt, "IMAG", f.at[R::tension] + 4);
  }
  SUBCASE("Key_Count above Frame_Count") {
    check_refused(broken(f.at[R::key_count], 4, f.frames + 1), Status::corrupt, "IMAG", f.at[R::key_count]);
  }
  SUBCASE("a constant channel's Fixed_Frame at Frame_Count") {
    check_refused(broken(f.at[R::fixed_frame] + 4 * constant, 4, f.frames), Status::corrupt, "IMAG", f.at[R::curve_of] + 4 * constant);
  }
  SUBCASE("a constant channel's Fixed_Value infinite") {
    check_refused(broken(f.at[R::fixed_value] + 4 * constant, 4, 0x7f800000u), Status::corrupt, "IMAG", f.at[R::curve_of] + 4 * constant);
  }
  SUBCASE("a curve's channel given Curve_Of 0xFFFFFFFF") {
    check_refused(broken(f.at[R::curve_of] + 4 * curve_ch, 4, 0xFFFFFFFFu), Status::corrupt, "IMAG", f.at[R::curve_of] + 4 * curve_ch);
  }
  SUBCASE("Fixed_Channels out of order") {
    REQUIRE(f.channels - f.nc >= 2);
    const uint64_t second = get_le(good, f.at[R::fixed_channels] + 4, 4);
    check_refused(broken(f.at[R::fixed_channels], 4, second), Status::corrupt, "IMAG", f.at[R::fixed_channels]);
  }
  SUBCASE("Curve_Reserved") {
    check_refused(broken(f.at[R::curves] + 20, 4, 1), Status::reserved_bits_set, "IMAG", f.at[R::curves] + 20);
  }
  SUBCASE("a curve's Step 0") { check_refused(broken(f.at[R::curves] + 8, 8, 0), Status::corrupt, "IMAG", f.at[R::curves]); }
  SUBCASE("a curve's Q_Base above 2^53") {
    check_refused(broken(f.at[R::curves], 8, (1ull << 53) + 1), Status::corrupt, "IMAG", f.at[R::curves]);
  }
  SUBCASE("a curve's Base_Bits 56") { check_refused(broken(f.at[R::curves] + 16, 4, 56), Status::corrupt, "IMAG", f.at[R::curves]); }
  SUBCASE("Curve_S not the channel's tension") {
    check_refused(broken(f.at[R::curve_s], 4, std::bit_cast<uint32_t>(0.125f)), Status::corrupt, "IMAG", f.at[R::curve_s]);
  }
  SUBCASE("a padding lane of First_Frame not +inf") {
    REQUIRE(f.nc % 4 != 0);
    const uint64_t lane = f.nc;
    check_refused(broken(f.at[R::first_frame] + 4 * lane, 4, 0), Status::corrupt, "IMAG", f.at[R::curve_s] + 4 * lane);
  }
  SUBCASE("a block curve's First_Frame not its first key") {
    const float first = std::bit_cast<float>(uint32_t(get_le(good, f.at[R::first_frame], 4)));
    check_refused(broken(f.at[R::first_frame], 4, std::bit_cast<uint32_t>(first + 1.0f)), Status::corrupt, "IMAG",
                  f.at[R::first_frame]);
  }
  SUBCASE("Curve_Channel not the channel whose Curve_Of is it") {
    // The rule binds two fields (Curve_Of[c] = i and Curve_Channel[i] = c): either may be named.
    const Loaded l = load(broken(f.at[R::curve_channel], 4, constant));
    CHECK(l.status == Status::corrupt);
    CHECK(l.err.section == "IMAG");
    const bool named = l.err.byte_offset == f.at[R::curve_channel] || l.err.byte_offset == f.at[R::curve_of] + 4 * curve_ch;
    CHECK(named);
  }
  SUBCASE("Record_Offset's extra entries") {
    const uint64_t extra = f.at[R::record_offset] + 4 * (f.blocks * f.nb);
    check_refused(broken(extra + 4, 4, 1), Status::corrupt, "IMAG", extra + 4);
  }
  SUBCASE("Record_Offset[1] not where record 0 ends") {
    REQUIRE(f.blocks * f.nb >= 2);
    const uint64_t at = f.at[R::record_offset] + 4;
    check_refused(broken(at, 4, get_le(good, at, 4) + 1), Status::corrupt, "IMAG", at);
  }
  SUBCASE("Payload's 8 extra bytes") {
    const uint64_t extra = f.at[R::payload_arr] + f.payload;
    check_refused(broken(extra + 3, 1, 1), Status::corrupt, "IMAG", extra + 3);
  }
  SUBCASE("Payload_Size not where the records end") {
    // A larger P with the section grown to match would move SKEL; instead the last record's
    // declared end: P - 1 makes the section 8 bytes shorter only when P % 8 == 1, so shrink P
    // by 8 and its array by 8 bytes, keeping the size rule.
    std::vector<uint8_t> b = good;
    REQUIRE(f.payload >= 8);
    put_le(b, f.imag + 20, 4, f.payload - 8);
    b.erase(b.begin() + int64_t(f.at[R::payload_arr] + f.payload), b.begin() + int64_t(f.at[R::payload_arr] + f.payload + 8));
    put_le(b, f.imag_entry + 8, 8, get_le(b, f.imag_entry + 8, 8) - 8);
    put_le(b, f.imag_entry + 16, 8, get_le(b, f.imag_entry + 16, 8) - 8);
    fix_xxh64(b);
    const Loaded l = load(b);
    CHECK(l.status == Status::corrupt);
    CHECK(l.err.section == "IMAG");
    CHECK(l.err.byte_offset >= f.at[R::record_offset]);
    CHECK(l.err.byte_offset < f.imag_end());
  }
  SUBCASE("a record's Value_Bits 56") {
    const Record r = record_of(good, f, 0, 0);
    check_refused(broken(r.at + 8, 1, 56), Status::corrupt, "IMAG", r.at + 8);
  }
  SUBCASE("a record's Context_Bits 32") {
    const Record r = record_of(good, f, 0, 0);
    check_refused(broken(r.at + 9, 1, 32), Status::corrupt, "IMAG", r.at + 9);  // the field itself
  }
  SUBCASE("a Mask bit at Frame_Count") {
    REQUIRE(f.frames % 64 != 0);
    const uint64_t last = f.blocks - 1;
    const Record r = record_of(good, f, last, 0);
    check_refused(broken(r.at, 8, r.mask | (1ull << (f.frames % 64))), Status::corrupt, "IMAG", r.at);
  }
  SUBCASE("a bit after a record's last field") {
    uint64_t found = ~0ull;
    for (uint64_t i = 0; i < f.blocks * f.nb && found == ~0ull; ++i) {
      const Record r = record_of(good, f, i / f.nb, i % f.nb);
      if (r.bits() % 8 != 0) found = i;
    }
    REQUIRE(found != ~0ull);
    const Record r = record_of(good, f, found / f.nb, found % f.nb);
    const uint64_t byte = r.at + r.bits() / 8;
    check_refused(broken(byte, 1, good[byte] | 0x80), Status::corrupt, "IMAG", byte);
  }
  SUBCASE("a record's popcount off: a Mask bit cleared") {
    Record r = record_of(good, f, 0, 0);
    REQUIRE(r.m >= 3);
    // The middle key of the record cleared: the window order still holds, the popcounts do not
    // sum to Key_Count (the record also gets one value field fewer, so its size changes: the
    // next Record_Offset, or Payload_Size, no longer matches; either is this rule's refusal).
    uint64_t mask = r.mask, bit = 0;
    for (uint64_t k = 0; k < r.m / 2 + 1; ++k) bit = uint64_t(std::countr_zero(mask)), mask &= mask - 1;
    const Loaded l = load(broken(r.at, 8, r.mask & ~(1ull << bit)));
    CHECK(l.status == Status::corrupt);
    CHECK(l.err.section == "IMAG");
    CHECK(l.err.byte_offset >= f.imag);
    CHECK(l.err.byte_offset < f.imag_end());
  }
  SUBCASE("a record's context frames out of order") {
    // e_0 made equal to e_1 (both before the block): zigzag fields of wk bits from bit 80.
    const Record r = record_of(good, f, 0, 0);
    REQUIRE(r.wk > 0);
    std::vector<uint8_t> b = good;
    auto field = [&](uint64_t bit, uint64_t w) {
      uint64_t v = 0;
      for (uint64_t j = 0; j < w; ++j) v |= uint64_t((b[r.at + (bit + j) / 8] >> ((bit + j) % 8)) & 1) << j;
      return v;
    };
    auto set_field = [&](uint64_t bit, uint64_t w, uint64_t v) {
      for (uint64_t j = 0; j < w; ++j) {
        uint8_t& byte = b[r.at + (bit + j) / 8];
        byte = uint8_t((byte & ~(1u << ((bit + j) % 8))) | (((v >> j) & 1) << ((bit + j) % 8)));
      }
    };
    set_field(80, r.wk, field(80 + r.wk, r.wk));
    fix_xxh64(b);
    check_refused(b, Status::corrupt, "IMAG", r.at + 10);
  }
}

TEST_CASE("runtime profile: a content-rule break passes the structure checks and only check_content refuses it") {
  const std::vector<uint8_t> good = v4_rules();
  const RuntimeFile f(good);
  const Loaded original = load(good, true);
  REQUIRE(original.status == Status::ok);
  // A record with a real key (m > 0) and value fields of at least one bit: the lowest bit of its
  // first key's field (Values[2]) flipped changes that key's q by one, inside the field's width.
  bool done = false;
  for (uint64_t i = 0; i < f.blocks * f.nb && !done; ++i) {
    const Record r = record_of(good, f, i / f.nb, i % f.nb);
    if (r.m == 0 || r.w == 0) continue;
    done = true;
    std::vector<uint8_t> b = good;
    const uint64_t bit = r.value_bit(2);
    b[r.at + bit / 8] ^= uint8_t(1u << (bit % 8));
    fix_xxh64(b);
    Aligned a(b);
    const Loaded v = view(a), l = load(b), c = load(b, true);
    CHECK(v.status == Status::ok);
    CHECK(l.status == Status::ok);
    CHECK(c.status == Status::corrupt);
    CHECK(c.err.section == "IMAG");
    CHECK(c.err.byte_offset == f.imag);
    CHECK(c.clip.channel_count() == 0);
    // view with check_content rebuilds the image as load does, and refuses it the same way.
    DecodeLimits checking;
    checking.check_content = true;
    Clip vc;
    ErrorInfo vce;
    CHECK(Clip::view(a.span(), vc, &vce, checking) == Status::corrupt);
    CHECK(vce.section == "IMAG");
    CHECK(vc.channel_count() == 0);
    // The flip reached a key: exactly one key value of the viewed clip differs from the file's.
    const uint64_t curve_ch = get_le(good, f.at[RuntimeFile::curve_channel] + 4 * (i % f.nb), 4);
    uint64_t differing = 0;
    for (uint32_t ch = 0; ch < original.clip.channel_count(); ++ch) {
      const auto ko = keyanim::test::channel_keys(original.clip, ch), kv = keyanim::test::channel_keys(v.clip, ch);
      REQUIRE(ko.values.size() == kv.values.size());
      for (size_t k = 0; k < ko.values.size(); ++k)
        if (!same_bits(ko.values[k], kv.values[k])) {
          ++differing;
          CHECK(ch == curve_ch);
        }
    }
    CHECK(differing == 1);
  }
  REQUIRE(done);
}

TEST_CASE("runtime profile: a Step whose values overflow binary32 is a content break (fuzz_load's crash-runtime-infinite-step)") {
  // Section 9.4: Step need only be finite and > 0 for the structure; "every v is finite" is a
  // content rule. A structure-valid file with infinite values samples (to whatever) without
  // harm, and check_content refuses it.
  std::vector<uint8_t> b = v4_rules();
  const RuntimeFile f(b);
  REQUIRE(f.nb >= 1);
  put_le(b, f.at[RuntimeFile::curves] + 8, 8, std::bit_cast<uint64_t>(1e300));
  fix_xxh64(b);
  Aligned a(b);
  const Loaded v = view(a), l = load(b), c = load(b, true);
  REQUIRE(v.status == Status::ok);
  CHECK(l.status == Status::ok);
  CHECK(c.status == Status::corrupt);
  CHECK(c.err.section == "IMAG");
  const uint32_t ch = uint32_t(get_le(b, f.at[RuntimeFile::curve_channel], 4));
  const auto keys = keyanim::test::channel_keys(v.clip, ch);
  REQUIRE(!keys.values.empty());
  CHECK(std::any_of(keys.values.begin(), keys.values.end(), [](float x) { return !std::isfinite(x); }));
  std::vector<float> out(v.clip.channel_count());
  std::vector<Transform> pose(v.clip.skeleton().joints.size());
  Cursor cursor;
  REQUIRE(cursor.prepare(v.clip) == Status::ok);
  for (double x = -1.0; x <= v.clip.frame_count() + 1.0; x += 0.25) {
    CHECK(v.clip.sample(x, out, &cursor) == Status::ok);
    CHECK(v.clip.sample_model(x, pose) == Status::ok);
  }
}

TEST_CASE("runtime profile: a quaternion node's stored value beyond +-16 is a content break (section 4.7)") {
  // v5_blocks_runtime's curve 0 is its quaternion track's x (curves [0, 3 QT) are the tracks').
  // Its Step scaled so that its largest key is exactly 16 (allowed), then 16.5 (refused by
  // check_content; the structure checks pass and sampling stays harmless).
  const std::vector<uint8_t> good = read_file(vector_path("v5_blocks_runtime", ".kanim"));
  const RuntimeFile f(good);
  REQUIRE(get_le(good, f.imag + 28, 4) >= 1);  // Quat_Track_Count
  const Loaded original = load(good, true);
  REQUIRE(original.status == Status::ok);
  const uint32_t ch = uint32_t(get_le(good, f.at[RuntimeFile::curve_channel], 4));
  REQUIRE(original.clip.channel(ch).stored == keyanim::StoredAs::quat_x);
  const auto keys = keyanim::test::channel_keys(original.clip, ch);
  const double step = std::bit_cast<double>(get_le(good, f.at[RuntimeFile::curves] + 8, 8));
  float largest = 0.0f;
  for (float v : keys.values) largest = std::max(largest, std::fabs(v));
  REQUIRE(largest > 0.0f);
  REQUIRE(largest <= 1.0f);
  const double top = std::round(largest / step);  // the largest |q|
  for (const double bound : {16.0, 16.5}) {
    CAPTURE(bound);
    std::vector<uint8_t> b = good;
    put_le(b, f.at[RuntimeFile::curves] + 8, 8, std::bit_cast<uint64_t>(bound / top));
    fix_xxh64(b);
    const Loaded l = load(b);
    REQUIRE(l.status == Status::ok);
    const auto got = keyanim::test::channel_keys(l.clip, ch);
    // The curve's end values as its keys now give them (9.2), so that the bound is the only
    // content rule the file can break.
    put_le(b, f.at[RuntimeFile::first_value], 4, std::bit_cast<uint32_t>(got.values.front()));
    put_le(b, f.at[RuntimeFile::last_value], 4, std::bit_cast<uint32_t>(got.values.back()));
    fix_xxh64(b);
    const Loaded c = load(b, true);
    float most = 0.0f;
    for (float v : got.values) most = std::max(most, std::fabs(v));
    CHECK(most == float(bound));
    CHECK(c.status == (bound <= 16.0 ? Status::ok : Status::corrupt));
    std::vector<Transform> pose(l.clip.skeleton().joints.size());
    for (double x = 0.0; x < l.clip.frame_count(); x += 7.5) CHECK(l.clip.sample_model(x, pose) == Status::ok);
  }
}

TEST_CASE("runtime profile: lifetime of a clip's bytes (clip.h)") {
  const std::vector<uint8_t> good = v4_rules();
  const Loaded reference = load(good);
  REQUIRE(reference.status == Status::ok);
  SUBCASE("load copies the bytes: the clip and its copies outlive them") {
    Clip copy;
    Cursor cursor;
    {
      std::vector<uint8_t> b = good;
      Clip original;
      REQUIRE(Clip::load(b, original) == Status::ok);
      REQUIRE(cursor.prepare(original) == Status::ok);
      copy = original;
      std::fill(b.begin(), b.end(), uint8_t(0xA5));
    }  // the bytes and the original clip destroyed
    CHECK(cursor.prepared_for(copy));
    check_same_everything(reference.clip, copy);
  }
  SUBCASE("view keeps pointers into the bytes: copies share the image while the bytes live") {
    Aligned a(good);
    Clip copy;
    {
      Clip original;
      REQUIRE(Clip::view(a.span(), original) == Status::ok);
      copy = original;
    }  // the original clip destroyed; the copy shares its image, over the same bytes
    check_same_everything(reference.clip, copy);
    // Nothing was copied from the bytes: a value field changed in them shows in the view (a
    // caller must not do this; it shows the pointers), not in a clip loaded from them.
    const RuntimeFile f(good);
    Clip loaded;
    REQUIRE(Clip::load(a.span(), loaded) == Status::ok);
    for (uint64_t i = 0; i < f.blocks * f.nb; ++i) {
      const Record r = record_of(good, f, i / f.nb, i % f.nb);
      if (r.m == 0 || r.w == 0) continue;
      const uint64_t bit = r.value_bit(2);
      a.data()[r.at + bit / 8] ^= uint8_t(1u << (bit % 8));
      const uint32_t ch = uint32_t(get_le(good, f.at[RuntimeFile::curve_channel] + 4 * (i % f.nb), 4));
      CHECK(keyanim::test::channel_keys(copy, ch).values != keyanim::test::channel_keys(reference.clip, ch).values);
      CHECK(keyanim::test::channel_keys(loaded, ch).values == keyanim::test::channel_keys(reference.clip, ch).values);
      break;
    }
  }
  SUBCASE("a viewed clip holds none of the file's bytes; a loaded one holds a copy of them") {
    Aligned a(good);
    Clip viewed, loaded;
    REQUIRE(Clip::view(a.span(), viewed) == Status::ok);
    REQUIRE(Clip::load(good, loaded) == Status::ok);
    // Both count the image they sample; the loaded clip's is inside the copy of the whole file
    // it holds, the viewed clip's is IMAG in the caller's bytes.
    const RuntimeFile f(good);
    CHECK(viewed.skeleton_bytes() == loaded.skeleton_bytes());
    CHECK(loaded.animation_bytes() - viewed.animation_bytes() == good.size() - (f.imag_end() - f.imag));
  }
  SUBCASE("clips viewed and loaded through one RigCache share its rig") {
    keyanim::RigCache rigs;
    Aligned a(good), b(good);
    Clip first, second, archive;
    REQUIRE(Clip::view(a.span(), first, nullptr, {}, &rigs) == Status::ok);
    REQUIRE(Clip::view(b.span(), second, nullptr, {}, &rigs) == Status::ok);
    REQUIRE(Clip::load(read_file(vector_path("v3_rules", ".kanim")), archive, nullptr, {}, &rigs) == Status::ok);
    CHECK(rigs.rig_count() == 1);
    CHECK(first.shares_rig(second));
    CHECK(first.shares_rig(archive));
    check_same_everything(archive, second);
  }
  SUBCASE("view of an archive file decodes it: the clip does not use the bytes after view returns") {
    Clip viewed;
    {
      Aligned a(read_file(vector_path("v3_rules", ".kanim")));
      REQUIRE(Clip::view(a.span(), viewed) == Status::ok);
      std::fill(a.words.begin(), a.words.end(), 0xA5A5A5A5A5A5A5A5ull);
    }
    const Loaded archive = load(read_file(vector_path("v3_rules", ".kanim")));
    check_same_everything(archive.clip, viewed);
  }
}
