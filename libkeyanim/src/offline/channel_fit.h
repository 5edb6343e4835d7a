// Fitting one channel: key frames, quantized key values and tension, so that the decoded curve
// stays within a per-frame tolerance. Internal to the encoder.
#pragma once
#include <cstdint>
#include <optional>
#include <queue>
#include <vector>

#include "keyanim/cardinal.h"
#include "keyanim/offline/encode.h"

namespace keyanim::offline {

// A channel's keys, kept within a per-frame tolerance by inserting keys at the worst frame
// (a max-heap of segments) and pruning keys that are not needed. The state persists, so that
// when the encoder tightens tolerances it refines from the keys it has instead of starting over.
// The arithmetic is the decoder's own (cardinal.h): what is checked here is what plays back.
class CurveFit {
 public:
  CurveFit(const std::vector<double>& y, Interpolation interp, float s, TangentRule rule);

  // Starts from `keys` (sorted; first and last frame included) with this tolerance and step.
  void reset(const std::vector<uint32_t>& keys, const std::vector<double>& tol, double step);
  // New tolerances (only ever smaller) and step: requantizes if the step changed, re-measures
  // the segments holding `changed` frames (sorted; null: all of them).
  void retarget(const std::vector<double>& tol, double step, const std::vector<uint32_t>* changed);
  // Inserts keys at the worst frames until every frame is within tolerance.
  void refine();
  // Removes interior keys whose absence keeps every frame within tolerance: every key after
  // reset(), afterwards only around the keys inserted since the last prune.
  void prune();
  // Least-squares s over the non-key frames: the curve is A + s B (method.md section 3).
  float best_s() const;

  size_t key_count() const { return count_; }
  EncodedChannel result(float tension) const;

 private:
  static constexpr uint32_t kNone = UINT32_MAX;
  struct Entry {
    double ratio;
    uint32_t start, end;
    bool operator<(const Entry& o) const { return ratio < o.ratio; }
  };
  void quantize(uint32_t f);
  void link(uint32_t f, uint32_t a, uint32_t b);  // make f a key between keys a and b
  void unlink(uint32_t f);
  // Segment starting at key frame `start`: worst ratio |error| / tol over the frames inside
  // it; queued if over budget.
  void measure(uint32_t start, bool push = true);
  void measure_all();

  const std::vector<double>* y_;  // pointers, not references: fits are copied
  const std::vector<double>* tol_ = nullptr;
  double step_ = 1.0;
  Interpolation interp_;
  float s_;
  TangentRule rule_;
  // Keys as a doubly linked list over frames, so inserting and removing are O(1).
  uint32_t first_ = kNone;
  size_t count_ = 0;
  std::vector<uint32_t> prev_, next_;  // kNone at the ends, and for frames that are not keys
  std::vector<uint8_t> is_key_;
  std::vector<int64_t> q_;
  std::vector<float> v_;
  // Per segment, indexed by its start frame: worst ratio, worst frame.
  std::vector<double> seg_ratio_;
  std::vector<uint32_t> seg_arg_;
  std::priority_queue<Entry> heap_;  // lazily invalidated: checked against the list when popped
  std::vector<uint32_t> recent_;     // keys inserted since the last prune
  bool prune_all_ = true;
  bool try_remove(uint32_t f);
};

struct ChannelFitOptions {
  TangentRule rule = TangentRule::step_adjusted;
  bool fit_tension = false;  // least-squares tension per channel, kept only if it saves keys
  float tension = 0.0f;      // used when not fitting
  bool allow_linear = true;  // try linear interpolation too and keep whichever needs fewer keys
  bool force_linear = false; // linear only
};

// One key (or none for zero) if a single quantized value is within tolerance everywhere.
std::optional<EncodedChannel> constant_channel(const std::vector<double>& y, const std::vector<double>& tol,
                                               double step);

// Keys at the given frames (sorted, first and last included); values quantized with `step`.
// Channels that are constant within `tol` still collapse to one key (or none if zero).
EncodedChannel fit_channel_at_keys(const std::vector<double>& y, const std::vector<uint32_t>& keys,
                                   const std::vector<double>& tol, double step,
                                   const ChannelFitOptions& options);

// The candidate fits of one channel in error mode (Cardinal with the given or fitted tension,
// and linear), kept across the encoder's tightening rounds.
class ChannelFitter {
 public:
  ChannelFitter(const std::vector<double>& y, const ChannelFitOptions& options);
  // Fits (or refits, from the previous keys) to these tolerances, whose values changed only at
  // `changed` frames since the last call (null: anywhere); returns the cheapest candidate.
  EncodedChannel fit(const std::vector<double>& tol, double step, const std::vector<uint32_t>* changed = nullptr);

 private:
  const std::vector<double>* y_;
  ChannelFitOptions opt_;
  std::vector<CurveFit> candidates_;
  std::vector<float> tensions_;
};

}  // namespace keyanim::offline
