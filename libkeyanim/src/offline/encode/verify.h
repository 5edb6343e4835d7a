// Verification against what a decoder reproduces: the encoded channels decoded with the
// decoder's own arithmetic (cardinal.h), posed by FK and compared with the original pose on
// the measured points (metrics.h), window of frames by window, so that memory does not grow
// with the clip. Internal to the encoder.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "keyanim/offline/encode.h"
#include "keyanim/offline/fk.h"

namespace keyanim::offline {

// Decodes one channel at increasing frames, as a decoder computes it: the stored keys
// dequantized, segment_operands, segment_u, eval_operands, with the curve clamped outside its
// keys and exactly a key's value at a key. Keeps its segment between calls.
class ChannelCursor {
 public:
  ChannelCursor() = default;
  ChannelCursor(const EncodedChannel& ch, TangentRule rule) : ch_(&ch), rule_(rule) {}
  // The value at frame f; f must not decrease from call to call. (Inline: verification calls
  // it for every channel of every node it poses.)
  double at(uint32_t f) {
    const EncodedChannel& ch = *ch_;
    const size_t n = ch.frames.size();
    if (n == 0) return 0.0;
    const uint32_t* k = ch.frames.data();
    if (n == 1 || f <= k[0]) return dequantize(ch.q[0], ch.step);
    if (f >= k[n - 1]) return dequantize(ch.q[n - 1], ch.step);
    if (j_ == SIZE_MAX) j_ = size_t(std::upper_bound(k, k + n, f) - k) - 1;  // k[0] < f < k[n-1]
    while (k[j_ + 1] <= f) ++j_;
    if (f == k[j_]) return dequantize(ch.q[j_], ch.step);
    if (prepared_ != j_) prepare();
    return eval_operands(ops_, segment_u(k[j_], k[j_ + 1], float(f)));
  }

 private:
  const EncodedChannel* ch_ = nullptr;
  TangentRule rule_ = TangentRule::step_adjusted;
  size_t j_ = SIZE_MAX;         // segment [k[j], k[j+1]) of the last frame; SIZE_MAX: none yet
  size_t prepared_ = SIZE_MAX;  // segment whose operands are in ops_
  SegmentOperands ops_;
  void prepare();  // ops_ of segment j_
};

// The values of channel `ch` at the sorted frames `frames[0..count)`, into out[i * stride].
void decode_channel_at(const EncodedChannel& ch, TangentRule rule, const uint32_t* frames, size_t count, double* out,
                       size_t stride);

// Frame ranges [first, last] (increasing, disjoint) outside which `before` and `after` decode
// to the same values over a clip of `frame_count` frames. A value depends on the (up to) four
// keys around it, so each key that differs (present in one only, or with another value)
// spreads to two keys either side in both lists. May include frames whose value is the same.
void changed_ranges(const EncodedChannel& before, const EncodedChannel& after, uint32_t frame_count,
                    std::vector<std::pair<uint32_t, uint32_t>>& out);

// A node farther from its original than the tolerance at some frame.
// 16 bytes: a first round can hold one per node and frame of the clip.
struct OverNode {
  uint32_t frame = 0;
  uint32_t node : 31 = 0;
  uint32_t shell : 1 = 0;  // a shell point is over (then the node's own rotation moves it too)
  double error = 0.0;      // file length units: the largest distance among the node's measured points
};
static_assert(sizeof(OverNode) == 16);

// What to verify, frame by frame, and which nodes may have moved or were over there.
class FrameMarks {
 public:
  static constexpr uint8_t kChanged = 1;  // some decoded value may have changed
  static constexpr uint8_t kOver = 2;     // some node was over the tolerance when last verified
  static constexpr uint8_t kAll = 4;      // verify every node (every frame, in the first round)

  FrameMarks(uint32_t frames, size_t nodes);
  void mark_all() { std::fill(check_.begin(), check_.end(), kAll); }
  // Channels of `node` may decode differently at frames [first, last].
  void mark(uint32_t node, uint32_t first, uint32_t last);
  // Forgets which nodes moved (after a round's verification).
  void clear_moved();
  uint8_t* check() { return check_.data(); }
  bool moved(uint32_t node, uint32_t f) const { return bit(moved_, node, f); }
  bool over(uint32_t node, uint32_t f) const { return bit(over_, node, f); }
  // Records whether `node` was over at f. Calls for frames in different 64-frame words may run
  // concurrently.
  void set_over(uint32_t node, uint32_t f, bool over) {
    uint64_t& w = over_[node * words_ + f / 64];
    w = over ? w | uint64_t(1) << (f % 64) : w & ~(uint64_t(1) << (f % 64));
  }

