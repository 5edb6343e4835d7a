// The runtime image: what a loaded clip holds in memory and samples in place. Keys stay
// quantized integers, bit-packed per time block, so that a loaded clip is about as compact as
// the keys themselves (spec/FORMAT.md, Appendix F, describes this layout; it is not part of
// the file format and may change between library versions).
//
// Time is cut into blocks of kBlockFrames frames. For every block and every channel with two
// keys or more (a "curve"), one record holds the channel's keys inside the block plus two keys
// before and two after it: every key any position inside the block can need (a segment's two
// ends and their outer neighbours). Beyond the channel's first or last key, virtual keys
// repeat the end value at the end segment's spacing, which gives exactly the end rules of
// Appendix A (P_{-1} = P_0, tangent scale 1). So a record is self-contained: sampling one
// channel at one position reads one record header and one record.
//
// Record layout (byte-aligned start, then bit-packed least significant bit first):
//   Mask          64 bits   bit t set: a key at frame block_start + t
//   Value_Bits     6 bits   w, width of each value below (0..55)
//   Context_Bits   5 bits   wk, width of each context frame below (0..31)
//   Base          wc bits   the record's smallest q minus the curve's q_base (wc per curve)
//   Context       4 x wk    zigzag(frame - block_start) of the two keys before the block,
//                           zigzag(frame - block_end) of the two keys after it
//   Values        n x w     q - q_base - Base of the window's n = popcount(Mask) + 4 keys, in
//                           frame order: two before, the block's keys, two after
#pragma once
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "internal/clip_source.h"
#include "keyanim/cardinal.h"
#include "keyanim/skeleton.h"

namespace keyanim::internal {

inline constexpr uint32_t kBlockShift = 6;
inline constexpr uint32_t kBlockFrames = 1u << kBlockShift;
inline constexpr uint32_t kRecordFixedBits = 64 + 6 + 5;  // Mask, Value_Bits, Context_Bits
inline constexpr uint32_t kContextKeys = 4;
inline constexpr uint32_t kNoCurve = UINT32_MAX;
inline constexpr size_t kPayloadPadding = 8;  // so that an 8-byte load at any record bit is in bounds

// Per curve: what the sampler needs besides the records. 48 bytes, one cache line for most.
struct Curve {
  double step = 1.0;
  int64_t q_base = 0;       // smallest q of the curve
  float s = 0.5f;           // (1 - tension) / 2
  float first_frame = 0.0f, last_frame = 0.0f;  // K_0 and K_{n-1}
  float first_value = 0.0f, last_value = 0.0f;  // v_0 and v_{n-1}
  uint32_t channel = 0;     // output column
  uint16_t context_at = 0;  // bit offset of Context in a record: kRecordFixedBits + wc
  uint8_t base_bits = 0;    // wc
  uint8_t linear = 0;       // 1: linear interpolation
};

struct Image {
  // The clip.
  uint16_t version_major = 0, version_minor = 0;
  uint32_t frame_count = 0;
  double frame_time = 0.0;
  TangentRule rule = TangentRule::step_adjusted;
  Skeleton skeleton;
  std::vector<float> node_offset;  // 3 per node: OFFSET in binary32, for poses
  std::string notes;
  uint64_t total_keys = 0;
  uint64_t id = 0;  // distinguishes clips for cursors (an address can be reused)

  // Per channel (frame column).
  std::vector<Interpolation> interp;
  std::vector<float> tension;
  std::vector<uint32_t> key_count;
  std::vector<uint32_t> curve_of;  // index into curves, or kNoCurve
  std::vector<float> fixed_value;  // the value of a channel with fewer than two keys
  std::vector<uint32_t> fixed_frame;  // the frame of a channel's single key (0 without keys)
  std::vector<uint32_t> fixed_channels;  // channels with fewer than two keys, in order

  // Curves and their records.
  std::vector<Curve> curves;
  uint32_t block_count = 0;
  std::vector<uint32_t> record_offset;  // [block * curves.size() + curve]: byte offset in payload
  std::vector<uint8_t> payload;         // records, then kPayloadPadding zero bytes

