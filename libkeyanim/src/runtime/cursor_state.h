// What a Cursor holds, and playback through it. Internal to the runtime.
#pragma once
#include <memory>
#include <vector>

#include "keyanim/clip.h"
#include "runtime/image.h"
#include "runtime/key_stream.h"
#include "runtime/sampler.h"

namespace keyanim {

namespace internal {
// Eight curves' segment states, field by field: the SIMD evaluation of 8 (or 4) curves reads
// each field with one load, and a refresh writes a curve's fields through one address.
struct SegmentLanes {
  alignas(32) float lo[8], hi[8], k0[8], k1[8], p0[8], d[8], m0[8], m1[8], value[8];
  uint32_t linear[8], direct[8];  // all ones / zeros, for select
  float result[8];                // before the scatter to channels
};
}  // namespace internal

struct Cursor::State {
  std::shared_ptr<const internal::Image> image;
  // Curve i's segment state (sampler.h's Segment, prepared for the polynomial): lanes[i / 8],
  // lane i % 8; the last group's lanes past the curves are padding.
  std::vector<internal::SegmentLanes> lanes;
  // Per curve, its keys around the current segment and where its record continues: playback
  // crosses a key every few frames, and the next segment is then one key read away.
  std::vector<internal::KeyStream> streams;
  std::vector<float> channels;  // a whole pose, for sample_local/model
};

namespace internal {
// Every channel at f through the cursor's state (prepared for img): out[c] for every channel.
void sample_playback(const Image& img, Cursor::State& st, float f, float* out) noexcept;
}  // namespace internal

}  // namespace keyanim
