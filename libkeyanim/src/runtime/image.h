// The runtime image: what a loaded clip holds in memory and samples in place. Keys stay
// quantized integers, bit-packed per time block, so that a loaded clip is about as compact as
// the keys themselves (spec/FORMAT.md, Appendix F, describes this layout; it is not part of
// the file format and may change between library versions).
//
// Time is cut into blocks of kBlockFrames frames. For every block and every channel with two
// keys or more (a "curve") that is not a list curve, one record holds the curve's keys inside
// the block plus two keys before and two after it (a quaternion track's record: its three
// curves', below): every key any position inside the block can need (a segment's two
// ends and their outer neighbours). Beyond the channel's first or last key, virtual keys
// repeat the end value at the end segment's spacing, which gives exactly the end rules of
// Appendix A (P_{-1} = P_0, tangent scale 1). So a record is self-contained: sampling one
// channel at one position reads one record header and one record.
//
// Record layout (byte-aligned start):
//   bytes 0-7     Mask          bit t set: a key at frame block_start + t
//   byte 8        Value_Bits    w, width of each value below (0..55)
//   byte 9        Context_Bits  wk, width of each context frame below (0..31)
//   then, bit-packed least significant bit first from byte 10:
//   Context       4 x wk        zigzag(frame - block_start) of the two keys before the block,
//                               zigzag(frame - block_end) of the two keys after it
//   Base          wc            the record's smallest q minus the curve's q_base (wc per curve)
//   Values        n x w         q - q_base - Base of the window's n = popcount(Mask) + 4 keys,
//                               in frame order: two before, the block's keys, two after
//
// A quaternion node's three curves share their key frames (version 5), so they share a record:
// its track's. Such a record has the Mask, three Value_Bits (x, y, z: bytes 8-10) and
// Context_Bits (byte 11), the Context from bit 96, then the three Bases, then the three curves'
// Values one after the other: one search of the mask gives the window of all three. Quaternion
// track t's curves are t, T + t and 2T + t (T tracks: their x's, then their y's, then their
// z's, before every other curve), so that the facts of 4 or 8 tracks load at once.
#pragma once
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "internal/clip_source.h"
#include "internal/format.h"
#include "keyanim/cardinal.h"
#include "keyanim/skeleton.h"
#include "runtime/image_layout.h"
#include "runtime/rig.h"

namespace keyanim {
class RigCache;
}

namespace keyanim::internal {

inline constexpr uint32_t kBlockShift = 6;
inline constexpr uint32_t kBlockFrames = 1u << kBlockShift;
inline constexpr uint32_t kRecordBitsAt = 80;  // Context starts after Mask, Value_Bits, Context_Bits
inline constexpr uint32_t kTrackRecordBitsAt = 96;  // in a quaternion track's: three Value_Bits
inline constexpr uint32_t kTrackCurves = 3;         // curves of a quaternion node's track
inline constexpr uint32_t kContextKeys = 4;
inline constexpr uint32_t kNoCurve = UINT32_MAX;
inline constexpr uint32_t kMaxValueBits = 55;    // Value_Bits and Base_Bits (spec 9.3)
inline constexpr uint32_t kMaxContextBits = 31;  // Context_Bits
inline constexpr uint32_t kPrefetchRecords = kImageTailEntries;  // see Image::record_offset
// so that an 8-byte load at any record bit is in bounds
inline constexpr size_t kPayloadPadding = kImageTailEntries;

// Per block curve, what reading its records needs (the rest is in Image's per-curve arrays):
// 24 bytes, since a cold pose reads one per curve.
struct Curve {
  int64_t q_base = 0;    // smallest q of the curve
  double step = 1.0;
  uint32_t base_bits = 0;  // wc
  uint32_t reserved = 0;   // IMAG's Curve_Reserved
};
static_assert(sizeof(Curve) == kCurveBytes && offsetof(Curve, base_bits) == 16, "IMAG's Curves entry (spec 9.2)");

// A list curve's keys: Image::list_frames/list_values[first .. first + count).
struct ListSpan {
  uint32_t first = 0, count = 0;
};

// The image's arrays are spans into its IMAG bytes (spec/FORMAT.md section 9.2, the runtime
// profile): the bytes build_image wrote (owned by `storage`), a runtime-profile file copied by
// Clip::load (owned too), or caller-owned bytes viewed by Clip::view (no owner: the caller keeps
// them alive). Either way the sampler reads the same layout.
struct Image {
  // Not copied or moved: `euler` may point at this image's own `own_euler`.
  Image() = default;
  Image(const Image&) = delete;
  Image& operator=(const Image&) = delete;