 private:
  bool bit(const std::vector<uint64_t>& bits, uint32_t node, uint32_t f) const {
    return bits[node * words_ + f / 64] >> (f % 64) & 1;
  }
  size_t words_;
  std::vector<uint8_t> check_;   // per frame
  std::vector<uint64_t> moved_;  // per node, a bit per frame
  std::vector<uint64_t> over_;   // per node, a bit per frame: over when last measured
};

// The original's measured points (measured_points) at every frame, under each of
// measured_readings, posed once for every round instead of with each frame verified: one FK
// pass of four rows then verifies four frames instead of two (an original and a decoded row
// each). Held only where they take at most `budget` bytes (96 per node and frame and reading);
// otherwise empty, and verify_window poses the original with each frame as before. The same
// points either way, bit for bit (measured_points of four rows is that of each row alone).
// Their storage goes to the next clip encoded on the thread (spare.h).
class OriginalPoints {
 public:
  OriginalPoints() = default;
  OriginalPoints(const Motion& original, double shell, size_t budget, unsigned threads);
  ~OriginalPoints();
  OriginalPoints(const OriginalPoints&) = delete;
  OriginalPoints& operator=(const OriginalPoints&) = delete;
  bool empty() const noexcept { return per_frame_ == 0; }
  // Frame f's points under measured_readings(...)[reading].
  const Vec3* at(uint32_t f, size_t reading) const noexcept {
    return points_.data() + (reading * frames_ + f) * per_frame_;
  }

 private:
  size_t per_frame_ = 0, frames_ = 0, budget_ = 0;
  std::vector<Vec3> points_;  // reading-major, then frame-major
};

// Working memory of verify_window, one per thread. Frames are verified in groups (k = 0 .. 3
// within one): four rows posed together, each frame's original and decoded rows (two frames),
// or with OriginalPoints four frames' decoded rows.
struct VerifyScratch {
  std::vector<ChannelCursor> cursors;
  std::vector<uint32_t> frames;                // of the window, to verify
  std::array<std::vector<double>, 4> row;      // decoded
  std::array<std::vector<double>, 2> original; // with quaternion nodes: the original's, in stored form
  std::array<std::vector<uint8_t>, 4> measure; // per node: its error is measured
  std::vector<uint8_t> pose;                   // per node: posed (for any frame of the group)
  std::array<std::vector<double>, 4> error;    // per node: the largest distance over the readings
  std::array<std::vector<uint8_t>, 4> shell_over;  // per node: a shell point is over
  std::array<std::vector<Vec3>, 4> points;     // of the four rows posed
  std::array<std::vector<Vec3>, 4> points_add; // the same under the add reading (when measured)
};

// Verifies the frames f of [first, first + count) marked in `marks`: decodes the channels of
// the nodes that moved there (and their ancestors), poses original and decoded (under each of
// measured_readings), and appends to `over` each node whose error on its measured points
// (shell distance `shell`) exceeds `tolerance` (frame order, then node order) with its error,
// computed as measure_error does. Only the nodes that can have changed are measured: the
// subtrees of the nodes that moved, and the nodes that were over (every node at a frame marked
// kAll); every other node has not moved since it was last found within the tolerance, so the
// list is the one measuring every node would give. Frames with a node over stay marked kOver;
// the others are unmarked. `first` is a multiple of 64 where windows run concurrently.
// `originals`: the original's points, if held (the same result, in fewer instructions).
// `quats`: the clip's quaternion nodes (their rotation from stored x, y, z, in binary64). Their
// angles as a converter writes them (decode.h) pose the same points within a few ulps, so a
// node of such a clip is over from tolerance x (1 - kQuatMargin): what passes here passes
// measure_error on the decoded motion.
inline constexpr double kQuatMargin = 1e-9;
void verify_window(const Motion& original, const std::vector<EncodedChannel>& channels, TangentRule rule,
                   double tolerance, double shell, uint32_t first, uint32_t count, FrameMarks& marks,
                   std::vector<OverNode>& over, VerifyScratch& scratch, const OriginalPoints* originals = nullptr,
                   const QuatForms* quats = nullptr);

// The error report of `clip` (valid: validate_encoded_clip) against `original`, on the clip a
// decoder loads (to_clip) decoded at every frame as decode_motion does (a quaternion node's
// angles in binary64): measure_error's numbers, computed window by window on `threads`
// threads, shell distance `shell`.
ErrorReport measure_encoded(const Motion& original, const EncodedClip& clip, double shell, unsigned threads);

}  // namespace keyanim::offline
