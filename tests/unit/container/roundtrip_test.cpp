// Write -> load round trips: bit-exact equality with to_clip, dequantization, the cursor,
// sampling entry points and their argument errors, bit-packed keys, and what the writer refuses.
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
    for (std::optional<int> level : {std::optional<int>{}, std::optional<int>{0}, std::optional<int>{3},
                                     std::optional<int>{19}}) {
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

// The stored frame of a section compressed alone at `level` (and `min_match`, 0: the level's),
// as zstd's one-shot API makes it with the writer's frame options.
std::vector<uint8_t> zstd_alone(const std::vector<uint8_t>& raw, int level, int min_match) {
  ZSTD_CCtx* c = ZSTD_createCCtx();
  ZSTD_CCtx_setParameter(c, ZSTD_c_compressionLevel, level);
  if (min_match > 0) ZSTD_CCtx_setParameter(c, ZSTD_c_minMatch, min_match);
  ZSTD_CCtx_setParameter(c, ZSTD_c_checksumFlag, 0);
  std::vector<uint8_t> z(ZSTD_compressBound(raw.size()));
  const size_t n = ZSTD_compress2(c, z.data(), z.size(), raw.data(), raw.size());
  ZSTD_freeCCtx(c);
  REQUIRE(!ZSTD_isError(n));
  z.resize(n);
  return z;
}

TEST_CASE("zstd parameters: measured per section by default, a given level on every section") {
  const EncodedClip e = random_clip(4, 3000, 20);  // sections large enough to compress
  const RawFile by_section = split(keyanim::offline::write_kanim(e));
  const RawFile at_3 = split(keyanim::offline::write_kanim(e, 3));
  // The parameters container_writer.cpp documents; KVAL (zstd blocks per plane) is left out.
  const std::map<std::string, std::pair<int, int>> measured = {
      {"SKEL", {15, 0}}, {"CHAN", {15, 0}}, {"KTIM", {15, 6}}, {"NOTE", {15, 0}}};
  REQUIRE(by_section.sections.size() == at_3.sections.size());
  for (size_t i = 0; i < at_3.sections.size(); ++i) {
    const RawSection& a = by_section.sections[i];
    const RawSection& b = at_3.sections[i];
    CAPTURE(a.tag);
    REQUIRE(a.tag == b.tag);
    if (!(a.flags & 1) || !(b.flags & 1)) continue;  // stored raw (CLIP; a section zstd cannot shrink)
    std::vector<uint8_t> raw(a.raw_size), raw_b(b.raw_size);
    REQUIRE(ZSTD_decompress(raw.data(), raw.size(), a.stored.data(), a.stored.size()) == raw.size());
    REQUIRE(ZSTD_decompress(raw_b.data(), raw_b.size(), b.stored.data(), b.stored.size()) == raw_b.size());
    CHECK(raw == raw_b);  // the level changes the frames only
    if (a.tag == "KVAL") {
      CHECK(a.stored != b.stored);
      continue;
    }
    CHECK(b.stored == zstd_alone(raw, 3, 0));
    const auto it = measured.find(a.tag);
    if (it != measured.end()) CHECK(a.stored == zstd_alone(raw, it->second.first, it->second.second));
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

// Playback refreshes the curves whose segment a step left in batches of up to 32 (cursor.cpp):
// a clip of over a hundred curves, stepped, jumped and swept back, has batches that are full,
// partial and flushed at the last curve, with clamped and interior curves mixed in each.
TEST_CASE("the cursor's batched refresh changes no result when many curves go stale at once") {
  const Clip clip = keyanim::offline::to_clip(random_clip(9, 300, 45));
  const uint32_t n = clip.channel_count();
  REQUIRE(n > 100);
  std::vector<float> a(n), b(n);
  keyanim::Cursor cursor;
  REQUIRE(cursor.prepare(clip) == Status::ok);
  uint64_t s = 5, mismatches = 0;
  for (int i = 0; i < 2400; ++i) {
    const double x = i < 800 ? i * 0.37 - 3.0 : i < 1600 ? 310.0 - (i - 800) * 1.7 : double(lcg(s) % 32000) / 97.0 - 8.0;
    REQUIRE(clip.sample(x, a) == Status::ok);
    REQUIRE(clip.sample(x, b, &cursor) == Status::ok);
    for (uint32_t c = 0; c < n; ++c) mismatches += !same_bits(a[c], b[c]);
  }
  CHECK(mismatches == 0);
}

// At a key frame the cursor's polynomial gives the key's value only when the operands are
// finite and the value is not -0 (cursor.cpp, set_segment); elsewhere the key is a direct state.
// Channel 0: values +0, -0, +0, -0 (q of both signs times a step that rounds them to zero);
// channel 1: +-3e38, whose differences overflow to infinity.
TEST_CASE("the cursor gives a key's own value at its frame when the value is -0 or the operands overflow") {
  EncodedClip e;
  e.skeleton.joints.push_back(node("root", -1, 0, 0, 0, {CT::z_rotation, CT::x_rotation}));
  e.skeleton.joints.push_back(node("end", 0, 0, 1, 0, {}, true));
  e.frame_count = 40;
  e.frame_time = 1.0 / 30.0;
  e.tangent_rule = TangentRule::step_adjusted;
  const int64_t q[2][4] = {{1, -1, 2, -3}, {3, -3, 3, -3}};
  const double step[2] = {1e-300, 1e38};
  for (int c = 0; c < 2; ++c) {
    EncodedChannel ch;
    ch.interp = kCard;
    ch.tension = 0.0f;
    ch.step = step[c];
    ch.frames = {0, 10, 25, 39};
    ch.q.assign(q[c], q[c] + 4);
    e.channels.push_back(std::move(ch));
  }
  const Clip clip = keyanim::offline::to_clip(e);
  REQUIRE(clip.channel_count() == 2);
  std::vector<float> a(2), b(2);
  keyanim::Cursor cursor;
  REQUIRE(cursor.prepare(clip) == Status::ok);
  uint64_t mismatches = 0, minus_zero = 0;
  for (double x = 0.0; x <= 39.0; x += 0.5) {
    REQUIRE(clip.sample(x, a) == Status::ok);
    REQUIRE(clip.sample(x, b, &cursor) == Status::ok);
    for (int c = 0; c < 2; ++c) mismatches += !same_bits(a[c], b[c]);
    minus_zero += (x == 10.0 || x == 39.0) && same_bits(b[0], -0.0f);
  }
  CHECK(mismatches == 0);
  CHECK(minus_zero == 2);  // the test reaches the case: the -0 keys come back as -0
  float v = 0.0f;
  REQUIRE(clip.sample_channel(1, 10.0f, v) == Status::ok);
  CHECK(v == -3e38f);
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

TEST_CASE("memory is reported as the rig's part and the animation's part") {
  const EncodedClip e = random_clip(21, 1500, 10);
  EncodedClip renamed = e;  // the same motion on a rig whose names are longer
  size_t longer = 0;
  for (Joint& j : renamed.skeleton.joints) {
    j.name += std::string(40, 'n');
    longer += j.name.size();
  }
  EncodedClip shorter = e;  // the same rig with a third of the frames (and so fewer keys)
  shorter.frame_count = 500;
  for (auto& ch : shorter.channels) {
    size_t n = 0;
    while (n < ch.frames.size() && ch.frames[n] < 500) ++n;
    ch.frames.resize(n), ch.q.resize(n);
  }
  const Clip a = load(keyanim::offline::write_kanim(e)).clip;
  const Clip b = load(keyanim::offline::write_kanim(renamed)).clip;
  const Clip c = load(keyanim::offline::write_kanim(shorter)).clip;
  REQUIRE(a.channel_count() > 0);
  REQUIRE(b.channel_count() > 0);
  REQUIRE(c.channel_count() > 0);
  for (const Clip* k : {&a, &b, &c}) CHECK(k->memory_bytes() == k->skeleton_bytes() + k->animation_bytes());
  // Names are the rig's: they grow its part by at least their bytes and leave the animation's.
  CHECK(b.animation_bytes() == a.animation_bytes());
  CHECK(b.skeleton_bytes() >= a.skeleton_bytes() + longer);
  // Keys are the animation's: fewer of them shrink its part and leave the rig's.
  CHECK(c.skeleton_bytes() == a.skeleton_bytes());
  CHECK(c.animation_bytes() < a.animation_bytes());
  CHECK(a.skeleton_bytes() >= e.skeleton.joints.size() * (sizeof(Joint) + 3 * sizeof(float)));
  CHECK(Clip{}.memory_bytes() == 0);
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

}  // TEST_SUITE("container")
