// Fuzz target: a correctness fuzzer for the whole codec. Input: one settings byte, then BVH
// text. A small motion that reads (frames x channels <= 2000) is encoded, written as .kanim,
// loaded back by the runtime, decoded at the source rate and measured by FK.
// Checks: an encode that succeeds gives a file that write_kanim accepts and Clip::load loads;
// the skeleton, frame count and frame time come back exactly; decode_motion succeeds; and in
// the error-bounded key mode the measured maximum joint error is within the tolerance and equal
// to the error the encoder reported (it verified on the very values a decoder computes).
// Settings byte: bits 0-1 tolerance (0.05 %, 0.5 %, 2 %, 0.01 file units), bit 2 uniform
// tangent rule, bit 3 fitted tension, bit 4 no linear channels, bit 5 all linear, bits 6-7 key
// mode (error, error, uniform every 4th frame, curvature).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz_common.h"
#include "keyanim/clip.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/decode.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/metrics.h"

namespace {

using keyanim::Clip;
using keyanim::Status;
using namespace keyanim::offline;

constexpr uint64_t kMaxValues = 2000;

EncodeSettings settings_from(uint8_t b) {
  EncodeSettings s;
  static const double kTolerance[4] = {0.05, 0.5, 2.0, 0.01};
  s.tolerance = kTolerance[b & 3];
  s.tolerance_in_percent = (b & 3) != 3;
  s.tangent_rule = (b & 4) ? keyanim::TangentRule::uniform : keyanim::TangentRule::step_adjusted;
  s.fit_tension = (b & 8) != 0;
  s.allow_linear = (b & 16) == 0;
  s.force_linear = (b & 32) != 0;
  switch (b >> 6) {
    case 2: s.key_mode = KeyMode::uniform; s.uniform_interval = 4; break;
    case 3: s.key_mode = KeyMode::curvature; break;
    default: s.key_mode = KeyMode::error; break;
  }
  s.zstd_level = 1;  // fast; the level changes only the size
  return s;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const EncodeSettings settings = settings_from(data[0]);
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  Motion motion;
  try {
    motion = read_bvh(text, "fuzz.bvh");
  } catch (const Error&) {
    return 0;
  }
  const uint64_t channels = motion.channel_count();
  if (uint64_t(motion.frame_count) * channels > kMaxValues || motion.frame_count > kMaxValues ||
      motion.skeleton.joints.size() > kMaxValues)
    return 0;

  EncodeResult result;
  try {
    result = encode(motion, settings);
  } catch (const Error& e) {
    FUZZ_CHECK(std::string(e.what()).size() > 0);
    return 0;
  }
  // encode() refuses a clip no .kanim may hold (a frame time of 0 with several frames,
  // corpus/roundtrip/crash-frame-time-zero.bvh; a quantized value past 2^53,
  // crash-huge-value.bvh): whatever it returns must be storable.
  std::vector<uint8_t> file;
  try {
    file = write_kanim(result.clip, settings.zstd_level);
  } catch (const Error& e) {
    std::fprintf(stderr, "encode's clip cannot be written: %s\n", e.what());
    FUZZ_CHECK(false);
  }

  Clip clip;
  keyanim::ErrorInfo info;
  const Status s = Clip::load(file, clip, &info);
  if (s != Status::ok) {
    std::fprintf(stderr, "write_kanim's file does not load: %s at %s+%llu: %s\n", keyanim::status_string(s),
                 info.section.c_str(), static_cast<unsigned long long>(info.byte_offset), info.detail.c_str());
    FUZZ_CHECK(false);
  }
  FUZZ_CHECK(clip.frame_count() == motion.frame_count);
  FUZZ_CHECK(keyanim::fuzz::same_double(clip.frame_time(), motion.frame_time));
  FUZZ_CHECK(clip.channel_count() == channels);
  FUZZ_CHECK(clip.total_keys() == result.total_keys);
  const auto& a = motion.skeleton.joints;
  const auto& b = clip.skeleton().joints;
  FUZZ_CHECK(a.size() == b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    FUZZ_CHECK(a[i].name == b[i].name && a[i].parent == b[i].parent && a[i].end_site == b[i].end_site &&
               a[i].channels == b[i].channels);
    for (size_t k = 0; k < 3; ++k) FUZZ_CHECK(keyanim::fuzz::same_double(a[i].offset[k], b[i].offset[k]));
  }

  const Motion decoded = decode_motion(clip);
  FUZZ_CHECK(decoded.frame_count == motion.frame_count);
  FUZZ_CHECK(decoded.values.size() == motion.values.size());
  const ErrorReport measured = measure_error(motion, decoded);
  if (settings.key_mode == KeyMode::error) {
    if (!(measured.max_error <= result.tolerance_units) || measured.max_error != result.error.max_error) {
      std::fprintf(stderr, "max error %.17g (encoder reported %.17g), tolerance %.17g units\n", measured.max_error,
                   result.error.max_error, result.tolerance_units);
      FUZZ_CHECK(false);
    }
  }
  return 0;
}
