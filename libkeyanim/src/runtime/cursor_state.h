// What a Cursor holds, and playback through it. Internal to the runtime.
#pragma once
#include <memory>
#include <vector>

#include "keyanim/clip.h"
#include "runtime/image.h"
#include "runtime/sampler.h"

namespace keyanim {

struct Cursor::State {
  std::shared_ptr<const internal::Image> image;
  // Per curve, structure of arrays: the segment state of sampler.h's Segment, for the SIMD
  // evaluation of every curve at once.
  std::vector<float> lo, hi, k0, k1, p0, d, m0, m1, value;
  std::vector<uint32_t> linear, direct;  // all ones / zeros, for select
  std::vector<float> result;             // per curve, before the scatter to channels
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
