// Fuzz target: load a .kanim, then sample it at positions taken from the input.
// Input layout: byte 0 = number of requests n (mod 33); then n records of 9 bytes (a mode byte
// and 8 bytes of payload); then the .kanim file, whose CRC-32 (a runtime-profile file's XXH64)
// is recomputed so that mutated files load. Each request samples every channel (plain, through
// a cursor, through a cursor last used on another clip) or a subset of channels, at a frame
// position or a time made from the payload: any double (NaN, infinities, negative, huge,
// subnormal), an integer frame near the clip, a key frame or its float neighbours, a fraction
// between frames.
// Checks: no crash; NaN is invalid_argument and nothing else fails; every value equals
// eval_channel (cardinal.h, the spec's reference) at RN32(position) bit for bit, as clip.h
// promises, whichever path computed it; a quaternion node's rotation channels (version 5) the
// Euler angles of its stored x, y, z so evaluated (Appendix B, clip_reference.h), and
// sample_stored (through the cursor, mode 2) the stored values themselves. A runtime-profile
// file is compared so only if it passes check_content (spec 9.4 makes its values' agreement with
// its keys a content rule); otherwise only the statuses are checked.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <span>
#include <vector>

#include "fuzz_common.h"
#include "keyanim/cardinal.h"
#include "keyanim/clip.h"
#include "clip_reference.h"

