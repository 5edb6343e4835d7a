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
};
}  // namespace internal

struct Cursor::State {
  std::shared_ptr<const internal::Image> image;
  // Curve i's segment state (sampler.h's Segment, prepared for the polynomial): lanes[i / 8],
  // lane i % 8; the last group's lanes past the curves are padding.
  std::vector<internal::SegmentLanes> lanes;
  // Per curve, its keys around the current segment and where its record continues: playback
  // crosses a key every few frames, and the next segment is then one key read away. A
  // quaternion track's three curves share their key frames: their streams move together, and
  // their states share one range (lo, hi), so that the track's x stands for the three.
  std::vector<internal::KeyStream> streams;
  // Curve i's value at the last position: in curve order, so that the x's, y's and z's of
  // consecutive quaternion tracks load into registers as they are (8 floats of padding past
  // the last group, read by those loads and never used).
  std::vector<float> results;
  std::vector<float> channels;  // a whole pose, for sample_local/model
};

namespace internal {
// Every channel at f through the cursor's state (prepared for img): out[c] for every channel.
// With `tracks`, a whole pose, the quaternion tracks' rotations go to tracks[node].rotation
// instead, straight from their curves' values (the same bits as from their channels, pose.cpp),
// and their channels in `out` are left as they are.
void sample_playback(const Image& img, Cursor::State& st, float f, float* out, Transform* tracks = nullptr) noexcept;
}  // namespace internal

}  // namespace keyanim
