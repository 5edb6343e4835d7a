// The .kanim container: write -> load round trips, every decoder obligation of spec/FORMAT.md
// on crafted files, decode_motion, and the spec's test vectors (whose expected values come from
// spec/test-vectors/reference_decoder.py, an independent Python implementation).
//
// Crafted files are assembled here by a small builder with its own CRC-32, not by the writer,
// so that a writer bug cannot hide a loader bug.
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

namespace {

using keyanim::ChannelType;
using keyanim::Clip;
using keyanim::ErrorInfo;
using keyanim::Interpolation;
using keyanim::Joint;
using keyanim::Status;
using keyanim::TangentRule;
using keyanim::offline::EncodedChannel;
using keyanim::offline::EncodedClip;

// ---------------------------------------------------------------------------------------------
// Hand-built clips. The test vectors are made from the first five: never change them.

Joint node(const char* name, int32_t parent, double x, double y, double z, std::vector<ChannelType> ch,
           bool end_site = false) {
  Joint j;
  j.name = name;
  j.parent = parent;
  j.offset = {x, y, z};
  j.channels = std::move(ch);
  j.end_site = end_site;
  return j;
}

EncodedChannel chan(Interpolation interp, float tension, double step, std::vector<uint32_t> frames,
                    std::vector<int64_t> q) {
  EncodedChannel c;
  c.interp = interp;
  c.tension = tension;
  c.step = step;
  c.frames = std::move(frames);
  c.q = std::move(q);
  return c;
}

constexpr auto kCard = Interpolation::cardinal;
constexpr auto kLin = Interpolation::linear;
using CT = ChannelType;

// Step-adjusted rule, uneven spacing, tensions, linear, zero, constant and 2-key channels,
// position channels, a named End Site.
EncodedClip vector_rules() {
  EncodedClip c;
  c.skeleton.joints = {
      node("Hips", -1, 0, 0, 0, {CT::x_position, CT::y_position, CT::z_position, CT::z_rotation, CT::x_rotation, CT::y_rotation}),
      node("Chest", 0, 0, 10.5, 0, {CT::z_rotation, CT::x_rotation, CT::y_rotation}),
      node("Head_end", 1, 0, 5.25, 0.125, {}, true),
      node("LeftLeg", 0, 3, -2, 0, {CT::z_rotation, CT::x_rotation, CT::y_rotation}),
      node("", 3, 0, -8, 0, {}, true),
  };
  c.frame_count = 20;
  c.frame_time = 1.0 / 30.0;
  c.tangent_rule = TangentRule::step_adjusted;
  std::vector<uint32_t> all(20);
  std::vector<int64_t> dense(20);
  for (uint32_t i = 0; i < 20; ++i) {
    all[i] = i;
    dense[i] = int64_t(i * i) - 7 * int64_t(i);
  }
  c.channels = {
      chan(kCard, 0.0f, 0.01, {0, 3, 4, 10, 19}, {0, 150, 170, -30, 20}),
      chan(kLin, 0.0f, 0.01, {0, 7, 19}, {1000, 1200, 900}),
      chan(kCard, 0.0f, 1.0, {}, {}),
      chan(kCard, 0.0f, 0.1, {5}, {123}),
      chan(kCard, 0.3f, 0.5, {2, 15}, {-10, 40}),
      chan(kCard, -0.5f, 0.25, {0, 1, 2, 6, 12, 19}, {4, -4, 9, 30, 2, -17}),
      chan(kCard, 1.0f, 0.1, {0, 5, 10, 15, 19}, {0, 300, -200, 100, 50}),
      chan(kCard, 0.75f, 0.05, {0, 2, 9, 19}, {-100, 40, 900, 0}),
      chan(kCard, 0.0f, 0.2, {4, 8, 16}, {10, -10, 25}),
      chan(kCard, 0.0f, 0.125, all, dense),
      chan(kLin, 0.0f, 0.5, {0, 19}, {-7, 7}),
      chan(kCard, 0.25f, 1e-3, {0, 10}, {123456, -654321}),
  };
  return c;
}

// Uniform rule, two roots, keys not at the first or last frame, negative values.
EncodedClip vector_uniform() {
  EncodedClip c;
  c.skeleton.joints = {
      node("A", -1, 1, 2, 3, {CT::x_position, CT::y_rotation}),
      node("", 0, 0, 1, 0, {}, true),
      node("B", -1, -1, 0, 0.5, {CT::x_rotation, CT::z_rotation}),
      node("B1", 2, 0, 2, 0, {CT::y_rotation}),
      node("", 3, 0, 1, 0, {}, true),
  };
  c.frame_count = 12;
  c.frame_time = 0.0083333;
  c.tangent_rule = TangentRule::uniform;
  c.channels = {
      chan(kCard, 0.0f, 0.001, {1, 4, 5, 9}, {-5000, -2500, -2600, 100}),
      chan(kCard, 0.5f, 0.01, {0, 2, 4, 6, 8, 10, 11}, {0, -18000, -36000, -54000, -36000, -36500, -36400}),
      chan(kCard, -1.0f, 0.1, {3, 4, 10}, {-1, 1, -3}),
      chan(kLin, 0.0f, 0.1, {2, 8}, {-50, -20}),
      chan(kCard, 0.0f, 0.05, {0, 11}, {9, -9}),
  };
  return c;
}

// One frame, Frame_Time 0, notes.
EncodedClip vector_single() {
  EncodedClip c;
  c.skeleton.joints = {
      node("Root", -1, 0, 0, 0, {CT::y_position, CT::x_rotation, CT::z_rotation}),
      node("Tip", 0, 0, 0, 4, {}, true),
  };
  c.frame_count = 1;
  c.frame_time = 0.0;
  c.tangent_rule = TangentRule::step_adjusted;
  c.channels = {
      chan(kCard, 0.0f, 0.001, {0}, {95250}),
      chan(kCard, 0.0f, 0.01, {}, {}),
      chan(kLin, 0.0f, 0.01, {0}, {-18000}),
  };
  c.notes = "encoder=test-vectors\nmode=manual\n";
  return c;
}

// Long enough that zstd shrinks the key sections: compressed KTIM/KVAL/NOTE for readers.
EncodedClip vector_long() {
  EncodedClip c;
  c.skeleton.joints = {
      node("Pelvis", -1, 0, 90, 0, {CT::x_position, CT::y_position, CT::z_position, CT::y_rotation}),
      node("Spine", 0, 0, 12, 0, {CT::z_rotation, CT::y_rotation, CT::x_rotation}),
      node("", 1, 0, 20, 0, {}, true),
  };
  c.frame_count = 240;
  c.frame_time = 1.0 / 120.0;
  c.tangent_rule = TangentRule::step_adjusted;
  const uint32_t gaps[5] = {1, 2, 3, 5, 8};
  for (uint32_t ch = 0; ch < 7; ++ch) {
    EncodedChannel e;
    e.interp = ch == 3 ? kLin : kCard;
    e.tension = ch == 5 ? 0.2f : 0.0f;
    e.step = 0.001;
    uint32_t f = 0;
    for (uint32_t i = 0;; ++i) {
      e.frames.push_back(f);
      // A smooth integer-valued curve, so that the file does not depend on any libm.
      const int64_t x = int64_t(f) - 120;
      e.q.push_back((int64_t(ch) + 1) * (x * x * 3 - 40 * x) + int64_t(ch) * 1000);
      if (f == 239) break;
      const uint32_t gap = ch % 2 == 0 ? 4 : gaps[i % 5];
      f = f + gap > 239 ? 239 : f + gap;
    }
    c.channels.push_back(std::move(e));
  }
  std::string notes;
  for (int i = 0; i < 12; ++i) notes += "note" + std::to_string(i) + "=the same words again and again\n";
  c.notes = notes;
  return c;
}

// Version 2.0's value prediction (spec 4.5): ramps the extrapolation predicts exactly, halves
// rounded up for positive and negative deltas, a gap of 2^16 frames or more and deltas of 2^40
// or more (both fall back to repeating the delta), and a noisy channel that stays delta-coded.
EncodedClip vector_predict() {
  EncodedClip c;
  c.skeleton.joints = {node("Root", -1, 0, 0, 0, {CT::x_position, CT::y_position, CT::z_position, CT::z_rotation}),
                       node("Tip", 0, 0, 1, 0, {CT::x_rotation}, false)};
  c.frame_count = 70001;
  c.frame_time = 1.0 / 30.0;
  c.tangent_rule = TangentRule::step_adjusted;
  std::vector<uint32_t> far = {0, 100, 200, 300, 400, 500, 600, 700, 800, 900, 1000, 67000, 67100, 70000};
  std::vector<int64_t> ramp;
  for (uint32_t f : far) ramp.push_back(40 * int64_t(f));
  c.channels.push_back(chan(kCard, 0.0f, 0.01, far, ramp));
  std::vector<uint32_t> tight = {0, 1, 3, 4, 6, 7, 9, 10, 12};
  std::vector<int64_t> huge;
  for (size_t i = 0; i < tight.size(); ++i) huge.push_back(int64_t(tight[i]) * (int64_t(1) << 41) - (int64_t(1) << 52));
  c.channels.push_back(chan(kCard, 0.0f, 1e-12, tight, huge));
  std::vector<uint32_t> halves = {0, 2, 3, 5, 6, 8, 9, 11, 12, 14, 15, 17, 18, 20};
  std::vector<int64_t> up, down;
  for (uint32_t f : halves) up.push_back(301 * int64_t(f) / 2), down.push_back(-(301 * int64_t(f) + 1) / 2 + 7);
  c.channels.push_back(chan(kCard, 0.5f, 0.001, halves, up));
  c.channels.push_back(chan(kLin, 0.0f, 0.001, halves, down));
  std::vector<int64_t> noisy;
  for (size_t i = 0; i < halves.size(); ++i) noisy.push_back((i * 7919) % 13 - 6);
  c.channels.push_back(chan(kCard, 0.0f, 0.5, halves, noisy));
  return c;
}

// Version 3.0 adds nothing for blocks to the file, but a decoder's runtime layout (keyanim's:
// 64-frame blocks, spec Appendix F) meets its limits here: keys on both sides of every block
// boundary, a block full of keys, a gap of 40 000 frames (context frames 2^15 and more away),
// curves that start and end inside blocks, 2 keys in adjacent blocks, values across the whole
// +-2^53 range; and a sparse channel, which keyanim keeps as a plain list of keys. (Every other
// curve has keys on the last 300 frames too, so that keyanim gives it records.)
EncodedClip vector_blocks() {
  EncodedClip c;
  c.skeleton.joints = {
      node("Root", -1, 0, 0, 0, {CT::x_position, CT::y_position, CT::z_position, CT::z_rotation, CT::x_rotation, CT::y_rotation}),
      node("Arm", 0, 4, 1, 0, {CT::z_rotation, CT::x_rotation, CT::y_rotation}),
      node("Hand", 1, 0, 2, 0, {CT::z_rotation, CT::y_rotation}),
      node("", 2, 0.5, 0, 0, {}, true),
  };
  c.frame_count = 70000;
  c.frame_time = 1.0 / 120.0;
  c.tangent_rule = TangentRule::step_adjusted;
  // Keys at frames 69700 .. 69999 after a curve's own, with values from `seed`.
  auto with_tail = [](std::vector<uint32_t> frames, std::vector<int64_t> values, int64_t seed) {
    for (uint32_t f = 69700; f < 70000; ++f) {
      if (!frames.empty() && frames.back() >= f) continue;
      frames.push_back(f);
      values.push_back((int64_t(f) * (seed + 7)) % 23 - 11);
    }
    return std::make_pair(frames, values);
  };
  auto add = [&](Interpolation interp, float tension, double step, std::vector<uint32_t> frames,
                 std::vector<int64_t> values, int64_t seed) {
    auto [f, v] = with_tail(std::move(frames), std::move(values), seed);
    c.channels.push_back(chan(interp, tension, step, f, v));
  };
  std::vector<uint32_t> edges = {0, 1, 62, 63, 64, 65, 127, 128, 191, 192, 255, 256, 1000};
  std::vector<int64_t> ev;
  for (size_t i = 0; i < edges.size(); ++i) ev.push_back((int64_t(i) * 37) % 11 * 100 - 500);
  add(kCard, 0.0f, 0.01, edges, ev, 1);
  std::vector<uint32_t> full;
  std::vector<int64_t> fv;
  for (uint32_t f = 128; f < 256; ++f) full.push_back(f), fv.push_back(int64_t(f % 7) * 13 - int64_t(f / 9));
  add(kCard, 0.25f, 0.02, full, fv, 2);                             // blocks 2 and 3 full
  add(kCard, 0.0f, 0.1, {0, 5, 40000}, {10, -20, 30}, 3);           // a 40 000-frame gap
  add(kCard, -0.5f, 0.05, {70, 75, 200}, {5, -5, 15}, 4);            // starts inside a block
  add(kLin, 0.0f, 0.1, {63, 64}, {-1000, 1000}, 5);                  // two keys, adjacent blocks
  const int64_t big = int64_t(1) << 53;
  add(kCard, 0.0f, 1e-20, {0, 64, 65, 129}, {big, -big, big - 1, -big + 1}, 6);
  c.channels.push_back(chan(kCard, 0.0f, 0.5, {}, {}));      // zero
  c.channels.push_back(chan(kCard, 0.0f, 0.5, {33}, {-7}));  // constant
  std::vector<uint32_t> sparse;                               // a list curve: 15 keys
  std::vector<int64_t> sv;
  for (uint32_t f = 0; f < 70000; f += 4999) sparse.push_back(f), sv.push_back(int64_t(f / 4999) * int64_t(f / 4999) * 50);
  sparse.push_back(69999), sv.push_back(0);
  c.channels.push_back(chan(kCard, 0.1f, 0.001, sparse, sv));
  add(kLin, 0.0f, 0.25, {100, 160, 161, 224, 288, 289, 352}, {1, 2, 3, 4, 5, 6, 7}, 8);
  c.channels.push_back(chan(kCard, 0.0f, 0.125, {0, 69999}, {-3, 3}));  // a list curve: 2 keys
  return c;
}

// A bigger pseudo-random clip: many densities, so that the segment index and cursor meet every
// case (dense channels, sparse ones, keys far from the ends).
uint64_t lcg(uint64_t& s) {
  s = s * 6364136223846793005ull + 1442695040888963407ull;
  return s >> 33;
}

EncodedClip random_clip(uint64_t seed, uint32_t frames, uint32_t joints) {
  EncodedClip c;
  uint64_t s = seed;
  for (uint32_t j = 0; j < joints; ++j) {
    std::vector<ChannelType> ch;
    if (j == 0) ch = {CT::x_position, CT::y_position, CT::z_position};
    ch.insert(ch.end(), {CT::z_rotation, CT::x_rotation, CT::y_rotation});
    std::string name = "j";
    name += std::to_string(j);  // not "j" + ...: GCC 12 warns falsely (-Wrestrict)
    c.skeleton.joints.push_back(node(name.c_str(), j == 0 ? -1 : int32_t(lcg(s) % j), 1, 2, 3, ch));
  }
  c.skeleton.joints.push_back(node("end", 1, 0, 1, 0, {}, true));
  c.frame_count = frames;
  c.frame_time = 1.0 / 120.0;
  c.tangent_rule = seed % 2 ? TangentRule::step_adjusted : TangentRule::uniform;
  const uint32_t channels = c.skeleton.channel_count();
  for (uint32_t ch = 0; ch < channels; ++ch) {
    EncodedChannel e;
    e.interp = lcg(s) % 5 == 0 ? kLin : kCard;
    e.tension = float(int(lcg(s) % 21) - 10) / 10.0f;
    e.step = 1e-3 * double(1 + lcg(s) % 10);
    const uint32_t kind = ch % 7;
    const uint32_t density = kind == 0 ? 1 : kind == 1 ? 2 : kind == 2 ? 40 : kind == 3 ? 300 : 6;
    if (kind == 4 && ch % 2 == 0) {  // zero channel
      c.channels.push_back(e);
      continue;
    }
    const bool inner = kind == 5 && frames > 40;  // keys away from both ends
    for (uint32_t f = inner ? 17 : 0; f < (inner ? frames - 13 : frames); ++f) {
      if (f == 0 || lcg(s) % density == 0) {
        e.frames.push_back(f);
        e.q.push_back(int64_t(lcg(s) % 200001) - 100000);
      }
    }
    c.channels.push_back(std::move(e));
  }
  return c;
}

std::vector<uint8_t> read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Every array a decoder builds, field by field.
void check_same_clip(const Clip& a, const Clip& b) {
  REQUIRE(a.frame_count() == b.frame_count());
  REQUIRE(a.channel_count() == b.channel_count());
  CHECK(a.frame_time() == b.frame_time());
  CHECK(a.tangent_rule() == b.tangent_rule());
  CHECK(a.total_keys() == b.total_keys());
  CHECK(a.encoder_notes() == b.encoder_notes());
  REQUIRE(a.skeleton().joints.size() == b.skeleton().joints.size());
  for (size_t i = 0; i < a.skeleton().joints.size(); ++i) {
    const Joint& x = a.skeleton().joints[i];
    const Joint& y = b.skeleton().joints[i];
    CHECK(x.name == y.name);
    CHECK(x.parent == y.parent);
    CHECK(std::memcmp(x.offset.data(), y.offset.data(), sizeof x.offset) == 0);
    CHECK(x.channels == y.channels);
    CHECK(x.end_site == y.end_site);
    CHECK(x.first_channel == y.first_channel);
  }
  for (uint32_t c = 0; c < a.channel_count(); ++c) {
    CHECK(a.channel(c).key_count == b.channel(c).key_count);
    CHECK(a.channel(c).interp == b.channel(c).interp);
    CHECK(same_bits(a.channel(c).tension, b.channel(c).tension));
    const keyanim::test::ChannelKeys ka = keyanim::test::channel_keys(a, c), kb = keyanim::test::channel_keys(b, c);
    CHECK(ka.frames == kb.frames);
    REQUIRE(ka.values.size() == kb.values.size());
    for (size_t k = 0; k < ka.values.size(); ++k) CHECK(same_bits(ka.values[k], kb.values[k]));
  }
}

// Samples every quarter frame (and outside the clip) of both clips, bit-exactly, and checks
// each against eval_channel on the clip's own arrays.
void check_same_samples(const Clip& a, const Clip& b) {
  const uint32_t n = a.channel_count();
  std::vector<float> sa(n), sb(n);
  keyanim::Cursor cursor;
  REQUIRE(cursor.prepare(b) == Status::ok);
  const auto keys = keyanim::test::all_channel_keys(a);
  uint64_t mismatches = 0, eval_mismatches = 0;
  const double end = double(a.frame_count()) + 1.0;
  for (double x = -2.0; x <= end; x += 0.25) {
    REQUIRE(a.sample(x, sa) == Status::ok);
    REQUIRE(b.sample(x, sb, &cursor) == Status::ok);
    for (uint32_t c = 0; c < n; ++c) {
      if (!same_bits(sa[c], sb[c])) ++mismatches;
      if (!same_bits(sa[c], keyanim::test::reference_value(a, keys[c], float(x)))) ++eval_mismatches;
    }
  }
  CHECK(mismatches == 0);
  CHECK(eval_mismatches == 0);
}

// ---------------------------------------------------------------------------------------------
// A file builder for crafted files, independent of the writer.

uint32_t crc32_ref(const uint8_t* p, size_t n) {
  uint32_t crc = 0xFFFFFFFFu;
  for (size_t i = 0; i < n; ++i) {
    crc ^= p[i];
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return crc ^ 0xFFFFFFFFu;
}

template <typename T>
void put(std::vector<uint8_t>& v, T x) {
  uint8_t b[sizeof(T)];
  std::memcpy(b, &x, sizeof(T));  // the test machines are little-endian (checked below)
  v.insert(v.end(), b, b + sizeof(T));
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
RawFile split(const std::vector<uint8_t>& f) {
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
std::vector<uint8_t> zstd_raw_frame(const std::vector<uint8_t>& content, int fcs) {
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

struct Loaded {
  Status status;
  ErrorInfo err;
  Clip clip;
};

Loaded load(const std::vector<uint8_t>& bytes, const keyanim::DecodeLimits& limits = {}) {
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
RawFile base_file() {
  const auto bytes = keyanim::offline::write_kanim(vector_uniform(), 0);
  RawFile r = split(bytes);
  for (const auto& s : r.sections) REQUIRE((s.flags & 1) == 0);  // crafting needs raw sections
  REQUIRE(r.build() == bytes);  // the builder reproduces the writer byte for byte
  return r;
}

// ---------------------------------------------------------------------------------------------
// A minimal JSON reader for the test vectors' expected values.

struct Json {
  enum Kind { null, boolean, number, string, array, object } kind = null;
  double num = 0;
  bool b = false;
  std::string str;
  std::vector<Json> arr;
  std::map<std::string, Json> obj;
  const Json& operator[](const std::string& k) const {
    static const Json none;
    auto it = obj.find(k);
    return it == obj.end() ? none : it->second;
  }
};

struct JsonParser {
  const std::string& s;
  size_t i = 0;
  bool ok = true;
  void ws() {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\n' || s[i] == '\r' || s[i] == '\t')) ++i;
  }
  Json value() {
    ws();
    Json j;
    if (i >= s.size()) {
      ok = false;
      return j;
    }
    const char c = s[i];
    if (c == '{') {
      j.kind = Json::object;
      ++i;
      ws();
      if (s[i] == '}') return ++i, j;
      while (ok) {
        ws();
        const std::string k = value().str;
        ws();
        if (s[i++] != ':') ok = false;
        j.obj[k] = value();
        ws();
        if (s[i] == ',') ++i;
        else if (s[i] == '}') return ++i, j;
        else ok = false;
      }
    } else if (c == '[') {
      j.kind = Json::array;
      ++i;
      ws();
      if (s[i] == ']') return ++i, j;
      while (ok) {
        j.arr.push_back(value());
        ws();
        if (s[i] == ',') ++i;
        else if (s[i] == ']') return ++i, j;
        else ok = false;
      }
    } else if (c == '"') {
      j.kind = Json::string;
      ++i;
      while (i < s.size() && s[i] != '"') {
        if (s[i] == '\\') {
          ++i;
          const char e = s[i];
          j.str += e == 'n' ? '\n' : e == 't' ? '\t' : e;  // \uXXXX is not used by the vectors
        } else {
          j.str += s[i];
        }
        ++i;
      }
      ++i;
    } else if (s.compare(i, 4, "true") == 0 || s.compare(i, 5, "false") == 0) {
      j.kind = Json::boolean;
      j.b = s[i] == 't';
      i += j.b ? 4 : 5;
    } else if (s.compare(i, 4, "null") == 0) {
      i += 4;
    } else {
      j.kind = Json::number;
      char* end = nullptr;
      j.num = std::strtod(s.c_str() + i, &end);
      if (end == s.c_str() + i) ok = false;
      i = size_t(end - s.c_str());
    }
    return j;
  }
};

// Version 1.0 files are frozen (written by the 1.0 writer); the current writer makes the rest.
const char* const kVectorNames[] = {"v1_rules",  "v1_uniform", "v1_single",  "v1_long",   "v2_rules",
                                    "v2_long",   "v2_predict", "v3_rules",   "v3_uniform", "v3_single",
                                    "v3_long",   "v3_predict", "v3_blocks"};
EncodedClip vector_clip(const std::string& name) {
  const std::string kind = name.substr(3);
  if (kind == "rules") return vector_rules();
  if (kind == "uniform") return vector_uniform();
  if (kind == "single") return vector_single();
  if (kind == "predict") return vector_predict();
  if (kind == "blocks") return vector_blocks();
  return vector_long();
}
std::string vector_path(const std::string& name, const char* ext) {
  return std::string(KEYANIM_SPEC_DIR) + "/test-vectors/" + name + ext;
}

}  // namespace

TEST_SUITE("container") {

TEST_CASE("the test machine is little-endian and the test CRC-32 is the standard one") {
  const uint16_t one = 1;
  uint8_t b[2];
  std::memcpy(b, &one, 2);
  REQUIRE(b[0] == 1);
  const char* check = "123456789";
  CHECK(crc32_ref(reinterpret_cast<const uint8_t*>(check), 9) == 0xCBF43926u);
}

TEST_CASE("write then load equals to_clip bit-exactly") {
  std::vector<EncodedClip> clips = {vector_rules(), vector_uniform(), vector_single(), vector_long(),
                                    random_clip(1, 500, 8), random_clip(2, 301, 31), random_clip(3, 2, 3)};
  for (const auto& e : clips) {
    CAPTURE(e.frame_count);
    REQUIRE_NOTHROW(keyanim::offline::validate_encoded_clip(e));
    const Clip ref = keyanim::offline::to_clip(e);
    for (int level : {0, 3, 19}) {
      const auto bytes = keyanim::offline::write_kanim(e, level);
      REQUIRE(!bytes.empty());
      const Loaded l = load(bytes);
      REQUIRE_MESSAGE(l.status == Status::ok, l.err.section << " " << l.err.detail);
      check_same_clip(l.clip, ref);
      check_same_samples(l.clip, ref);
      CHECK(l.clip.version_major() == keyanim::kFormatVersionMajor);
      CHECK(l.clip.version_minor() == 0);
    }
  }
}

TEST_CASE("key values are dequantized as float of q times step in double") {
  EncodedClip e = vector_rules();
  const Loaded l = load(keyanim::offline::write_kanim(e));
  REQUIRE(l.status == Status::ok);
  // Channel 11: q = 123456 and -654321 at step 1e-3, computed in double then rounded.
  const keyanim::test::ChannelKeys k11 = keyanim::test::channel_keys(l.clip, 11);
  REQUIRE(k11.values.size() == 2);
  CHECK(k11.values[0] == float(123456 * 1e-3));
  CHECK(k11.values[1] == float(-654321 * 1e-3));
  CHECK(keyanim::test::channel_keys(l.clip, 2).values.empty());
  float v = -1.0f;
  CHECK(l.clip.sample_channel(2, 7.5f, v) == Status::ok);
  CHECK(v == 0.0f);
  CHECK(l.clip.sample_channel(3, 0.0f, v) == Status::ok);
  CHECK(v == float(123 * 0.1));  // a constant before its key
  // A channel the clip does not have, or a NaN position: refused, `v` unchanged.
  CHECK(l.clip.sample_channel(l.clip.channel_count(), 0.0f, v) == Status::invalid_argument);
  CHECK(l.clip.sample_channel(3, std::nanf(""), v) == Status::invalid_argument);
  CHECK(v == float(123 * 0.1));
}

TEST_CASE("the cursor never changes a result") {
  const EncodedClip e = random_clip(7, 400, 10);
  const Clip clip = keyanim::offline::to_clip(e);
  const Clip other = keyanim::offline::to_clip(random_clip(8, 50, 2));
  const uint32_t n = clip.channel_count();
  std::vector<float> a(n), b(n), o(other.channel_count());
  keyanim::Cursor cursor;
  REQUIRE(cursor.prepare(clip) == Status::ok);
  CHECK(cursor.prepared_for(clip));
  CHECK(!cursor.prepared_for(other));
  uint64_t s = 99, mismatches = 0;
  for (int i = 0; i < 3000; ++i) {
    // Forward steps, backward jumps, far jumps; a second clip refuses the cursor.
    double x = i < 1000 ? i * 0.37 : i < 2000 ? 400.0 - (i - 1000) * 0.41 : double(lcg(s) % 40000) / 97.0;
    if (i % 500 == 0) REQUIRE(other.sample(x, o, &cursor) == Status::invalid_argument);
    if (i == 2500) REQUIRE(cursor.prepare(clip) == Status::ok);  // a fresh state mid-way
    REQUIRE(clip.sample(x, a) == Status::ok);
    REQUIRE(clip.sample(x, b, &cursor) == Status::ok);
    for (uint32_t c = 0; c < n; ++c) mismatches += !same_bits(a[c], b[c]);
  }
  CHECK(mismatches == 0);
  // A copy of the clip shares its image, and the cursor.
  const Clip copy = clip;
  CHECK(cursor.prepared_for(copy));
  // An unprepared cursor is refused, and a new clip at the address of a destroyed one is a
  // different clip for the cursor.
  keyanim::Cursor none;
  CHECK(clip.sample(1.0, a, &none) == Status::invalid_argument);
  std::optional<Clip> slot;
  slot.emplace(keyanim::offline::to_clip(random_clip(21, 300, 4)));
  std::vector<float> x(slot->channel_count()), y(slot->channel_count());
  keyanim::Cursor reused;
  REQUIRE(reused.prepare(*slot) == Status::ok);
  REQUIRE(slot->sample(150.5, x, &reused) == Status::ok);
  slot.emplace(keyanim::offline::to_clip(random_clip(22, 300, 4)));
  REQUIRE(slot->channel_count() == x.size());
  CHECK(slot->sample(150.5, x, &reused) == Status::invalid_argument);
  REQUIRE(reused.prepare(*slot) == Status::ok);
  REQUIRE(slot->sample(150.5, x, &reused) == Status::ok);
  REQUIRE(slot->sample(150.5, y) == Status::ok);
  for (size_t c = 0; c < x.size(); ++c) CHECK(same_bits(x[c], y[c]));
}

TEST_CASE("sample_time sample_channels and argument errors") {
  const Clip clip = keyanim::offline::to_clip(vector_rules());
  std::vector<float> all(clip.channel_count()), some(3);
  REQUIRE(clip.sample(7.25, all) == Status::ok);
  const uint32_t pick[3] = {9, 0, 5};
  REQUIRE(clip.sample_channels(7.25, pick, some) == Status::ok);
  CHECK(same_bits(some[0], all[9]));
  CHECK(same_bits(some[1], all[0]));
  CHECK(same_bits(some[2], all[5]));
  float one = 0.0f;
  REQUIRE(clip.sample_channel(5, 7.25f, one) == Status::ok);
  CHECK(same_bits(one, all[5]));
  std::vector<float> t(clip.channel_count());
  REQUIRE(clip.sample_time(7.0 / 30.0, t) == Status::ok);  // frame 7 at 30 fps
  REQUIRE(clip.sample(7.0 / 30.0 / (1.0 / 30.0), all) == Status::ok);
  for (uint32_t c = 0; c < clip.channel_count(); ++c) CHECK(same_bits(t[c], all[c]));
  CHECK(clip.duration() == 19.0 / 30.0);
  CHECK(clip.sample(std::nan(""), all) == Status::invalid_argument);
  CHECK(clip.sample_time(std::nan(""), all) == Status::invalid_argument);
  std::vector<float> short_out(clip.channel_count() - 1);
  CHECK(clip.sample(1.0, short_out) == Status::output_too_small);
  const uint32_t bad[1] = {12};
  CHECK(clip.sample_channels(1.0, bad, some) == Status::invalid_argument);
  CHECK(clip.sample_channels(1.0, pick, std::span<float>(some.data(), 2)) == Status::output_too_small);
  // A single-frame clip with Frame_Time 0 samples its only frame at any time.
  const Clip single = keyanim::offline::to_clip(vector_single());
  std::vector<float> s3(3);
  REQUIRE(single.sample_time(5.0, s3) == Status::ok);
  CHECK(s3[0] == float(95250 * 0.001));
  CHECK(single.duration() == 0.0);
}

TEST_CASE("a loaded clip holds its keys bit-packed, not expanded") {
  for (uint64_t seed : {11u, 12u, 13u}) {
    const EncodedClip e = random_clip(seed, 2000, 12);
    const Clip clip = keyanim::offline::to_clip(e);
    // Each key costs its value's bits in at most two records (its block's, and as context of
    // a neighbouring block), plus per-record headers; expanded arrays cost 8 bytes a key.
    uint64_t value_bits = 0;
    for (const auto& ch : e.channels) {
      if (ch.q.size() < 2) continue;
      const auto [lo, hi] = std::minmax_element(ch.q.begin(), ch.q.end());
      value_bits += 3 * ch.q.size() * std::bit_width(uint64_t(*hi - *lo));
    }
    const size_t records = e.channels.size() * ((e.frame_count + 63) / 64);
    CHECK(clip.memory_bytes() <= value_bits / 8 + records * 40 + 16384);
    CHECK(clip.memory_bytes() < clip.total_keys() * 8);
  }
}

TEST_CASE("the writer refuses clips that break the spec") {
  auto bad = [](auto mutate) {
    EncodedClip e = vector_rules();
    mutate(e);
    CHECK_THROWS_AS(keyanim::offline::validate_encoded_clip(e), keyanim::offline::Error);
    CHECK_THROWS_AS(keyanim::offline::write_kanim(e), keyanim::offline::Error);
  };
  bad([](EncodedClip& e) { e.channels[0].frames = {0, 3, 3, 10, 19}; });
  bad([](EncodedClip& e) { e.channels[0].frames.back() = 20; });
  bad([](EncodedClip& e) { e.channels[0].step = std::numeric_limits<double>::infinity(); });
  bad([](EncodedClip& e) { e.channels[0].step = 0.0; });
  bad([](EncodedClip& e) { e.channels[0].tension = 1.5f; });
  bad([](EncodedClip& e) { e.channels[0].q[0] = (int64_t(1) << 53) + 1; });
  bad([](EncodedClip& e) { e.channels[0].q.pop_back(); });
  bad([](EncodedClip& e) { e.channels[0].step = 1e300; });  // value overflows binary32
  bad([](EncodedClip& e) { e.channels.pop_back(); });
  bad([](EncodedClip& e) { e.skeleton.joints[1].parent = 1; });
  bad([](EncodedClip& e) { e.skeleton.joints[2].channels = {CT::x_rotation}; e.channels.push_back({}); });
  bad([](EncodedClip& e) { e.frame_time = 0.0; });
  bad([](EncodedClip& e) { e.frame_time = std::nan(""); });
}

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
    r.major = keyanim::kFormatVersionMajor + 1;
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

TEST_CASE("decode_motion at the source rate at another fps with inbetweens and a range") {
  using keyanim::offline::decode_motion;
  using keyanim::offline::Motion;
  using keyanim::offline::ResampleOptions;
  const Clip clip = keyanim::offline::to_clip(vector_long());  // 240 frames at 120 fps
  const uint32_t C = clip.channel_count();
  std::vector<float> pose(C);
  auto row_is = [&](const Motion& m, uint32_t row, double position) {
    REQUIRE(clip.sample(position, pose) == Status::ok);
    for (uint32_t c = 0; c < C; ++c)
      if (m.value(row, c) != double(pose[c])) return false;
    return true;
  };
  Motion m = decode_motion(clip);
  CHECK(m.frame_count == 240);
  CHECK(m.frame_time == 1.0 / 120.0);
  CHECK(m.values.size() == 240 * C);
  CHECK(m.skeleton.joints.size() == 3);
  CHECK(row_is(m, 0, 0));
  CHECK(row_is(m, 137, 137));
  CHECK(row_is(m, 239, 239));

  ResampleOptions o;
  o.fps = 30;  // 239 / 120 s = 1.9917 s: frames at 0, 1/30 .. 59/30 (frame 236)
  m = decode_motion(clip, o);
  CHECK(m.frame_count == 60);
  CHECK(m.frame_time == 1.0 / 30.0);
  CHECK(row_is(m, 1, 4));
  CHECK(row_is(m, 59, 236));

  o.fps = 50;  // every 2.4 source frames: 0, 2.4 .. 237.6 (99 x 2.4)
  m = decode_motion(clip, o);
  CHECK(m.frame_count == 100);
  CHECK(row_is(m, 3, 3.0 / 50.0 / (1.0 / 120.0)));

  o = {};
  o.inbetweens = 3;
  m = decode_motion(clip, o);
  CHECK(m.frame_count == 239 * 4 + 1);
  CHECK(m.frame_time == (1.0 / 120.0) / 4.0);
  CHECK(row_is(m, 8, 2));
  CHECK(row_is(m, 9, 2.25));
  CHECK(row_is(m, 10, 2.5));
  CHECK(row_is(m, 956, 239));

  o = {};
  o.first_frame = 5;
  o.last_frame = 20;
  m = decode_motion(clip, o);
  CHECK(m.frame_count == 16);
  CHECK(row_is(m, 0, 5));
  CHECK(row_is(m, 15, 20));
  o.fps = 60;  // 15 source frames at 120 fps = 0.125 s: 8 frames, the range's end included
  m = decode_motion(clip, o);
  CHECK(m.frame_count == 8);
  CHECK(row_is(m, 7, 19));
  o.fps = 40;  // every 3 source frames: 5, 8 .. 20, the end lands exactly
  m = decode_motion(clip, o);
  CHECK(m.frame_count == 6);
  CHECK(row_is(m, 5, 20));
  o.fps = 0;
  o.inbetweens = 1;
  m = decode_motion(clip, o);
  CHECK(m.frame_count == 31);
  CHECK(row_is(m, 1, 5.5));

  // Nonsense options.
  auto fails = [&](ResampleOptions bad) {
    try {
      decode_motion(clip, bad);
      FAIL_CHECK("accepted");
    } catch (const keyanim::offline::Error& e) {
      CHECK(e.kind() == keyanim::offline::ErrorKind::invalid_argument);
      CHECK(!e.message().empty());
    }
  };
  o = {};
  o.fps = 30;
  o.inbetweens = 2;
  fails(o);
  o = {};
  o.fps = -1;
  fails(o);
  o.fps = std::nan("");
  fails(o);
  o = {};
  o.first_frame = 10;
  o.last_frame = 9;
  fails(o);
  o.first_frame = 0;
  o.last_frame = 240;
  fails(o);
  o.first_frame = 240;
  o.last_frame = UINT32_MAX;
  fails(o);

  // A single-frame clip with Frame_Time 0 decodes to one frame at any rate.
  const Clip single = keyanim::offline::to_clip(vector_single());
  o = {};
  o.fps = 24;
  m = decode_motion(single, o);
  CHECK(m.frame_count == 1);
  CHECK(m.value(0, 0) == double(float(95250 * 0.001)));
}

TEST_CASE("test vectors load and equal their hand-built clips") {
  // KEYANIM_WRITE_TEST_VECTORS=1 (re)writes the files: only for adding new vectors.
  const bool write = std::getenv("KEYANIM_WRITE_TEST_VECTORS") != nullptr;
  for (const std::string name : kVectorNames) {
    CAPTURE(name);
    const EncodedClip e = vector_clip(name);
    if (write && name.starts_with("v" + std::to_string(keyanim::kFormatVersionMajor) + "_")) {
      // *_predict and *_uniform are stored uncompressed, the others at level 19.
      const bool raw = name.ends_with("_predict") || name.ends_with("_uniform");
      const auto bytes = keyanim::offline::write_kanim(e, raw ? 0 : 19);
      std::ofstream(vector_path(name, ".kanim"), std::ios::binary)
          .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    }
    const Loaded l = load(read_file(vector_path(name, ".kanim")));
    REQUIRE_MESSAGE(l.status == Status::ok, l.err.detail);
    const Clip ref = keyanim::offline::to_clip(e);
    check_same_clip(l.clip, ref);
    check_same_samples(l.clip, ref);
  }
}

TEST_CASE("the predict vectors hold both value codings and the long ones extrapolate") {
  for (const char* name : {"v2_predict", "v2_long", "v3_predict", "v3_long"}) {
    CAPTURE(name);
    const std::vector<uint8_t> bytes = read_file(vector_path(name, ".kanim"));
    REQUIRE(bytes.size() > 12);
    CHECK(bytes[8] == name[1] - '0');
    CHECK(bytes[9] == 0);
    const Loaded l = load(bytes);
    REQUIRE(l.status == Status::ok);
    const size_t C = l.clip.channel_count();
    std::vector<uint8_t> chan;
    RawFile r = split(bytes);
    chan = r.get("CHAN").stored;
    if (r.get("CHAN").flags & 1) {
      chan.assign(size_t(ZSTD_getFrameContentSize(chan.data(), chan.size())), 0);
      const auto& z = r.get("CHAN").stored;
      REQUIRE(ZSTD_decompress(chan.data(), chan.size(), z.data(), z.size()) == chan.size());
    }
    REQUIRE(chan.size() == (bytes[8] == 3 ? 19 : 18) * C);
    const std::vector<uint8_t> codings(chan.begin() + 17 * C, chan.begin() + 18 * C);
    CHECK(std::count(codings.begin(), codings.end(), 1) >= 1);
    if (std::string(name).ends_with("predict")) CHECK(std::count(codings.begin(), codings.end(), 0) >= 1);
    if (bytes[8] == 3) {  // Residual_Bytes: v3_predict's deltas of 2^41 and more need 7 bytes
      const std::vector<uint8_t> widths(chan.begin() + 18 * C, chan.end());
      CHECK(*std::max_element(widths.begin(), widths.end()) == (std::string(name) == "v3_predict" ? 7 : 3));
    }
  }
}

TEST_CASE("test vectors match the independent reference decoder") {
  double max_rel = 0.0;
  uint64_t values = 0, exact = 0;
  for (const std::string name : kVectorNames) {
    CAPTURE(name);
    std::ifstream in(vector_path(name, ".json"));
    REQUIRE(in.good());
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string text = ss.str();
    JsonParser p{text};
    const Json j = p.value();
    REQUIRE(p.ok);
    const Loaded l = load(read_file(vector_path(name, ".kanim")));
    REQUIRE(l.status == Status::ok);
    const Clip& clip = l.clip;
    CHECK(j["format_version"].str ==
          std::to_string(clip.version_major()) + "." + std::to_string(clip.version_minor()));
    CHECK(j["format_version"].str.substr(0, 1) == name.substr(1, 1));  // v1_* files are 1.x
    CHECK(j["frame_count"].num == clip.frame_count());
    CHECK(j["frame_time"].num == clip.frame_time());
    CHECK(j["tangent_rule"].num == double(static_cast<int>(clip.tangent_rule())));
    CHECK(j["notes"].str == clip.encoder_notes());
    const auto& nodes = j["nodes"].arr;
    REQUIRE(nodes.size() == clip.skeleton().joints.size());
    for (size_t i = 0; i < nodes.size(); ++i) {
      const Joint& jt = clip.skeleton().joints[i];
      CHECK(nodes[i]["name"].str == jt.name);
      CHECK(nodes[i]["parent"].num == jt.parent);
      CHECK(nodes[i]["end_site"].b == jt.end_site);
      for (size_t k = 0; k < 3; ++k) CHECK(nodes[i]["offset"].arr[k].num == jt.offset[k]);
      REQUIRE(nodes[i]["channels"].arr.size() == jt.channels.size());
      for (size_t k = 0; k < jt.channels.size(); ++k)
        CHECK(nodes[i]["channels"].arr[k].str == keyanim::channel_name(jt.channels[k]));
    }
    const auto& samples = j["samples"].arr;
    REQUIRE(samples.size() >= 8);
    std::vector<float> out(clip.channel_count());
    for (const Json& s : samples) {
      REQUIRE(clip.sample(s["position"].num, out) == Status::ok);
      const auto& expected = s["values"].arr;
      REQUIRE(expected.size() == out.size());
      for (size_t c = 0; c < out.size(); ++c) {
        const double e = expected[c].num;
        const double rel = std::fabs(double(out[c]) - e) / std::max(std::fabs(e), 1.0);
        max_rel = std::max(max_rel, rel);
        exact += double(out[c]) == e;
        ++values;
        CHECK_MESSAGE(rel <= 1e-6, "position " << s["position"].num << " channel " << c);
      }
    }
  }
  MESSAGE("test vectors: " << values << " values, " << exact << " bit-exact, max relative difference " << max_rel);
  CHECK(values > 500);
}

}  // TEST_SUITE("container")
