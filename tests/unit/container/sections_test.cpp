// Crafted CLIP, SKEL, CHAN, KTIM and KVAL sections (3.x and 2.x), crafted zstd frames, and
// load_file's I/O errors: each decoder obligation of spec/FORMAT.md section 7.
#include <doctest/doctest.h>
#include <zstd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "keyanim/cardinal.h"
#include "keyanim/clip.h"
#include "clip_reference.h"
#include "keyanim/version.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/decode.h"

#include "crafted.h"

using namespace container_test;

TEST_SUITE("container") {

TEST_CASE("crafted CLIP fields") {
  const RawFile base = base_file();
  const size_t clip = base.offset_of("CLIP");
  auto with = [&](size_t at, auto value) {
    RawFile r = base;
    poke(r.get("CLIP").stored, at, value);
    return r.build();
  };
  CHECK_FAILS(with(12, uint8_t(2)), Status::reserved_bits_set, clip + 12);
  CHECK_FAILS(with(13, uint8_t(1)), Status::reserved_bits_set, clip + 13);
  CHECK_FAILS(with(14, uint16_t(1)), Status::reserved_bits_set, clip + 14);
  CHECK_FAILS(with(16, std::numeric_limits<double>::quiet_NaN()), Status::corrupt, clip + 16);
  CHECK_FAILS(with(16, std::numeric_limits<double>::infinity()), Status::corrupt, clip + 16);
  CHECK_FAILS(with(16, 0.0), Status::corrupt, clip + 16);
  CHECK_FAILS(with(16, -0.5), Status::corrupt, clip + 16);
  // vector_uniform has 4 + 7 + 3 + 2 + 2 = 18 keys: CHAN disagrees at its end, or at the
  // channel whose count passes CLIP's.
  CHECK_FAILS(with(24, uint64_t(23)), Status::corrupt, base.offset_of("CHAN") + 13 * 5);
  CHECK_FAILS(with(24, uint64_t(17)), Status::corrupt, base.offset_of("CHAN") + 13 * 5 + 4 * 4);
  CHECK_FAILS(with(24, uint64_t(12 * 5 + 1)), Status::corrupt, clip + 24);  // > C x F
  {
    RawFile r = base;
    r.get("CLIP").stored.push_back(0);
    CHECK_FAILS(r.build(), Status::corrupt, clip);
  }
  {
    // Channel_Count 6 while the nodes have 5: SKEL disagrees first.
    CHECK_FAILS(with(8, uint32_t(6)), Status::corrupt, base.offset_of("SKEL"));
  }
}

TEST_CASE("crafted SKEL records") {
  const RawFile base = base_file();
  const size_t skel = base.offset_of("SKEL");
  // Node 0: name "A" (4 + 1 bytes), then parent at 5, offsets 9..32, flags 33, count 34, types.
  auto with = [&](size_t at, auto value) {
    RawFile r = base;
    poke(r.get("SKEL").stored, at, value);
    return r.build();
  };
  CHECK_FAILS(with(5, int32_t(0)), Status::corrupt, skel + 5);
  CHECK_FAILS(with(5, int32_t(-2)), Status::corrupt, skel + 5);
  CHECK_FAILS(with(9 + 8, std::numeric_limits<double>::infinity()), Status::corrupt, skel + 9 + 8);
  CHECK_FAILS(with(33, uint8_t(2)), Status::reserved_bits_set, skel + 33);
  CHECK_FAILS(with(33, uint8_t(1)), Status::corrupt, skel + 5);  // End Site without a parent
  CHECK_FAILS(with(34, uint8_t(7)), Status::corrupt, skel + 34);
  CHECK_FAILS(with(35, uint8_t(6)), Status::reserved_bits_set, skel + 35);
  CHECK_FAILS(with(0, uint32_t(1000)), Status::corrupt, skel);  // name past the end
  // Node 1 (an End Site, empty name) starts at 37: give it a channel.
  {
    RawFile r = base;
    auto& s = r.get("SKEL").stored;
    REQUIRE(s[37 + 4 + 28] == 1);
    s[37 + 4 + 29] = 1;
    s.insert(s.begin() + 37 + 4 + 30, 3);
    CHECK_FAILS(r.build(), Status::corrupt, skel + 37 + 4 + 29);
  }
  {
    // Node 2 names node 1 (an End Site) as its parent.
    RawFile r = base;
    auto& s = r.get("SKEL").stored;
    poke(s, 71 + 5, int32_t(1));
    CHECK_FAILS(r.build(), Status::corrupt, skel + 71 + 5);
  }
  {
    RawFile r = base;
    r.get("SKEL").stored.push_back(0);
    CHECK_FAILS(r.build(), Status::corrupt, skel + base.sections[1].stored.size());
  }
}

TEST_CASE("crafted CHAN KTIM KVAL") {
  const RawFile base = base_file();
  const size_t chan = base.offset_of("CHAN");
  const size_t C = 5;
  auto with = [&](const char* tag, size_t at, auto value) {
    RawFile r = base;
    poke(r.get(tag).stored, at, value);
    return r.build();
  };
  CHECK_FAILS(with("CHAN", 2, uint8_t(2)), Status::reserved_bits_set, chan + 2);
  CHECK_FAILS(with("CHAN", C + 4 * 1, 1.5f), Status::corrupt, chan + C + 4);
  CHECK_FAILS(with("CHAN", C + 4 * 1, std::numeric_limits<float>::quiet_NaN()), Status::corrupt, chan + C + 4);
  CHECK_FAILS(with("CHAN", 5 * C + 8 * 3, std::numeric_limits<double>::quiet_NaN()), Status::corrupt, chan + 5 * C + 24);
  CHECK_FAILS(with("CHAN", 5 * C + 8 * 3, std::numeric_limits<double>::infinity()), Status::corrupt, chan + 5 * C + 24);
  CHECK_FAILS(with("CHAN", 5 * C + 8 * 3, 0.0), Status::corrupt, chan + 5 * C + 24);
  CHECK_FAILS(with("CHAN", 5 * C + 8 * 3, -0.1), Status::corrupt, chan + 5 * C + 24);
  CHECK_FAILS(with("CHAN", 13 * C + 4 * 4, uint32_t(13)), Status::corrupt, chan + 13 * C + 16);  // > F
  CHECK_FAILS(with("CHAN", 17 * C + 1, uint8_t(2)), Status::reserved_bits_set, chan + 17 * C + 1);  // Value_Coding
  {
    RawFile r = base;
    r.get("CHAN").stored.pop_back();
    CHECK_FAILS(r.build(), Status::corrupt, chan);
  }
  // KTIM of vector_uniform: channel 0 is 1, 2, 0, 3 (frames 1 4 5 9); channel 1 starts at 4.
  const size_t ktim = base.offset_of("KTIM");
  REQUIRE(base.sections[3].stored[0] == 1);
  REQUIRE(base.sections[3].stored[3] == 3);
  CHECK_FAILS(with("KTIM", 3, uint8_t(6)), Status::corrupt, ktim + 3);  // frame 5 + 7 = 12 >= F
  {
    RawFile r = base;  // over-long varint: 0x83 0x00 for 3
    auto& s = r.get("KTIM").stored;
    s[3] = 0x83;
    s.insert(s.begin() + 4, 0x00);
    CHECK_FAILS(r.build(), Status::corrupt, ktim + 3);
  }
  {
    RawFile r = base;  // a varint of 6 bytes
    auto& s = r.get("KTIM").stored;
    s[3] = 0x80;
    s.insert(s.begin() + 4, {0x80, 0x80, 0x80, 0x80, 0x01});
    CHECK_FAILS(r.build(), Status::corrupt, ktim + 3);
  }
  {
    RawFile r = base;  // cut: the last varint has its continuation bit
    r.get("KTIM").stored.back() |= 0x80;
    CHECK_FAILS(r.build(), Status::corrupt, ktim + base.sections[3].stored.size() - 1);
  }
  {
    RawFile r = base;
    r.get("KTIM").stored.push_back(0);
    CHECK_FAILS(r.build(), Status::corrupt, ktim + base.sections[3].stored.size());
  }
  CHECK_FAILS(with("CHAN", 18 * C + 2, uint8_t(9)), Status::corrupt, chan + 18 * C + 2);  // Residual_Bytes > 8
  // KVAL, rebuilt here from the quantized values of vector_uniform by the spec's text (3.0):
  // each channel's residuals under its Value_Coding, zigzag, Residual_Bytes little-endian
  // bytes each, byte k of every residual of the channels with more than k bytes in plane k.
  auto zigzag = [](int64_t d) { return d >= 0 ? uint64_t(d) * 2 : uint64_t(-(d + 1)) * 2 + 1; };
  auto floor_div = [](int64_t a, int64_t b) { return a / b - ((a % b != 0 && a < 0) ? 1 : 0); };
  std::vector<std::vector<uint64_t>> residuals;  // zigzag, per channel
  const auto chans = vector_uniform().channels;
  for (size_t c = 0; c < chans.size(); ++c) {
    const auto& k = chans[c].frames;
    const auto& q = chans[c].q;
    const uint8_t coding = base.sections[2].stored[17 * C + c];
    REQUIRE(coding <= 1);
    residuals.emplace_back();
    for (size_t i = 0; i < q.size(); ++i) {
      int64_t pred = i ? q[i - 1] : 0;
      if (coding == 1 && i >= 2) {
        const int64_t d = q[i - 1] - q[i - 2], g0 = k[i - 1] - k[i - 2], g1 = k[i] - k[i - 1];
        if (d > -(int64_t(1) << 40) && d < (int64_t(1) << 40) && g0 < 65536 && g1 < 65536)
          pred += floor_div(2 * d * g1 + g0, 2 * g0);
        else
          pred += d;
      }
      residuals.back().push_back(zigzag(q[i] - pred));
    }
  }
  std::vector<uint8_t> widths(base.sections[2].stored.begin() + 18 * C, base.sections[2].stored.end());
  REQUIRE(widths.size() == C);
  auto planes = [&](const std::vector<std::vector<uint64_t>>& rs, const std::vector<uint8_t>& ws) {
    std::vector<uint8_t> out;
    for (int k = 0; k < 8; ++k)
      for (size_t c = 0; c < rs.size(); ++c)
        if (ws[c] > k)
          for (uint64_t z : rs[c]) out.push_back(uint8_t(z >> (8 * k)));
    return out;
  };
  for (size_t c = 0; c < C; ++c) {  // the fewest bytes that hold every residual
    uint64_t widest = 0;
    for (uint64_t z : residuals[c]) widest |= z;
    CHECK(widths[c] == (widest == 0 ? 0 : (std::bit_width(widest) + 7) / 8));
  }
  REQUIRE(planes(residuals, widths) == base.sections[4].stored);  // the writer follows the text
  const size_t kval = base.offset_of("KVAL");
  auto with_values = [&](const std::vector<std::vector<uint64_t>>& rs, std::vector<uint8_t> ws) {
    RawFile r = base;
    r.get("KVAL").stored = planes(rs, ws);
    std::copy(ws.begin(), ws.end(), r.get("CHAN").stored.begin() + 18 * C);
    return r.build();
  };
  {
    // First residual of channel 0 made 2^53 + 1 (eight bytes): |q| > 2^53, at that key's byte
    // in plane 0; then 2^53 and a second residual of 1.
    auto rs = residuals;
    auto ws = widths;
    ws[0] = 8;
    rs[0][0] = zigzag((int64_t(1) << 53) + 1);
    CHECK_FAILS(with_values(rs, ws), Status::corrupt, kval);
    rs[0][0] = zigzag(int64_t(1) << 53);
    rs[0][1] = zigzag(1);
    CHECK_FAILS(with_values(rs, ws), Status::corrupt, kval + 1);
    // A residual beyond 2^57, even though q would be in range after it.
    rs[0][0] = zigzag((int64_t(1) << 57) + 1);
    rs[0][1] = zigzag(-(int64_t(1) << 57));
    CHECK_FAILS(with_values(rs, ws), Status::corrupt, kval);
  }
  {
    // Wider than needed is allowed: the same clip.
    auto ws = widths;
    for (auto& w : ws) w = w ? 8 : 0;
    const Loaded l = load(with_values(residuals, ws));
    REQUIRE(l.status == Status::ok);
    check_same_clip(l.clip, keyanim::offline::to_clip(vector_uniform()));
  }
  {
    RawFile r = base;
    r.get("KVAL").stored.push_back(0);
    CHECK_FAILS(r.build(), Status::corrupt, kval);  // more bytes than keys x Residual_Bytes
    r.get("KVAL").stored.pop_back();
    r.get("KVAL").stored.pop_back();
    CHECK_FAILS(r.build(), Status::corrupt, kval);
  }
  {
    // A channel without keys must have no residual bytes: channel 4's two keys removed (their
    // gaps are the last two one-byte varints of KTIM), its Residual_Bytes left at 1.
    auto ws = widths;
    ws[4] = 1;
    auto rs = residuals;
    rs[4].clear();
    RawFile z = base;
    poke(z.get("CHAN").stored, 13 * C + 4 * 4, uint32_t(0));
    poke(z.get("CLIP").stored, 24, uint64_t(18 - 2));
    std::vector<uint8_t>& gaps = z.get("KTIM").stored;
    REQUIRE(gaps.size() > 2);
    gaps.erase(gaps.end() - 2, gaps.end());
    z.get("KVAL").stored = planes(rs, ws);
    std::copy(ws.begin(), ws.end(), z.get("CHAN").stored.begin() + 18 * C);
    CHECK_FAILS(z.build(), Status::corrupt, chan + 18 * C + 4);
  }
  {
    // A step so large that a value overflows binary32: at channel 0's first residual.
    CHECK_FAILS(with("CHAN", 5 * C + 8 * 0, 1e300), Status::corrupt, kval);
  }
}

// 2.x files (varint planes, spec Appendix E) still load, and their KVAL is still checked: the
// committed v2_long vector, its sections decompressed.

TEST_CASE("crafted KVAL of a 2.x file") {
  RawFile base = split(read_file(vector_path("v2_long", ".kanim")));
  REQUIRE(base.major == 2);
  for (auto& sec : base.sections) {
    if (!(sec.flags & 1)) continue;
    std::vector<uint8_t> raw(size_t(ZSTD_getFrameContentSize(sec.stored.data(), sec.stored.size())));
    REQUIRE(ZSTD_decompress(raw.data(), raw.size(), sec.stored.data(), sec.stored.size()) == raw.size());
    sec.stored = raw;
    sec.flags &= ~1u;
  }
  REQUIRE(load(base.build()).status == Status::ok);
  const size_t kval = base.offset_of("KVAL");
  const std::vector<uint8_t> v = base.get("KVAL").stored;
  const uint8_t count = v[0];
  REQUIRE(count >= 2);
  {
    RawFile r = base;
    r.get("KVAL").stored.push_back(0);
    CHECK_FAILS(r.build(), Status::corrupt, kval + 1);  // plane sizes do not add up
    r.get("KVAL").stored = v;
    r.get("KVAL").stored[0] = 11;
    CHECK_FAILS(r.build(), Status::corrupt, kval);
    r.get("KVAL").stored = {0};  // no planes for the keys
    CHECK_FAILS(r.build(), Status::corrupt, kval);
  }
  {
    // Plane 0 one byte short, plane 1 one longer: sizes add up, plane 0 does not match K.
    auto w = v;
    uint32_t p0 = 0, p1 = 0;
    std::memcpy(&p0, &w[1], 4);
    std::memcpy(&p1, &w[5], 4);
    poke(w, 1, p0 - 1);
    poke(w, 5, p1 + 1);
    RawFile r = base;
    r.get("KVAL").stored = w;
    CHECK_FAILS(r.build(), Status::corrupt, kval + 1);
  }
  {
    // The first varint made over-long: its first byte gains a continuation and plane 1 a 0.
    auto w = v;
    const size_t first = 1 + 4 * size_t(count);
    if (!(w[first] & 0x80)) {
      uint32_t p1 = 0;
      std::memcpy(&p1, &w[5], 4);
      w[first] |= 0x80;
      poke(w, 5, p1 + 1);
      uint32_t p0 = 0;
      std::memcpy(&p0, &w[1], 4);
      w.insert(w.begin() + std::ptrdiff_t(first + p0), 0x00);
      RawFile r = base;
      r.get("KVAL").stored = w;
      CHECK_FAILS(r.build(), Status::corrupt, kval + first);
    }
  }
}

TEST_CASE("crafted zstd frames") {
  const RawFile base = base_file();
  const std::vector<uint8_t> clip_raw = base.sections[0].stored;
  const size_t clip = base.offset_of("CLIP");
  {
    // A valid hand-made frame: the compressed path gives the same clip.
    RawFile r = base;
    r.sections[0].flags = 1;
    r.sections[0].stored = zstd_raw_frame(clip_raw, 32);
    r.sections[0].raw_size = 32;
    const Loaded l = load(r.build());
    REQUIRE(l.status == Status::ok);
    check_same_clip(l.clip, keyanim::offline::to_clip(vector_uniform()));
  }
  auto compressed_clip = [&](std::vector<uint8_t> stored, uint64_t raw) {
    RawFile r = base;
    r.sections[0].flags = 1;
    r.sections[0].stored = std::move(stored);
    r.sections[0].raw_size = raw;
    return r.build();
  };
  CHECK_FAILS(compressed_clip(zstd_raw_frame(clip_raw, -1), 32), Status::zstd_error, clip);  // no size
  CHECK_FAILS(compressed_clip(zstd_raw_frame(clip_raw, 31), 32), Status::zstd_error, clip);  // declared != raw
  CHECK_FAILS(compressed_clip(zstd_raw_frame(clip_raw, 32), 31), Status::zstd_error, clip);
  CHECK_FAILS(compressed_clip(clip_raw, 32), Status::zstd_error, clip);  // not a frame
  // A section whose declared size its parse must refuse is refused before it is inflated: a
  // CLIP of 1000 MiB from 32 KB of RLE blocks (the loader used to allocate and inflate it).
  CHECK_FAILS(compressed_clip(zstd_rle_frame(1000ull << 20, 0), 1000ull << 20), Status::corrupt, clip);
  {
    RawFile r = base;  // a KTIM of more than 5 bytes a key, compressed
    RawSection& ktim = r.get("KTIM");
    const uint64_t raw = 64ull << 20;
    ktim.flags = 1, ktim.stored = zstd_rle_frame(raw, 0), ktim.raw_size = raw;
    CHECK_FAILS(r.build(), Status::corrupt, r.offset_of("KTIM"));
    // Said from its declared size (inflated, its zeros would fail later, as other faults).
    CHECK(load(r.build()).err.detail.find("longer than its key frames' varints") != std::string::npos);
  }
  {
    auto two = zstd_raw_frame(clip_raw, 32);
    two.push_back(0);  // a byte after the frame
    CHECK_FAILS(compressed_clip(two, 32), Status::zstd_error, clip);
  }
  {
    auto lying = zstd_raw_frame(clip_raw, 32);
    lying[6] = uint8_t(1 | (31u << 3));  // block says 31 bytes: frame and section disagree
    lying[7] = 0;
    CHECK_FAILS(compressed_clip(lying, 32), Status::zstd_error, clip);
  }
  {
    // A field error inside a compressed section is reported at the section's offset.
    auto raw = clip_raw;
    raw[12] = 9;
    CHECK_FAILS(compressed_clip(zstd_raw_frame(raw, 32), 32), Status::reserved_bits_set, clip);
  }
}

// Spec section 8, limits that follow from the file's size: no zstd frame makes more than 32768
// bytes of each of its bytes, and a key takes a byte of KTIM at least, so a file of N bytes
// holds at most 32768 N keys, and a section at most 32768 times its stored bytes. A count
// beyond is refused where it is read (CLIP's Key_Count, the table's Raw_Size), before any
// section is inflated or anything it sizes allocated, with the status a later step would give
// (corrupt, zstd_error): the files here are a few hundred bytes.
TEST_CASE("crafted counts beyond what the file's size can hold") {
  const RawFile base = base_file();
  const size_t n = base.build().size();
  uint32_t channels = 0;
  std::memcpy(&channels, base.sections[0].stored.data() + 8, 4);
  auto with_keys = [&](uint64_t keys) {
    RawFile r = base;
    poke(r.sections[0].stored, 0, uint32_t(1) << 24);  // Frame_Count 2^24: C x F allows the keys
    poke(r.sections[0].stored, 24, keys);
    return r.build();
  };
  const uint64_t most = 32768 * uint64_t(n);
  const uint64_t cf = uint64_t(channels) << 24;
  REQUIRE(cf > most);  // within Channel_Count x Frame_Count and the default limits
  REQUIRE(most + 1 <= keyanim::DecodeLimits{}.max_keys);
  CHECK_FAILS(with_keys(most + 1), Status::corrupt, base.offset_of("CLIP") + 24);
  CHECK(load(with_keys(most + 1)).err.detail.find("more than a file of " + std::to_string(n) + " bytes can hold") !=
        std::string::npos);
  CHECK_FAILS(with_keys(cf), Status::corrupt, base.offset_of("CLIP") + 24);
  // At the bound the rule lets the file through (CHAN's key counts then disagree with CLIP's).
  CHECK(load(with_keys(most)).status == Status::corrupt);
  CHECK(load(with_keys(most)).err.section == std::string("CHAN"));
  {
    // A NOTE declaring 1 GiB - 1 MiB behind a frame of 64 KiB (a few bytes): refused at the
    // table (before, once its frame's blocks were walked). The note limit is raised here, so
    // that the bound is what refuses it.
    keyanim::DecodeLimits roomy;
    roomy.max_note_bytes = 1ull << 30;
    auto fails_at = [&](const std::vector<uint8_t>& f, Status want, uint64_t at) {
      const Loaded l = load(f, roomy);
      CHECK_MESSAGE(l.status == want, keyanim::status_string(l.status) << " " << l.err.section << ": " << l.err.detail);
      CHECK(l.err.byte_offset == at);
      return l.err.detail;
    };
    RawFile r = base;
    RawSection note;
    note.tag = "NOTE";
    note.flags = 3;  // compressed, ancillary
    note.stored = zstd_rle_frame(64 << 10, 'a');
    note.raw_size = (1ull << 30) - (1ull << 20);
    r.sections.push_back(note);
    const size_t entry = 24 + 24 * (r.sections.size() - 1);
    const uint64_t frame_most = 32768 * uint64_t(note.stored.size());
    REQUIRE(note.raw_size > frame_most);
    CHECK(fails_at(r.build(), Status::zstd_error, entry + 16).find("stored bytes can make") != std::string::npos);
    r.sections.back().raw_size = frame_most + 1;  // one byte beyond the bound
    fails_at(r.build(), Status::zstd_error, entry + 16);
    r.sections.back().raw_size = frame_most;  // at it: the frame's blocks then refuse it
    CHECK(load(r.build(), roomy).err.section == std::string("NOTE"));
    // The same NOTE declared as what its frame makes loads.
    r.sections.back().raw_size = 64 << 10;
    const Loaded l = load(r.build());
    REQUIRE(l.status == Status::ok);
    CHECK(l.clip.encoder_notes() == std::string(64 << 10, 'a'));
  }
  {
    // A valid NOTE of 600 MiB from 19 KB of RLE blocks, within the bound: the note limit
    // (16 MiB by default) refuses it from the table; one of 16 MiB loads.
    RawFile r = base;
    RawSection note;
    note.tag = "NOTE";
    note.flags = 3;
    note.stored = zstd_rle_frame(600ull << 20, 'a');
    note.raw_size = 600ull << 20;
    r.sections.push_back(note);
    REQUIRE(r.build().size() < 20000);
    CHECK_FAILS(r.build(), Status::limit_exceeded, 24 + 24 * (r.sections.size() - 1) + 16);
    CHECK(load(r.build()).err.detail.find("NOTE declares 629145600 bytes, above the limit of 16777216") != std::string::npos);
    r.sections.back().stored = zstd_rle_frame(16ull << 20, 'a');
    r.sections.back().raw_size = 16ull << 20;
    const Loaded l = load(r.build());
    REQUIRE(l.status == Status::ok);
    CHECK(l.clip.encoder_notes().size() == (16u << 20));
  }
}

TEST_CASE("load_file reports I/O errors") {
  Clip c;
  ErrorInfo err;
  CHECK(Clip::load_file("/nonexistent/dir/x.kanim", c, &err) == Status::io_error);
  CHECK(err.status == Status::io_error);
  const std::string path = vector_path("v1_rules", ".kanim");
  CHECK(Clip::load_file(path, c, &err) == Status::ok);
  keyanim::DecodeLimits lim;
  lim.max_decompressed_bytes = 10;
  CHECK(Clip::load_file(path, c, &err, lim) == Status::limit_exceeded);
}

}  // TEST_SUITE("container")
