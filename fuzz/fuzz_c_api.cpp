// Fuzz target: the C API (keyanim.h, libkeyanim_c.so) against the C++ runtime it wraps.
// Input layout: fuzz_sample's (so that its seeds serve here too): byte 0 = number of requests n
// (mod 33); then n records of 9 bytes (a mode byte and 8 bytes of payload); then the .kanim
// file, whose CRC-32 is recomputed unless byte 0 is >= 231 (then the bytes load as given).
// The bytes go through keyanim_clip_load_limited and through Clip::load with the same limits
// (and, when they load, twice through one rig cache).
// Checks: no crash; the same status; a failure leaves the handle NULL and its last error holds
// the loader's section and offset; a loaded clip answers every question (counts, times,
// memory, every node's name, parent, End Site flag, OFFSET, channels, rotation order) as Clip
// does; each request (Euler channels, local or model transforms, by frame or by time, with or
// without a cursor, with a short buffer, a NULL buffer or a NULL handle, at any double: NaN,
// infinities, huge, subnormal, frames around the clip) returns Clip's status and Clip's values
// bit for bit, a refused buffer left unchanged; the clip freed twice and used after its free
// is refused (the last freed handle), never a crash.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <span>
#include <vector>

#include "fuzz_common.h"
#include "keyanim.h"
#include "keyanim/clip.h"