  const uint8_t* record(uint32_t block, uint32_t curve) const noexcept {
    return payload.data() + record_offset[size_t(block) * curves.size() + curve];
  }
  size_t memory_bytes() const noexcept;
};

// Builds the image of a valid source (its keys decoded, every rule checked).
std::shared_ptr<const Image> build_image(ClipSource&& source);

// `width` bits (<= 57) starting `bit` bits after p, least significant bit first. Reads the 8
// bytes from p + bit / 8.
inline uint64_t read_bits(const uint8_t* p, uint64_t bit, uint32_t width) noexcept {
  uint64_t x;
  std::memcpy(&x, p + (bit >> 3), 8);  // little-endian hosts (the x86-64 and ARM we build for)
  return (x >> (bit & 7)) & ((uint64_t(1) << width) - 1);
}
inline int64_t unzigzag(uint64_t u) noexcept { return static_cast<int64_t>(u >> 1) ^ -static_cast<int64_t>(u & 1); }

// One record's window around position t (0 <= t < kBlockFrames: frame block_start + t, or the
// block's first or last frame for positions outside it): key j is the last key at or before
// block_start + t (a context key when the block has none up to t), and j-1, j+1, j+2 its
// neighbours. Frames are relative to the block's start; values are q - q_base.
struct Window {
  int64_t frame[4];   // k_{j-1}, k_j, k_{j+1}, k_{j+2}
  uint64_t value[4];  // q_{j-1} .. q_{j+2}, minus q_base
};

template <bool kPopcnt>
inline uint32_t popcount64(uint64_t x) noexcept {
  if constexpr (kPopcnt) {
    return static_cast<uint32_t>(__builtin_popcountll(x));
  } else {  // SWAR: the baseline x86-64 has no popcnt instruction
    x = x - ((x >> 1) & 0x5555555555555555ull);
    x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
    x = (x + (x >> 4)) & 0x0F0F0F0F0F0F0F0Full;
    return static_cast<uint32_t>((x * 0x0101010101010101ull) >> 56);
  }
}

// Index of the highest set bit (x != 0) / lowest set bit (x != 0).
inline int64_t top_bit(uint64_t x) noexcept { return 63 - __builtin_clzll(x); }
inline int64_t low_bit(uint64_t x) noexcept { return __builtin_ctzll(x); }

template <bool kPopcnt>
inline void read_window(const uint8_t* rec, const Curve& c, uint32_t t, Window& w) noexcept {
  uint64_t mask;
  std::memcpy(&mask, rec, 8);
  const uint64_t widths = read_bits(rec, 64, 11);
  const uint32_t vw = static_cast<uint32_t>(widths & 63);
  const uint32_t kw = static_cast<uint32_t>(widths >> 6);
  const uint64_t base = read_bits(rec, kRecordFixedBits, c.base_bits);
  const uint64_t cat = c.context_at;
  const int64_t before0 = unzigzag(read_bits(rec, cat, kw));
  const int64_t before1 = unzigzag(read_bits(rec, cat + kw, kw));
  const int64_t after0 = unzigzag(read_bits(rec, cat + 2 * kw, kw)) + kBlockFrames;
  const int64_t after1 = unzigzag(read_bits(rec, cat + 3 * kw, kw)) + kBlockFrames;
  // Keys up to t (bits 0..t) and after it.
  const uint64_t upto = t >= 63 ? ~uint64_t(0) : (uint64_t(2) << t) - 1;
  const uint64_t below = mask & upto;
  const uint64_t above = mask & ~upto;
  const uint32_t count = popcount64<kPopcnt>(below);
  // k_j and k_{j-1}: the highest keys at or below t, else the context before the block.
  const int64_t top = top_bit(below | 1);  // | 1: defined when below is 0 (then unused)
  const uint64_t below_rest = below & ~(uint64_t(1) << top);
  const int64_t kj = below ? top : before1;
  const int64_t kjm = below_rest ? top_bit(below_rest | 1) : (below ? before1 : before0);
  // k_{j+1} and k_{j+2}: the lowest keys above t, else the context after the block.
  const uint64_t above_rest = above & (above - 1);
  const int64_t kjp = above ? low_bit(above) : after0;
  const int64_t kjp2 = above_rest ? low_bit(above_rest) : (above ? after0 : after1);
  w.frame[0] = kjm;
  w.frame[1] = kj;
  w.frame[2] = kjp;
  w.frame[3] = kjp2;
  // Window index of key j: two context keys, then `count` keys up to t.
  const uint64_t at = cat + 4 * uint64_t(kw) + uint64_t(count) * vw;  // value of k_{j-1}
  w.value[0] = base + read_bits(rec, at, vw);
  w.value[1] = base + read_bits(rec, at + vw, vw);
  w.value[2] = base + read_bits(rec, at + 2 * vw, vw);
  w.value[3] = base + read_bits(rec, at + 3 * vw, vw);
}

}  // namespace keyanim::internal
