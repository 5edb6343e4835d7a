// The world-space tolerance turned into per-channel, per-frame budgets through the hierarchy,
// and tightened where verification finds a node over. Internal to the encoder.
//
// A channel's error moves every measured point below it (metrics.h): a translation moves its
// own node's points and the subtree's, a rotation its own node's shell points and the strict
// descendants'. The first budget of a rotation is the angle that moves the farthest point it
// moves by the whole tolerance; of a translation, the tolerance. Where a node is over at a
// frame, every channel that moves the points over is tightened at that frame.
// Everything here is linear in the number of nodes (a 32,000-joint chain costs 32,000 steps
// per frame, not 32,000 squared).
#pragma once
#include <cstdint>
#include <vector>

#include "keyanim/offline/motion.h"
#include "offline/encode/channel_fit.h"

namespace keyanim::offline {

// For every node, the longest path (sum of local translation lengths, the largest over the
// clip and both readings of position channels) from it to a measured point its rotation
// moves: a descendant, or a shell point `shell` away from a joint at or below it.
std::vector<double> reach_below(const Motion& motion, double shell);

// Per channel, the first budget: `tol_units` for a translation; for a rotation, the angle in
// degrees that moves a point at reach_below by `tol_units` (at most 180: a rotation that moves
// no measured point).
std::vector<double> base_tolerances(const Motion& motion, double tol_units, double shell);

// A node over its budget at some frame, and the factor its movers' budgets are to be
// multiplied by there (< 1). shell: one of its shell points is over (its own rotation moves it).
struct NodeRatio {
  uint32_t node = 0;
  double ratio = 1.0;
  bool shell = false;
};

// Every channel's tolerance at every frame: its base times a per-frame factor. Factors are
// stored as float, rounded down (a budget may come out a hair tighter than computed, never
// looser): 4 bytes per value. Tracks which channels were tightened since they were last
// taken for refitting, and at which frames.
class Budgets {
 public:
  Budgets(const Skeleton& skeleton, std::vector<double> base, uint32_t frames);

  uint32_t channel_count() const noexcept { return uint32_t(base_.size()); }
  // The view a fit reads.
  Tolerance tolerance(uint32_t c) const noexcept;
  double min_tolerance(uint32_t c) const noexcept { return base_[c] * double(min_factor_[c]); }
  // Quantization step: the largest power of 2^(1/4) within `fraction` of the smallest
  // tolerance; but `held` (the step the channel has, 0: none) while that is less than twice
  // it. Requantizing moves every key of a channel, and so the error at frames that were within:
  // without the hold, late rounds chase the overs it makes (CMU assimp__01_01 at 0.5%: 47
  // rounds and 34,932 bytes; with it, 25 rounds and 29,724 bytes). A step held above the fraction may put a key off by more than its tolerance;
  // verification sees it and tightens there until the step shrinks.
  double step(uint32_t c, double fraction, double held = 0.0) const noexcept;

  // Tightens, at `frame`, each channel that moves one of `over` by the smallest ratio among
  // the nodes it moves. Frames must come in increasing order within a round.
  void tighten(uint32_t frame, const std::vector<NodeRatio>& over);
  // The channels tightened since the last call (all of them the first time), in order; their
  // tightened frames stay readable through changed_frames until they are tightened again.
  std::vector<uint32_t> take_dirty();
  // Frames of channel c tightened in the round it was last tightened, increasing.
  void changed_frames(uint32_t c, std::vector<uint32_t>& out) const;

 private:
  const Skeleton* skeleton_;
  uint32_t frames_;
  std::vector<double> base_;
  std::vector<float> factor_;      // channel-major: factor_[c * frames_ + f]
  std::vector<float> min_factor_;  // per channel
  std::vector<uint8_t> dirty_;
  size_t words_;                   // 64-bit words per channel in changed_
  std::vector<uint64_t> changed_;  // per channel, a bit per frame
  // Scratch of tighten(): per node, its own ratio, that of its shell points, and the smallest
  // ratio strictly below it.
  std::vector<double> own_, own_shell_, below_;
};

}  // namespace keyanim::offline
