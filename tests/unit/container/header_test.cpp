// Crafted headers and section tables, truncations, single-byte changes, trailing bytes, the
// checksum, and declared counts above the limits (refused before anything is allocated).
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

TEST_CASE("crafted headers: signature version flags") {
  const RawFile base = base_file();
  const auto good = base.build();
  REQUIRE(load(good).status == Status::ok);
  {
    auto f = good;
    f[3] ^= 0x20;
    CHECK_FAILS(f, Status::bad_signature, 3);
  }
  CHECK_FAILS(std::vector<uint8_t>({'B', 'V', 'H'}), Status::bad_signature, 0);
  {
    RawFile r = base;
    r.major = keyanim::kNewestFormatVersionMajor + 1;  // 4 is a valid archive version (spec 9)
    CHECK_FAILS(r.build(), Status::unsupported_version, 8);
    r.major = 0;
    CHECK_FAILS(r.build(), Status::unsupported_version, 8);
  }
  {
    RawFile r = base;
    r.minor = 7;  // a later minor version: readable
    CHECK(load(r.build()).status == Status::ok);
  }
  {
    RawFile r = base;
    r.header_flags = 1;
    CHECK_FAILS(r.build(), Status::reserved_bits_set, 12);
    r.header_flags = 0x8000;
    CHECK_FAILS(r.build(), Status::reserved_bits_set, 12);
    r.header_flags = 0x10000;  // unused bit: ignored
    CHECK(load(r.build()).status == Status::ok);
  }
  {
    RawFile r = base;
    r.reserved = 1;
    CHECK_FAILS(r.build(), Status::reserved_bits_set, 20);
  }
}

TEST_CASE("crafted tables: flags tags order sizes") {
  const RawFile base = base_file();
  {
    RawFile r = base;
    r.sections[1].flags = 1u << 2;  // reserved
    CHECK_FAILS(r.build(), Status::reserved_bits_set, 24 + 24 + 4);
    r.sections[1].flags = 1u << 16;  // unused
    CHECK(load(r.build()).status == Status::ok);
  }
  {
    RawFile r = base;
    r.sections.insert(r.sections.begin() + 2, RawSection{"ZZZZ", 0, {1, 2, 3}, 3});
    CHECK_FAILS(r.build(), Status::reserved_bits_set, 24 + 2 * 24);
    r.sections[2].flags = 2;  // ancillary: skipped
    const Loaded l = load(r.build());
    CHECK(l.status == Status::ok);
    // ... even when it claims to be compressed and is not a zstd frame at all.
    r.sections[2].flags = 3;
    r.sections[2].raw_size = 1000;
    CHECK(load(r.build()).status == Status::ok);
  }
  {
    RawFile r = base;
    std::swap(r.sections[2], r.sections[3]);  // KTIM before CHAN
    CHECK_FAILS(r.build(), Status::corrupt, 24 + 2 * 24);
  }
  {
    RawFile r = base;
    r.sections.pop_back();  // no KVAL (the base has no NOTE)
    REQUIRE(r.sections.size() == 4);
    CHECK_FAILS(r.build(), Status::corrupt, 24);
  }
  {
    RawFile r = base;
    r.sections.push_back(r.sections[0]);  // a second CLIP
    CHECK_FAILS(r.build(), Status::corrupt, 24 + 5 * 24);
  }
  {
    RawFile r = base;
    r.sections[0].flags = 2;  // CLIP marked ancillary
    CHECK_FAILS(r.build(), Status::corrupt, 24 + 4);
  }
  {
    RawFile r = base;
    r.sections.push_back(RawSection{"NOTE", 2, {'a'}, 1});
    r.sections.push_back(RawSection{"NOTE", 2, {'b'}, 1});
    CHECK_FAILS(r.build(), Status::corrupt, 24 + 6 * 24);
    r.sections.pop_back();
    r.sections.back().flags = 0;  // NOTE must be ancillary
    CHECK_FAILS(r.build(), Status::corrupt, 24 + 5 * 24 + 4);
  }
  {
    // Uncompressed with Raw_Size != Stored_Size.
    auto f = base.build();
    poke<uint64_t>(f, 24 + 24 + 16, 7);
    CHECK_FAILS(f, Status::corrupt, 24 + 24 + 8);
  }
  {
    // A huge Stored_Size: the file is shorter than declared.
    auto f = base.build();
    poke<uint64_t>(f, 24 + 8, ~uint64_t(0));
    poke<uint64_t>(f, 24 + 16, ~uint64_t(0));
    CHECK_FAILS(f, Status::truncated, f.size());
    // A huge Section_Count.
    auto g = base.build();
    poke<uint32_t>(g, 16, 0xFFFFFFFFu);
    CHECK_FAILS(g, Status::truncated, g.size());
  }
}