namespace {

using keyanim::Clip;
using keyanim::Status;

constexpr size_t kRecord = 9;

// Bit-exact, -0 included (corpus/sample/crash-cursor-negative-zero.bin: a key value of -0 once
// came back from the cursor path as +0 at its own key frame).
bool same_value(float a, float b) { return keyanim::fuzz::same_float(a, b); }

// The clip's keys, read once per input: the reference evaluates them with eval_channel, and
// turns a quaternion node's stored x, y, z into its Euler angles (version 5: what sample gives).
keyanim::test::SampleReference g_ref;

// Whether the values must be the reference's: a runtime-profile file is sampled as loaded (its
// structure checked), but only one that passes check_content holds the image its keys make
// (spec 9.4; corpus/sample/crash-runtime-unchecked-content.bin: a v4 runtime file whose curve
// values are not its keys'); the others must only sample without a crash, with the statuses.
bool g_exact = true;

float reference(const Clip& clip, uint32_t c, float f) { return keyanim::test::reference_sample(clip, g_ref, c, f); }
// What sample_stored gives: eval_channel on the keys, a quaternion node's stored x, y, z as such.
float reference_stored(const Clip& clip, uint32_t c, float f) {
  return keyanim::test::reference_value(clip, g_ref.keys[c], f);
}

// A position from the mode's upper bits and the payload.
double make_position(const Clip& clip, uint8_t mode, const uint8_t* payload) {
  uint64_t bits;
  std::memcpy(&bits, payload, 8);
  const uint32_t lo = static_cast<uint32_t>(bits);
  const uint32_t hi = static_cast<uint32_t>(bits >> 32);
  const double frames = static_cast<double>(clip.frame_count());
  switch ((mode >> 3) & 7) {
    case 0: {
      double d;
      std::memcpy(&d, payload, 8);
      return d;
    }
    case 1: return static_cast<double>(lo % (clip.frame_count() + 3u)) - 1.0;  // -1 .. frames+1
    case 2: return static_cast<double>(lo) / 65536.0 - 2.0;                   // fractions
    case 3: return frames * (static_cast<double>(lo) / 4294967295.0);          // anywhere inside
    case 4: {  // a key frame of some channel, or a float neighbour of it
      if (clip.total_keys() == 0) return 0.0;
      const uint32_t c = hi % clip.channel_count();
      const auto& keys = g_ref.keys[c].frames;
      if (keys.empty()) return 0.0;
      const float k = static_cast<float>(keys[lo % keys.size()]);
      const int side = static_cast<int>((lo >> 24) % 3);
      return side == 0 ? k : std::nextafter(k, side == 1 ? -INFINITY : INFINITY);
    }
    case 5: return std::numeric_limits<double>::quiet_NaN();
    case 6: return (lo & 1) ? INFINITY : -INFINITY;
    default: return (lo & 1 ? -1.0 : 1.0) * std::ldexp(1.0, static_cast<int>(hi % 2100) - 1075);
  }
}

void check_pose(const Clip& clip, float f, const std::vector<float>& pose, bool stored = false) {
  if (!g_exact) return;
  for (uint32_t c = 0; c < clip.channel_count(); ++c) {
    const float want = stored ? reference_stored(clip, c, f) : reference(clip, c, f);
    if (!same_value(pose[c], want)) {
      std::fprintf(stderr, "channel %u%s at f=%.9g: got %.9g, the reference gives %.9g\n", c,
                   stored ? " (stored)" : g_ref.quat_of[c] >= 0 ? " (a quaternion node's angle)" : "",
                   static_cast<double>(f), static_cast<double>(pose[c]), static_cast<double>(want));
      FUZZ_CHECK(false);
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  size_t n = data[0] % 33u;
  if (1 + n * kRecord > size) n = (size - 1) / kRecord;
  const uint8_t* records = data + 1;
  const size_t file_at = 1 + n * kRecord;
  const std::vector<uint8_t> file = keyanim::fuzz::with_fixed_checksum(data + file_at, size - file_at);

  keyanim::DecodeLimits limits;
  limits.max_decompressed_bytes = 16u << 20;  // small limits keep every run fast
  limits.max_joints = 4096;
  limits.max_channels = 4096;
  Clip clip;
  if (Clip::load(file, clip, nullptr, limits) != Status::ok) return 0;
  g_exact = true;
  if (keyanim::fuzz::is_runtime_profile(file.data(), file.size())) {
    keyanim::DecodeLimits checked_limits = limits;
    checked_limits.check_content = true;
    Clip checked;
    g_exact = Clip::load(file, checked, nullptr, checked_limits) == Status::ok;
  }
  const Clip other = clip;  // a copy shares the image, and so the cursor
  const uint32_t channels = clip.channel_count();
  std::vector<float> pose(channels), pose2(channels);
  g_ref = keyanim::test::sample_reference(clip);
  keyanim::Cursor cursor;
  if (cursor.prepare(clip) != Status::ok) return 0;

  for (size_t r = 0; r < n; ++r) {
    const uint8_t mode = records[r * kRecord];
    const uint8_t* payload = records + r * kRecord + 1;
    const double x = make_position(clip, mode, payload);
    const bool by_time = (mode & 0x40) != 0;
    const double position = by_time ? (clip.frame_time() > 0.0 ? x / clip.frame_time() : 0.0) : x;
    const float f = static_cast<float>(position);
    // The request at x, by frame position or by time.
    auto call = [&](const Clip& c, std::vector<float>& out, keyanim::Cursor* cur) {
      return by_time ? c.sample_time(x, out, cur) : c.sample(x, out, cur);
    };
    Status s;
    switch (mode & 7) {
      case 0: s = call(clip, pose, nullptr); break;
      case 1: s = call(clip, pose, &cursor); break;
      case 2:  // through the cursor, then the stored values (sample_stored) through it too
        s = call(clip, pose, &cursor);
        if (s == Status::ok) {
          FUZZ_CHECK(clip.sample_stored(position, pose2, &cursor) == Status::ok);
          check_pose(clip, f, pose2, true);
        }
        break;
      case 3: s = call(other, pose, &cursor); break;
      case 4: {  // a subset of channels, in an order and with repeats from the payload
        std::vector<uint32_t> list;
        for (size_t i = 0; i < 8 && channels > 0; ++i) list.push_back(payload[i] % channels);
        std::vector<float> part(list.size());
        s = clip.sample_channels(position, list, part);
        if (s == Status::ok && g_exact)
          for (size_t i = 0; i < list.size(); ++i)
            FUZZ_CHECK(same_value(part[i], reference(clip, list[i], f)));
        if (channels > 0) {  // a channel number out of range, and a short output span
          const uint32_t bad[2] = {0, channels + payload[0]};
          float two[2];
          FUZZ_CHECK(clip.sample_channels(position, bad, two) == Status::invalid_argument);
          FUZZ_CHECK(clip.sample_channels(position, std::span<const uint32_t>(bad, 2), std::span<float>(two, 1)) !=
                     Status::ok);
        }
        FUZZ_CHECK(std::isnan(position) == (s == Status::invalid_argument));
        if (!std::isnan(position)) FUZZ_CHECK(s == Status::ok);
        continue;
      }
      case 5:  // playback: a forward sweep in quarter frames through the cursor
        if (!std::isnan(position)) {
          for (int k = 0; k < 8; ++k) {
            const double p = position + 0.25 * k;
            FUZZ_CHECK(clip.sample(p, pose, &cursor) == Status::ok);
            check_pose(clip, static_cast<float>(p), pose);
          }
        }
        continue;
      case 6:
        if (channels > 0) FUZZ_CHECK(clip.sample(x, std::span<float>(pose2.data(), channels - 1)) ==
                                     (std::isnan(x) ? Status::invalid_argument : Status::output_too_small));
        continue;
      default: {  // cursor, then the same position again without: both equal the reference
        s = call(clip, pose, &cursor);
        if (s == Status::ok) {
          FUZZ_CHECK(call(clip, pose2, nullptr) == Status::ok);
          if (g_exact)
            for (uint32_t c = 0; c < channels; ++c) FUZZ_CHECK(same_value(pose[c], pose2[c]));
        }
        break;
      }
    }
    if (std::isnan(x)) {
      FUZZ_CHECK(s == Status::invalid_argument);
      continue;
    }
    FUZZ_CHECK(s == Status::ok);
    check_pose(clip, f, pose);
  }
  return 0;
}
