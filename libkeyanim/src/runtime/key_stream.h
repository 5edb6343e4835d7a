// A curve's keys around the playback position (the Cursor, cursor.cpp): its keys j-1 .. j+2
// and where the next key of its record or list is, so that moving to the next segment reads
// one key. Internal to the runtime; internal linkage and inlined, so that the copies of the
// Cursor compiled for each CPU level (internal/cpu.h) never call code of another level.
#pragma once
#include <cstdint>
#include <cstring>

#include "internal/cpu.h"
#include "runtime/gather.h"
#include "runtime/image.h"

namespace keyanim::internal {

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

// Moves the stream one key forward. False when its record has no further key (the position
// has left the record's block: seek instead).
KEYANIM_INLINE inline bool advance_stream(KeyStream& s) noexcept {
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

// Moves stream s (a quaternion track's y or z) one key forward with x, its track's x, which has
// just moved (advance_stream true): the same key frames (one Mask for the three), so only s's
// next value is read, from its own value run, in the order advance_stream would read it.
KEYANIM_INLINE inline void follow_stream(KeyStream& s, const KeyStream& x) noexcept {
  const float value = dequantize(s.low + static_cast<int64_t>(read_bits(s.rec, s.next_at, s.value_bits)), s.step);
  s.next_at += s.value_bits;
  std::memcpy(s.k, x.k, sizeof s.k);
  s.v[0] = s.v[1], s.v[1] = s.v[2], s.v[2] = s.v[3], s.v[3] = value;
}

namespace {

// Positions the stream on the segment holding f (K_0 < f < K_{n-1}): reads f's record.
KEYANIM_INLINE inline void seek_stream(const Image& img, uint32_t curve, float f, KeyStream& s) noexcept {
  const Curve& cv = img.curves[curve];
  if (curve >= img.block_curves) {  // a list curve: the stream walks the list
    const ListSpan list = img.lists[curve - img.block_curves];
    ListWindow w;
    list_window(img, list, f, w);
    for (int i = 0; i < 4; ++i) s.k[i] = static_cast<int32_t>(w.frame[i]), s.v[i] = w.value[i];
    s.list = img.list_frames.data() + list.first;
    s.list_values = img.list_values.data() + list.first;
    s.list_count = list.count;
    s.list_next = w.j + 3;
    s.block = 0;
    return;
  }
  s.list = nullptr;
  const Position at = position(img, f);
  CurveFields fl;
  const uint8_t* rec = curve_record(img, at.block, curve, fl);
  const uint64_t upto = frames_upto(at.t);
  Window w;
  const uint32_t below = window_frames<false>(rec, fl.mask, fl.context_at, fl.context_bits, upto, w.frame);
  w.base = read_bits(rec, fl.base_at, cv.base_bits);
  w.value_bits = fl.value_bits;
  w.at = fl.values_at + uint64_t(below) * fl.value_bits;
  float v[4];
  dequantize4(rec, w, cv, v);
  const int32_t start = static_cast<int32_t>(at.block << kBlockShift);
  for (int i = 0; i < 4; ++i) s.k[i] = w.frame[i] + start, s.v[i] = v[i];
  // Where key j+3 is: the block keys after key j+2, or the context keys after the block.
  int32_t c[4];
  read_context(rec, fl.context_at, fl.context_bits, c);
  s.after[0] = c[2] + start, s.after[1] = c[3] + start;
  const uint64_t above = fl.mask & ~upto;
  const uint64_t above_rest = above & (above - 1);
  s.rest = above_rest & (above_rest - 1);
  s.after_used = above_rest ? 0 : above ? 1 : 2;
  s.value_bits = w.value_bits;
  s.next_at = fl.values_at + uint64_t(below + 4) * w.value_bits;
  s.low = cv.q_base + static_cast<int64_t>(w.base);
  s.block = static_cast<int32_t>(at.block);
  s.rec = rec;
  s.step = cv.step;
}

}  // namespace
}  // namespace keyanim::internal