TEST_CASE("every truncation is reported as truncated and never crashes") {
  for (const auto& e : {vector_uniform(), vector_long()}) {
    const auto good = keyanim::offline::write_kanim(e);
    for (size_t len = 0; len < good.size(); ++len) {
      const std::vector<uint8_t> cut(good.begin(), good.begin() + long(len));
      const Loaded l = load(cut);
      CHECK_MESSAGE(l.status == Status::truncated, "length " << len << ": " << keyanim::status_string(l.status));
    }
  }
}

TEST_CASE("every single-byte change is rejected and never crashes") {
  for (const auto& e : {vector_uniform(), vector_long()}) {
    const auto good = keyanim::offline::write_kanim(e);
    uint64_t accepted = 0;
    for (size_t i = 0; i < good.size(); ++i) {
      for (uint8_t mask : {uint8_t(0x01), uint8_t(0x80), uint8_t(0xFF)}) {
        auto f = good;
        f[i] ^= mask;
        accepted += load(f).status == Status::ok;
      }
    }
    CHECK(accepted == 0);
  }
}

TEST_CASE("trailing bytes and a wrong checksum") {
  const auto good = base_file().build();
  auto longer = good;
  longer.push_back(0);
  CHECK_FAILS(longer, Status::trailing_bytes, good.size());
  auto bad = good;
  bad.back() ^= 1;
  CHECK_FAILS(bad, Status::checksum_mismatch, good.size() - 4);
  auto inside = good;
  inside[good.size() / 2] ^= 4;
  CHECK_FAILS(inside, Status::checksum_mismatch, good.size() - 4);
}

TEST_CASE("declared counts above the limits are refused before allocation") {
  const RawFile base = base_file();
  const size_t clip = base.offset_of("CLIP");
  auto with_clip = [&](size_t at, auto value) {
    RawFile r = base;
    poke(r.get("CLIP").stored, at, value);
    return r.build();
  };
  // Above 2^24 frames a 3.x file breaks a rule; at 2^24 it only meets a decoder's limit.
  CHECK_FAILS(with_clip(0, uint32_t(0xFFFFFFFFu)), Status::corrupt, clip + 0);
  CHECK_FAILS(with_clip(0, uint32_t((1u << 24) + 1)), Status::corrupt, clip + 0);
  {
    keyanim::DecodeLimits lim;
    lim.max_frames = 1000;
    Clip out;
    keyanim::ErrorInfo err;
    CHECK(Clip::load(with_clip(0, uint32_t(1u << 24)), out, &err, lim) == Status::limit_exceeded);
    CHECK(err.byte_offset == clip + 0);
  }
  CHECK_FAILS(with_clip(4, uint32_t(0xFFFFFFFFu)), Status::limit_exceeded, clip + 4);
  CHECK_FAILS(with_clip(8, uint32_t(0xFFFFFFFFu)), Status::limit_exceeded, clip + 8);
  CHECK_FAILS(with_clip(24, uint64_t(1) << 40), Status::limit_exceeded, clip + 24);
  {
    // Within the default limits but not backed by data: rejected, not allocated.
    CHECK_FAILS(with_clip(4, uint32_t(60000)), Status::corrupt, base.offset_of("SKEL"));
  }
  {
    // A compressed section declaring a gigantic raw size.
    RawFile r = base;
    r.get("KVAL").flags = 1;
    r.get("KVAL").raw_size = uint64_t(1) << 40;
    CHECK_FAILS(r.build(), Status::limit_exceeded, 24 + 4 * 24 + 16);
  }
  {
    // The caller's own limits.
    const auto good = base.build();
    keyanim::DecodeLimits lim;
    lim.max_frames = 11;
    CHECK(load(good, lim).status == Status::limit_exceeded);
    lim = {};
    lim.max_keys = 10;
    CHECK(load(good, lim).status == Status::limit_exceeded);
    lim = {};
    lim.max_joints = 4;
    CHECK(load(good, lim).status == Status::limit_exceeded);
    lim = {};
    lim.max_channels = 4;
    CHECK(load(good, lim).status == Status::limit_exceeded);
    lim = {};
    lim.max_decompressed_bytes = 100;
    CHECK(load(good, lim).status == Status::limit_exceeded);
    lim.max_frames = 12;
    lim.max_keys = 18;
    lim.max_joints = 5;
    lim.max_channels = 5;
    lim.max_decompressed_bytes = 0;
    for (const auto& s : base.sections) lim.max_decompressed_bytes += s.stored.size();
    CHECK(load(good, lim).status == Status::ok);  // exactly at the limits
  }
}

}  // TEST_SUITE("container")