  // The clip.
  uint16_t version_major = 0, version_minor = 0;
  uint32_t frame_count = 0;
  double frame_time = 0.0;
  TangentRule rule = TangentRule::step_adjusted;
  // The rig (rig.h): skeleton and pose tables, shared by the clips of one rig loaded through
  // one RigCache. Never null in a built image.
  std::shared_ptr<const Rig> rig;
  std::string notes;
  uint64_t total_keys = 0;
  uint64_t id = 0;  // distinguishes clips for cursors (an address can be reused)
  std::shared_ptr<const void> storage;  // the bytes the spans below point into, unless viewed
  std::span<const uint8_t> imag;        // IMAG's content, 8-aligned
  size_t held_bytes = 0;                // bytes `storage` holds (the file's, or IMAG's)
  bool runtime_profile = false;         // read from a runtime-profile file (spec section 9)

  // Per channel (frame column).
  std::span<const Interpolation> interp;
  std::span<const float> tension;
  std::span<const uint32_t> key_count;
  std::span<const uint32_t> curve_of;  // index into curves, or kNoCurve
  std::span<const float> fixed_value;  // the value of a channel with fewer than two keys
  std::span<const uint32_t> fixed_frame;  // the frame of a channel's single key (0 without keys)
  std::span<const uint32_t> fixed_channels;  // channels with fewer than two keys, in order

  // Curves and their records. The per-curve arrays are separate so that 4 curves load at once.
  // Curves [0, block_curves) have a record per block; the others, sparse ones (fewer keys than
  // a quarter of the blocks), keep a plain list of keys instead, so that the image stays
  // linear in the keys whatever the frame count.
  std::span<const Curve> curves;
  uint32_t block_curves = 0;
  std::span<const ListSpan> lists;       // list curve block_curves + i: lists[i]
  std::span<const uint32_t> list_frames; // list curves' key frames, curve after curve
  std::span<const float> list_values;    // and their values
  std::span<const int64_t> list_q;       // and their quantized values (for conversion)
  // Padded to whole groups of 4 lanes (ImageLayout::lanes).
  std::span<const float> curve_s;        // (1 - tension) / 2
  std::span<const float> first_frame, last_frame;  // K_0 and K_{n-1}
  std::span<const float> first_value, last_value;  // v_0 and v_{n-1}
  std::span<const uint32_t> curve_linear;    // all ones: linear interpolation
  std::span<const uint32_t> curve_channel;   // curve i's output column (channel)
  // Quaternion nodes (version 5; none before): their nodes (the quat_tracks whose curves are
  // block curves first, each group in node order), the column of each one's x, and their
  // references as four arrays of quat_lanes floats (x's, y's, z's, w's; padding lanes the
  // identity), so that 4 or 8 nodes' rotations are built per register.
  std::span<const uint32_t> quat_node, quat_column;
  std::span<const float> quat_reference;
  uint32_t quat_lanes = 0;
  uint32_t quat_tracks = 0;
  // The Euler nodes' rotation groups (pose.cpp): the rig's when the clip has no quaternion
  // node, else those of the clip's Euler nodes (plan_rotations): `rig_euler`, kept by the rig
  // for every clip of the same quaternion nodes, or `own_euler`.
  const EulerGroups* euler = nullptr;
  EulerGroups own_euler;
  std::shared_ptr<const EulerGroups> rig_euler;  // or the rig's groups for the clip's set (Rig::plans)
  // Block tracks, one record per block each: quaternion track t < quat_tracks (curves t,
  // quat_tracks + t, 2 quat_tracks + t), then every other block curve alone.
  uint32_t block_tracks = 0;
  uint32_t block_count = 0;
  // [block * block_tracks + track]: byte offset in payload; kPrefetchRecords extra zeros at the
  // end, so that the sampler may read the offset of a record a few tracks ahead unchecked.
  std::span<const uint32_t> record_offset;
  std::span<const uint8_t> payload;      // records, then kPayloadPadding zero bytes

