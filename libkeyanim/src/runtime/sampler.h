// Sampling the runtime image (image.h): any set of channels at any frame position, exactly as
// Appendix A of spec/FORMAT.md computes them. Internal to the runtime; Clip and Cursor call it.
#pragma once
#include <cstdint>

#include "keyanim/cardinal.h"
#include "runtime/image.h"

namespace keyanim::internal {

// Every channel at frame position f (not NaN): out[c] for c < channel count.
void sample_all(const Image& img, float f, float* out) noexcept;
// The same but the quaternion tracks' channels, left as they were: for a pose, which takes
// those tracks' rotations from quat_track_rotations (quat_tracks.h).
void sample_all_but_quat_tracks(const Image& img, float f, float* out) noexcept;
// The listed channels (each < channel count): out[i] for channels[i].
void sample_listed(const Image& img, float f, const uint32_t* channels, uint32_t count, float* out) noexcept;

// The channels first .. first + count - 1 (each < channel count): out[i] for channel first + i.
void sample_range(const Image& img, float f, uint32_t first, uint32_t count, float* out) noexcept;

// Playback support (the Cursor): one curve's keys j-1 .. j+2 around the current position, and
// where the next key of its record is, so that moving to the next segment reads one key.
struct KeyStream {
  int32_t k[4];          // absolute frames of keys j-1 .. j+2
  float v[4];            // their values
  const uint8_t* rec = nullptr;  // the record
  double step = 1.0;
  int64_t low = 0;       // q_base + the record's Base
  uint64_t rest = 0;     // the record's block keys after key j+2 (mask bits)
  uint64_t next_at = 0;  // bit position in the record of the next key's value
  int32_t after[2];      // the record's two context keys after the block
  int32_t block = -1;    // the record's block, -1 for none
  uint32_t value_bits = 0;
  uint32_t after_used = 0;  // context keys after the block already in k
  // A list curve's stream (Image::curves): its keys, and the index of the next one to read.
  const uint32_t* list = nullptr;
  const float* list_values = nullptr;
  uint32_t list_count = 0, list_next = 0;
};

// Positions the stream on the segment holding f (K_0 < f < K_{n-1}): reads f's record.
void seek_stream(const Image& img, uint32_t curve, float f, KeyStream& s) noexcept;
// Moves the stream one key forward. False when its record has no further key (the position
// has left the record's block: seek instead).
inline bool advance_stream(KeyStream& s) noexcept {
  int32_t next;
  if (s.list != nullptr) {  // the next key of the list; one virtual key after the last
    const uint32_t n = s.list_count, i = s.list_next++;
    if (i > n) return false;
    next = i < n ? static_cast<int32_t>(s.list[i]) : 2 * static_cast<int32_t>(s.list[n - 1]) - static_cast<int32_t>(s.list[n - 2]);
    s.k[0] = s.k[1], s.k[1] = s.k[2], s.k[2] = s.k[3], s.k[3] = next;
    s.v[0] = s.v[1], s.v[1] = s.v[2], s.v[2] = s.v[3], s.v[3] = s.list_values[i < n ? i : n - 1];
    return true;
  }
  if (s.rest != 0) {
    next = static_cast<int32_t>(static_cast<uint32_t>(s.block) << kBlockShift) + low_bit(s.rest);
    s.rest &= s.rest - 1;
  } else if (s.after_used < 2) {
    next = s.after[s.after_used++];
  } else {
    return false;
  }
  const float value = dequantize(s.low + static_cast<int64_t>(read_bits(s.rec, s.next_at, s.value_bits)), s.step);
  s.next_at += s.value_bits;
  s.k[0] = s.k[1], s.k[1] = s.k[2], s.k[2] = s.k[3], s.k[3] = next;
  s.v[0] = s.v[1], s.v[1] = s.v[2], s.v[2] = s.v[3], s.v[3] = value;
  return true;
}

}  // namespace keyanim::internal
