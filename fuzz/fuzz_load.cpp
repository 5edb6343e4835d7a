// Fuzz target: the .kanim loader (Clip::load) on arbitrary bytes.
// Each input is loaded twice: as given (almost always stopped by a check of the header, the
// table or the checksum) and with its trailing checksum recomputed (the CRC-32, or a runtime-
// profile file's XXH64), so that mutations reach the section parsers and the image checks.
// Checks: no crash, no read outside the input, no hang, no allocation beyond what the limits
// and the data justify (run with -malloc_limit_mb); a failure leaves the clip
// empty with an error naming a section and an offset inside the file; a success gives arrays
// that keep every promise the sampler relies on (key frames strictly increasing and below
// frame_count, finite key values, tracks covering the key arrays, channels = skeleton's;
// quaternion nodes, version 5, in node order, each quaternion_capable, their channels reported
// as stored x, y, z and no other channel so).
// A runtime-profile file (spec section 9) is checked for its structure only, unless
// DecodeLimits::check_content: its key values may then be infinite (a Step of 1e300, say),
// which section 9.4 leaves to the content rules. Such a file is loaded a second time with
// check_content, and only a clip that passes it must have finite key values.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fuzz_common.h"
#include "keyanim/clip.h"
#include "clip_reference.h"
#include "keyanim/version.h"

namespace {

using keyanim::Clip;
using keyanim::ErrorInfo;
using keyanim::Status;

// Smaller than the defaults so that a tiny zstd frame cannot make every run decompress 1 GiB;
// the checks are the same code whatever the numbers.
keyanim::DecodeLimits fuzz_limits(bool check_content = false) {
  keyanim::DecodeLimits l;
  l.max_decompressed_bytes = 64u << 20;
  l.check_content = check_content;
  return l;
}

// `finite`: whether the key values must be finite (all but an unchecked runtime profile).
void check_loaded(const Clip& clip, bool finite) {
  FUZZ_CHECK(clip.version_major() >= keyanim::kOldestFormatVersionMajor && clip.version_major() <= keyanim::kNewestFormatVersionMajor);
  const uint32_t channels = clip.channel_count();
  FUZZ_CHECK(clip.skeleton().channel_count() == channels);
  FUZZ_CHECK(std::isfinite(clip.frame_time()) && clip.frame_time() >= 0.0);
  if (clip.frame_count() > 1) FUZZ_CHECK(clip.frame_time() > 0.0);
  const auto& joints = clip.skeleton().joints;
  for (size_t i = 0; i < joints.size(); ++i) {
    FUZZ_CHECK(joints[i].parent >= -1 && joints[i].parent < static_cast<int32_t>(i));
    if (joints[i].end_site) FUZZ_CHECK(joints[i].channels.empty() && joints[i].parent >= 0);
    for (double o : joints[i].offset) FUZZ_CHECK(std::isfinite(o));
  }
  uint64_t keys = 0;
  for (uint32_t c = 0; c < channels; ++c) {
    const keyanim::ChannelInfo info = clip.channel(c);
    FUZZ_CHECK(info.key_count <= clip.frame_count());
    FUZZ_CHECK(std::isfinite(info.tension) && info.tension >= -1.0f && info.tension <= 1.0f);
    keys += info.key_count;
    const keyanim::test::ChannelKeys k = keyanim::test::channel_keys(clip, c);
    FUZZ_CHECK(k.frames.size() == info.key_count);
    for (size_t i = 0; i < k.frames.size(); ++i) {
      FUZZ_CHECK(k.frames[i] < clip.frame_count());
      if (i > 0) FUZZ_CHECK(k.frames[i] > k.frames[i - 1]);
      if (finite) FUZZ_CHECK(std::isfinite(k.values[i]));
    }
  }
  FUZZ_CHECK(keys == clip.total_keys());
  // Quaternion nodes (version 5, section 4.7): in strictly increasing node order, each with
  // three rotation channels about three axes, which channel() reports as its stored x, y, z;
  // every other channel holds its own values.
  FUZZ_CHECK(clip.quat_node_count() == 0 || clip.version_major() >= 5);
  uint32_t quat_channels = 0;
  for (uint32_t i = 0; i < clip.quat_node_count(); ++i) {
    const keyanim::QuatNode q = clip.quat_node(i);
    FUZZ_CHECK(q.node < joints.size());
    if (i > 0) FUZZ_CHECK(q.node > clip.quat_node(i - 1).node);
    const double r2 = double(q.reference[0]) * q.reference[0] + double(q.reference[1]) * q.reference[1] +
                      double(q.reference[2]) * q.reference[2];
    FUZZ_CHECK(r2 <= 1073741824.0);
    uint32_t at = 0;
    FUZZ_CHECK(keyanim::quaternion_capable(joints[q.node], &at));
    for (uint32_t k = 0; k < 3; ++k)
      FUZZ_CHECK(clip.channel(joints[q.node].first_channel + at + k).stored == static_cast<keyanim::StoredAs>(k + 1));
    quat_channels += 3;
  }
  for (uint32_t c = 0; c < channels; ++c)
    if (clip.channel(c).stored != keyanim::StoredAs::value) --quat_channels;
  FUZZ_CHECK(quat_channels == 0);
  // The sampler on the clip just loaded: one pose at its first and last frame.
  std::vector<float> pose(channels);
  FUZZ_CHECK(clip.sample(0.0, pose) == Status::ok);
  FUZZ_CHECK(clip.sample(static_cast<double>(clip.frame_count()), pose) == Status::ok);
}

void load_once(std::span<const uint8_t> bytes) {
  Clip clip;
  ErrorInfo err;
  const Status s = Clip::load(bytes, clip, &err, fuzz_limits());
  if (s == Status::ok) {
    FUZZ_CHECK(err.status == Status::ok);
    const bool runtime = keyanim::fuzz::is_runtime_profile(bytes.data(), bytes.size());
    check_loaded(clip, !runtime);
    if (!runtime) return;
    Clip checked;
    const Status c = Clip::load(bytes, checked, &err, fuzz_limits(true));
    FUZZ_CHECK(c == Status::ok || (c == Status::corrupt && err.section == "IMAG"));
    if (c == Status::ok) check_loaded(checked, true);
    return;
  }
  FUZZ_CHECK(err.status == s);
  FUZZ_CHECK(!err.section.empty());
  FUZZ_CHECK(err.byte_offset <= bytes.size());
  FUZZ_CHECK(clip.channel_count() == 0 && clip.total_keys() == 0 && clip.frame_count() == 0);
  FUZZ_CHECK(clip.skeleton().joints.empty());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  load_once(std::span<const uint8_t>(data, size));
  const std::vector<uint8_t> fixed = keyanim::fuzz::with_fixed_checksum(data, size);
  load_once(fixed);
  return 0;
}