namespace {

using keyanim::Clip;
using keyanim::Status;

constexpr size_t kRecord = 9;
constexpr uint8_t kKeepChecksum = 231;

double make_position(const Clip& clip, uint8_t mode, const uint8_t* payload) {
  uint64_t bits;
  std::memcpy(&bits, payload, 8);
  const uint32_t lo = static_cast<uint32_t>(bits), hi = static_cast<uint32_t>(bits >> 32);
  switch ((mode >> 5) & 7) {
    case 0: {
      double d;
      std::memcpy(&d, payload, 8);
      return d;  // any double
    }
    case 1: return static_cast<double>(lo % (clip.frame_count() + 3u)) - 1.0;
    case 2: return static_cast<double>(lo) / 65536.0 - 2.0;
    case 3: return static_cast<double>(clip.frame_count()) * (static_cast<double>(lo) / 4294967295.0);
    case 4: return std::numeric_limits<double>::quiet_NaN();
    case 5: return (lo & 1) ? INFINITY : -INFINITY;
    case 6: return (lo & 1 ? -1.0 : 1.0) * std::ldexp(1.0, static_cast<int>(hi % 2100) - 1075);
    default: return static_cast<double>(lo % 64u) * clip.frame_time();  // a time near the start
  }
}

void check_queries(const keyanim_clip* h, const Clip& clip) {
  FUZZ_CHECK(keyanim_clip_frame_count(h) == clip.frame_count());
  FUZZ_CHECK(keyanim::fuzz::same_double(keyanim_clip_frame_time(h), clip.frame_time()));
  FUZZ_CHECK(keyanim::fuzz::same_double(keyanim_clip_duration(h), clip.duration()));
  FUZZ_CHECK(keyanim_clip_channel_count(h) == clip.channel_count());
  FUZZ_CHECK(keyanim_clip_total_keys(h) == clip.total_keys());
  FUZZ_CHECK(keyanim_clip_memory_bytes(h) == clip.memory_bytes());
  FUZZ_CHECK(keyanim_clip_skeleton_bytes(h) + keyanim_clip_animation_bytes(h) == clip.memory_bytes());
  FUZZ_CHECK(keyanim_clip_format_version(h) == ((uint32_t{clip.version_major()} << 16) | clip.version_minor()));
  FUZZ_CHECK(std::strcmp(keyanim_clip_encoder_notes(h), clip.encoder_notes().c_str()) == 0);
  const keyanim_skeleton* sk = keyanim_clip_skeleton(h);
  const auto& joints = clip.skeleton().joints;
  FUZZ_CHECK(keyanim_clip_node_count(h) == joints.size() && keyanim_skeleton_node_count(sk) == joints.size());
  FUZZ_CHECK(keyanim_skeleton_channel_count(sk) == clip.channel_count());
  for (uint32_t i = 0; i < joints.size(); ++i) {
    const keyanim::Joint& j = joints[i];
    // Every byte of the name, NUL included, and its length.
    FUZZ_CHECK(keyanim_skeleton_node_name_length(sk, i) == j.name.size());
    FUZZ_CHECK(std::memcmp(keyanim_clip_node_name(h, i), j.name.c_str(), j.name.size() + 1) == 0);
    FUZZ_CHECK(keyanim_clip_node_parent(h, i) == j.parent);
    FUZZ_CHECK(keyanim_skeleton_node_is_end_site(sk, i) == (j.end_site ? 1 : 0));
    double offset[3];
    FUZZ_CHECK(keyanim_skeleton_node_offset(sk, i, offset) == KEYANIM_OK);
    for (size_t k = 0; k < 3; ++k) FUZZ_CHECK(keyanim::fuzz::same_double(offset[k], j.offset[k]));
    FUZZ_CHECK(keyanim_skeleton_node_channel_count(sk, i) == j.channels.size());
    FUZZ_CHECK(keyanim_skeleton_node_first_channel(sk, i) == j.first_channel);
    uint8_t types[8];
    if (j.channels.size() <= 8) {
      FUZZ_CHECK(keyanim_skeleton_node_channel_types(sk, i, types, 8) == KEYANIM_OK);
      for (size_t k = 0; k < j.channels.size(); ++k) FUZZ_CHECK(types[k] == static_cast<uint8_t>(j.channels[k]));
    }
    char order[16];
    FUZZ_CHECK(keyanim_skeleton_node_rotation_order(sk, i, order, sizeof order) ==
               (j.channels.size() < sizeof order ? KEYANIM_OK : KEYANIM_OUTPUT_TOO_SMALL));
  }
  const uint32_t n = static_cast<uint32_t>(joints.size());
  FUZZ_CHECK(keyanim_clip_node_name(h, n) == nullptr && keyanim_clip_node_parent(h, n) == KEYANIM_NO_NODE);
}

// One request through the C API and through Clip: same status, same bits.
void check_request(const keyanim_clip* h, keyanim_cursor* cursor, const Clip& clip, keyanim::Cursor& cpp_cursor,
                   uint8_t mode, double x) {
  const int kind = mode & 3;  // 0, 3: channels; 1: local; 2: model
  const bool by_time = (mode & 4) != 0, with_cursor = (mode & 8) != 0, short_buffer = (mode & 16) != 0;
  const size_t need = kind == 1 || kind == 2 ? clip.skeleton().joints.size() : clip.channel_count();
  if (short_buffer && need == 0) return;
  const size_t count = short_buffer ? need - 1 : need;
  keyanim::Cursor* cc = with_cursor ? &cpp_cursor : nullptr;
  keyanim_status got;
  Status want;
  if (kind == 1 || kind == 2) {
    std::vector<keyanim_transform> a(need + 1);
    std::vector<keyanim::Transform> b(need + 1);
    std::memset(a.data(), 0x5a, a.size() * sizeof a[0]);
    const std::vector<keyanim_transform> before = a;
    const double ft = clip.frame_time();
    const double f = by_time ? (std::isnan(x) ? x : ft > 0.0 ? x / ft : 0.0) : x;
    if (kind == 1) {
      got = with_cursor ? (by_time ? keyanim_cursor_sample_local_time : keyanim_cursor_sample_local)(cursor, x, a.data(), count)
                        : (by_time ? keyanim_clip_sample_local_time : keyanim_clip_sample_local)(h, x, a.data(), count);
      want = clip.sample_local(f, std::span(b.data(), count), cc);
    } else {
      got = with_cursor ? (by_time ? keyanim_cursor_sample_model_time : keyanim_cursor_sample_model)(cursor, x, a.data(), count)
                        : (by_time ? keyanim_clip_sample_model_time : keyanim_clip_sample_model)(h, x, a.data(), count);
      want = clip.sample_model(f, std::span(b.data(), count), cc);
    }
    FUZZ_CHECK(got == static_cast<keyanim_status>(want));
    if (want == Status::ok) FUZZ_CHECK(std::memcmp(a.data(), b.data(), need * sizeof a[0]) == 0);
    else FUZZ_CHECK(std::memcmp(a.data(), before.data(), a.size() * sizeof a[0]) == 0);
  } else {
    std::vector<float> a(need + 1, 1234.5f), b(need + 1);
    got = with_cursor ? (by_time ? keyanim_cursor_sample_time : keyanim_cursor_sample)(cursor, x, a.data(), count)
                      : (by_time ? keyanim_clip_sample_time : keyanim_clip_sample)(h, x, a.data(), count);
    want = by_time ? clip.sample_time(x, std::span(b.data(), count), cc) : clip.sample(x, std::span(b.data(), count), cc);
    FUZZ_CHECK(got == static_cast<keyanim_status>(want));
    if (want == Status::ok) FUZZ_CHECK(std::memcmp(a.data(), b.data(), need * sizeof(float)) == 0);
    else for (float v : a) FUZZ_CHECK(v == 1234.5f);
  }
  FUZZ_CHECK(std::isnan(x) == (got == KEYANIM_INVALID_ARGUMENT));
  if (got != KEYANIM_OK) FUZZ_CHECK(keyanim_last_error_status() == got);
  // The same with a NULL buffer, and with a NULL handle: refused.
  FUZZ_CHECK(keyanim_clip_sample(h, x, nullptr, count) == KEYANIM_INVALID_ARGUMENT);
  FUZZ_CHECK(keyanim_clip_sample_model(nullptr, x, nullptr, count) == KEYANIM_INVALID_ARGUMENT);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  size_t n = data[0] % 33u;
  if (1 + n * kRecord > size) n = (size - 1) / kRecord;
  const uint8_t* records = data + 1;
  const size_t file_at = 1 + n * kRecord;
  const std::vector<uint8_t> file = data[0] >= kKeepChecksum
                                        ? std::vector<uint8_t>(data + file_at, data + size)
                                        : keyanim::fuzz::with_fixed_checksum(data + file_at, size - file_at);

  keyanim_decode_limits limits;
  keyanim_decode_limits_default(&limits);
  limits.max_decompressed_bytes = 16u << 20;  // small limits keep every run fast
  limits.max_joints = 4096;
  limits.max_channels = 4096;
  keyanim::DecodeLimits cpp_limits;
  cpp_limits.max_decompressed_bytes = limits.max_decompressed_bytes;
  cpp_limits.max_joints = limits.max_joints;
  cpp_limits.max_channels = limits.max_channels;

  keyanim_clip* h = reinterpret_cast<keyanim_clip*>(&n);  // not NULL: the call must set it
  const keyanim_status s = keyanim_clip_load_limited(file.data(), file.size(), &limits, &h);
  Clip clip;
  keyanim::ErrorInfo info;
  const Status want = Clip::load(file, clip, &info, cpp_limits);
  FUZZ_CHECK(s == static_cast<keyanim_status>(want));
  if (s != KEYANIM_OK) {
    FUZZ_CHECK(h == nullptr);
    FUZZ_CHECK(keyanim_last_error_status() == s && keyanim_last_error_offset() == info.byte_offset);
    FUZZ_CHECK(std::strncmp(keyanim_last_error_section(), info.section.c_str(), 31) == 0);
    keyanim_clip_free(h);  // NULL: a no-op
    return 0;
  }
  FUZZ_CHECK(h != nullptr);
  check_queries(h, clip);
  // Through a rig cache: the same file twice shares one rig, hashed as the plain load's, and
  // answers as Clip does.
  keyanim_rig_cache* rigs = nullptr;
  FUZZ_CHECK(keyanim_rig_cache_create(&rigs) == KEYANIM_OK);
  keyanim_clip *s1 = nullptr, *s2 = nullptr;
  FUZZ_CHECK(keyanim_clip_load_shared(file.data(), file.size(), &limits, rigs, &s1) == KEYANIM_OK);
  FUZZ_CHECK(keyanim_clip_load_shared(file.data(), file.size(), &limits, rigs, &s2) == KEYANIM_OK);
  FUZZ_CHECK(keyanim_clip_shares_rig(s1, s2) == 1 && keyanim_clip_rig_hash(s1) == clip.rig_hash());
  keyanim_rig_cache_free(rigs);  // the clips keep their rig
  check_queries(s2, clip);
  keyanim_clip_free(s1);
  keyanim_clip_free(s2);
  keyanim_cursor* cursor = nullptr;
  FUZZ_CHECK(keyanim_cursor_create(h, &cursor) == KEYANIM_OK);
  keyanim::Cursor cpp_cursor;
  FUZZ_CHECK(cpp_cursor.prepare(clip) == Status::ok);
  for (size_t r = 0; r < n; ++r) {
    const uint8_t mode = records[r * kRecord];
    check_request(h, cursor, clip, cpp_cursor, mode, make_position(clip, mode, records + r * kRecord + 1));
  }
  keyanim_clip_free(h);
  // The cursor keeps the clip's data: it still samples as Clip does.
  std::vector<float> a(clip.channel_count() + 1), b(clip.channel_count() + 1);
  FUZZ_CHECK(keyanim_cursor_sample(cursor, 1.5, a.data(), a.size()) == KEYANIM_OK);
  FUZZ_CHECK(clip.sample(1.5, b) == Status::ok);
  FUZZ_CHECK(std::memcmp(a.data(), b.data(), clip.channel_count() * sizeof(float)) == 0);
  keyanim_cursor_free(cursor);
  // The last freed handles: refused, not undefined.
  keyanim_clip_free(h);
  FUZZ_CHECK(keyanim_last_error_status() == KEYANIM_INVALID_ARGUMENT);
  FUZZ_CHECK(keyanim_clip_frame_count(h) == 0 && keyanim_clip_sample(h, 0.0, a.data(), a.size()) == KEYANIM_INVALID_ARGUMENT);
  keyanim_cursor_free(cursor);
  FUZZ_CHECK(keyanim_cursor_sample(cursor, 0.0, a.data(), a.size()) == KEYANIM_INVALID_ARGUMENT);
  return 0;
}