  // Block curve `curve`'s track, and its place in it (0 x .. 2 z, or 0 alone).
  struct TrackOf {
    uint32_t track, component, curves;  // curves: 1, or kTrackCurves
  };
  TrackOf track_of(uint32_t curve) const noexcept {
    if (curve >= 3 * quat_tracks) return {curve - 2 * quat_tracks, 0, 1};
    return {curve % quat_tracks, curve / quat_tracks, kTrackCurves};
  }
  const uint8_t* track_record(uint32_t block, uint32_t track) const noexcept {
    return payload.data() + record_offset[size_t(block) * block_tracks + track];
  }
  size_t skeleton_bytes() const noexcept { return rig->bytes(); }  // the rig's part
  size_t animation_bytes() const noexcept;  // the rest (image_build.cpp)
  size_t memory_bytes() const noexcept { return skeleton_bytes() + animation_bytes(); }
};

// IMAG's counts: its header's, and CLIP's channel count.
ImageCounts image_counts(std::span<const uint8_t> imag, uint32_t channels) noexcept;
// Sets img.euler (the rig and the quaternion nodes known): the rig's groups, or those of the
// clip's Euler nodes, made once per set of quaternion nodes and kept by the rig (Rig::plans;
// the clips of a cached rig share them), else the clip's own.
void plan_rotations(Image& img);
// Points `img`'s arrays into `imag` (IMAG's content, 8-aligned), whose header and sizes are
// known to be valid (built by build_image, or checked by the viewer): no check here.
void attach_image(Image& img, std::span<const uint8_t> imag, uint32_t channels) noexcept;

// Builds the image of a valid source (its keys decoded, every rule checked). With `rigs`, the
// skeleton is the cache's rig when it holds an equal one (rig.h).
std::shared_ptr<const Image> build_image(ClipSource&& source, RigCache* rigs = nullptr);
// The image of a runtime-profile file whose IMAG passed the structure checks (load/): `facts`
// holds its CLIP, SKEL and NOTE (no keys), `imag` points into `storage` (or into caller-owned
// bytes when `storage` is null: Clip::view).
// With `rig` (found in `rigs` by the file's SKEL bytes, `skel`), `facts` holds no skeleton;
// else its skeleton is interned in `rigs` (if any), which then remembers `skel`.
std::shared_ptr<const Image> view_image(ClipSource&& facts, uint64_t total_keys, std::span<const uint8_t> imag,
                                        std::shared_ptr<const void> storage, size_t held_bytes, RigCache* rigs,
                                        std::shared_ptr<const Rig> rig, std::span<const uint8_t> skel);
// The keys `img` holds (spec section 9.3), as a source (image_keys.cpp). A single key comes back
// as q = +-1 and step = |value| (the image keeps only its value): the same key, bit for bit.
ClipSource image_keys(const Image& img);
// Section 9.4's content rules: every q within 2^53 and every value finite, and IMAG exactly the
// image built from the keys it holds.
bool image_content_holds(const Image& img);
// Whether a curve of n keys over `blocks` blocks is kept as a list (see Image::curves).
inline bool is_list_curve(uint64_t n, uint64_t blocks) noexcept { return 4 * n < blocks; }

// `width` bits (<= 57) starting `bit` bits after p, least significant bit first. Reads the 8
// bytes from p + bit / 8.
inline uint64_t read_bits(const uint8_t* p, uint64_t bit, uint32_t width) noexcept {
  uint64_t x;
  std::memcpy(&x, p + (bit >> 3), 8);  // little-endian hosts (the x86-64 and ARM we build for)
  return (x >> (bit & 7)) & ((uint64_t(1) << width) - 1);
}

// One record's window around position t (0 <= t < kBlockFrames: frame block_start + t, or the
// block's first or last frame for positions outside it): key j is the last key at or before
// block_start + t (a context key when the block has none up to t), and j-1, j+1, j+2 its
// neighbours. Frames are relative to the block's start; the four keys' values are the
// value_bits-wide fields from record bit `at` on (window_values), and value + base + q_base is a
// key's q.
struct Window {
  int32_t frame[4];   // k_{j-1}, k_j, k_{j+1}, k_{j+2}
  uint64_t base;
  uint64_t at;        // record bit of key j-1's value
  uint32_t value_bits;
};

template <bool kPopcnt>
[[gnu::always_inline]] inline uint32_t popcount64(uint64_t x) noexcept {
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
inline int32_t top_bit(uint64_t x) noexcept { return 63 - __builtin_clzll(x); }
inline int32_t low_bit(uint64_t x) noexcept { return __builtin_ctzll(x); }
inline int32_t unzigzag32(uint64_t u) noexcept {
  return static_cast<int32_t>(static_cast<uint32_t>(u >> 1) ^ (0u - static_cast<uint32_t>(u & 1)));
}

// The four context frames of a record whose Context starts at byte `at` (kRecordBitsAt / 8,
// or kTrackRecordBitsAt / 8 in a quaternion track's), relative to the block's start.
[[gnu::always_inline]] inline void read_context(const uint8_t* rec, uint32_t at, uint32_t kw, int32_t* c) noexcept {
  if (kw <= 16) {  // one load: offsets below 2^15, the usual case
    uint64_t x;
    std::memcpy(&x, rec + at, 8);
    const uint64_t m = (uint64_t(1) << kw) - 1;
    c[0] = unzigzag32(x & m);
    c[1] = unzigzag32((x >> kw) & m);
    c[2] = unzigzag32((x >> (2 * kw)) & m);
    c[3] = unzigzag32((x >> (3 * kw)) & m);
  } else {
    for (uint32_t k = 0; k < 4; ++k) c[k] = unzigzag32(read_bits(rec, 8 * uint64_t(at) + k * kw, kw));
  }
  c[2] += static_cast<int32_t>(kBlockFrames);
  c[3] += static_cast<int32_t>(kBlockFrames);
}

// Bits 0..t set: the frames of a block at or before block_start + t.
inline uint64_t frames_upto(uint32_t t) noexcept { return t >= 63 ? ~uint64_t(0) : (uint64_t(2) << t) - 1; }

// The frames of the window around position t of a record with mask `mask` (its Context at byte
// `at`, kw bits each): k_{j-1} .. k_{j+2} relative to the block's start, into `frame`; returns
// how many of the block's keys lie at or before t. `upto` is frames_upto(t) (the same for
// every curve of a pose: computed once).
template <bool kPopcnt>
[[gnu::always_inline]] inline uint32_t window_frames(const uint8_t* rec, uint64_t mask, uint32_t at, uint32_t kw,
                                                     uint64_t upto, int32_t* frame) noexcept {
  // Keys up to t (bits 0..t) and after it; k_j, k_{j-1} are the highest keys at or below t,
  // k_{j+1}, k_{j+2} the lowest above, else the context keys before or after the block (read
  // only then: in a dense channel two keys on each side are the usual case).
  const uint64_t below = mask & upto;
  const uint64_t above = mask & ~upto;
  const int32_t top = top_bit(below | 1);  // | 1: defined when below is 0 (then unused)
  const uint64_t below_rest = below & ~(uint64_t(1) << top);
  const uint64_t above_rest = above & (above - 1);
  const uint64_t high = uint64_t(1) << 63;  // keeps low_bit defined (then unused)
  if (below_rest != 0 && above_rest != 0) [[likely]] {
    frame[0] = top_bit(below_rest);
    frame[1] = top;
    frame[2] = low_bit(above);
    frame[3] = low_bit(above_rest);
  } else {
    int32_t c[4];
    read_context(rec, at, kw, c);
    frame[0] = below_rest ? top_bit(below_rest | 1) : (below ? c[1] : c[0]);
    frame[1] = below ? top : c[1];
    frame[2] = above ? low_bit(above | high) : c[2];
    frame[3] = above_rest ? low_bit(above_rest | high) : (above ? c[2] : c[3]);
  }
  return popcount64<kPopcnt>(below);
}

template <bool kPopcnt>
[[gnu::always_inline]] inline void read_window(const uint8_t* rec, uint32_t base_bits, uint64_t upto, Window& w) noexcept {
  uint64_t mask;
  std::memcpy(&mask, rec, 8);
  const uint32_t vw = rec[8], kw = rec[9];
  const uint32_t count = window_frames<kPopcnt>(rec, mask, kRecordBitsAt / 8, kw, upto, w.frame);
  // Values: two context keys, then `count` keys up to t; key j-1 is value `count`.
  const uint64_t base_at = kRecordBitsAt + 4 * uint64_t(kw);
  w.base = read_bits(rec, base_at, base_bits);
  w.value_bits = vw;
  w.at = base_at + base_bits + uint64_t(count) * vw;
}

// Where one curve's fields lie in its block's record (its own, or its quaternion track's):
// for the paths that read one curve at a time (streams, key lists, checks).
struct CurveFields {
  uint64_t mask = 0;
  uint32_t context_at = 0;  // byte of Context
  uint32_t context_bits = 0, value_bits = 0;
  uint64_t base_at = 0;     // bit of Base
  uint64_t values_at = 0;   // bit of Values[0]
  uint64_t end = 0;         // bits of the whole record
};
// Component k of a record of `curves` curves (1, or kTrackCurves), whose Base_Bits are
// base_bits[0 .. curves).
inline CurveFields curve_fields(const uint8_t* rec, uint32_t k, uint32_t curves, const uint32_t* base_bits) noexcept {
  CurveFields f;
  std::memcpy(&f.mask, rec, 8);
  const uint64_t n = uint64_t(__builtin_popcountll(f.mask)) + kContextKeys;  // values per curve
  const uint32_t header = curves == 1 ? kRecordBitsAt : kTrackRecordBitsAt;
  f.context_at = header / 8;
  f.context_bits = rec[header / 8 - 1];
  f.value_bits = rec[8 + k];
  uint64_t at = header + uint64_t(kContextKeys) * f.context_bits;
  for (uint32_t i = 0; i < curves; ++i) {
    if (i == k) f.base_at = at;
    at += base_bits[i];
  }
  for (uint32_t i = 0; i < curves; ++i) {
    if (i == k) f.values_at = at;
    at += n * rec[8 + i];
  }
  f.end = at;
  return f;
}

// Block `block`'s record of block curve `curve` (its own, or its quaternion track's), with
// where its fields lie in it.
inline const uint8_t* curve_record(const Image& img, uint32_t block, uint32_t curve, CurveFields& f) noexcept {
  const Image::TrackOf t = img.track_of(curve);
  uint32_t base_bits[kTrackCurves];
  for (uint32_t k = 0; k < t.curves; ++k) base_bits[k] = img.curves[t.curves == 1 ? curve : t.track + k * img.quat_tracks].base_bits;
  const uint8_t* rec = img.track_record(block, t.track);
  f = curve_fields(rec, t.component, t.curves, base_bits);
  return rec;
}

// The index in img's quaternion arrays of its i-th quaternion node in node order (i < Q). The
// arrays list the tracks (A), then the others (B), each group in strictly increasing node order
// and no node in both (9.4); a binary search finds a, how many of A come before the i-th of the
// merge, in O(log Q): callers ask for every i, and Q reaches the node limit.
inline uint32_t quat_in_node_order(const Image& img, uint32_t i) noexcept {
  const uint32_t* node = img.quat_node.data();
  const uint32_t na = img.quat_tracks, nb = static_cast<uint32_t>(img.quat_node.size()) - na;
  const uint32_t* b = node + na;
  uint32_t lo = i > nb ? i - nb : 0, hi = std::min(i, na);
  while (lo < hi) {  // the first a such that A[a] is after B[i - a - 1]
    const uint32_t mid = lo + (hi - lo) / 2;
    if (node[mid] < b[i - mid - 1]) lo = mid + 1;
    else hi = mid;
  }
  const uint32_t j = i - lo;  // how many of B come before it
  return lo < na && (j >= nb || node[lo] < b[j]) ? lo : na + j;
}

// The window's four values (see Window).
inline void window_values(const uint8_t* rec, const Window& w, uint64_t* value) noexcept {
  const uint32_t vw = w.value_bits;
  if (vw <= 28) {  // two loads, two values each
    const uint64_t m = (uint64_t(1) << vw) - 1;
    uint64_t x, y;
    std::memcpy(&x, rec + (w.at >> 3), 8);
    std::memcpy(&y, rec + ((w.at + 2 * vw) >> 3), 8);
    x >>= w.at & 7;
    y >>= (w.at + 2 * vw) & 7;
    value[0] = x & m, value[1] = (x >> vw) & m;
    value[2] = y & m, value[3] = (y >> vw) & m;
  } else {
    for (uint32_t k = 0; k < 4; ++k) value[k] = read_bits(rec, w.at + k * vw, vw);
  }
}

}  // namespace keyanim::internal
