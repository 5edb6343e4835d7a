// Fitting one channel, or a quaternion node's three curves together: key frames, quantized key
// values and tension, so that the decoded curve stays within a per-frame tolerance. Internal to
// the encoder.
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <queue>
#include <type_traits>
#include <vector>

#include "keyanim/cardinal.h"
#include "keyanim/offline/encode.h"

namespace keyanim::offline {

// A channel's tolerance at each frame: its base times a per-frame factor (1 where never
// tightened), so that a tolerance costs 4 bytes per frame.
struct Tolerance {
  double base = 0.0;
  const float* factor = nullptr;  // one per frame
  double at(uint32_t f) const noexcept { return base * double(factor[f]); }
};

// The stored integer of a value: round half away from zero of y / step (std::llround).
int64_t quantize(double y, double step) noexcept;

// A key as the segment arithmetic sees it (window_operands takes the four around a segment).
using Key = WindowKey;

// What a fit fits.
//  - ChannelCurve: one channel's signal (one value per frame); a frame's error is |decoded -
//    signal| against the tolerance.
//  - QuatCurve: a quaternion node's stored x, y, z (spec section 4.7), three curves on shared
//    key frames; the signals are x, y, z and w of its relative rotation per frame (unit, w >=
//    0), and a frame's error is the chord between that and the decoded rotation (keyanim/
//    rotation.h: w rebuilt, normalized), against a tolerance given as a chord (chord_tolerance).
struct ChannelCurve {
  static constexpr uint32_t kCurves = 1, kSignals = 1;
};
struct QuatCurve {
  static constexpr uint32_t kCurves = 3, kSignals = 4;
};
inline constexpr uint32_t kMaxFitCurves = 3;

// A chord tolerance for QuatCurve from an angle tolerance in radians (base, per-frame factors):
// unit quaternions an angle t apart are 2 sin(t / 4) apart, at least base_t * 2 sin(base / 4) /
// base for every t = base_t <= base (sin x / x falls): within it, the angle is within t.
inline Tolerance chord_tolerance(Tolerance angle) noexcept {
  const double b = angle.base;
  return {b > 0.0 ? 2.0 * std::sin(0.25 * b) : 0.0, angle.factor};
}

// The per-frame working arrays of a fit, reused from channel to channel (one per thread): what
// a channel keeps between the encoder's rounds is then its keys, not arrays over its frames.
// A fit leaves the arrays clean when it is destroyed.
struct FitScratch {
  std::vector<uint32_t> prev, next;  // kNone at the ends, and for frames that are not keys
  std::vector<uint8_t> is_key;
  std::array<std::vector<float>, kMaxFitCurves> v;  // key values per curve
  std::vector<double> seg_ratio;  // per segment, indexed by its start frame
  std::vector<uint32_t> seg_arg;
  std::vector<double> y;                   // a channel's signal, for the caller to fill
  std::array<std::vector<double>, 4> q;    // a quaternion node's x, y, z, w, for the caller to fill
  // Sizes every array for `frames` and `curves` key values per frame (keeping them clean).
  void prepare(size_t frames, uint32_t curves = 1);
  // The signals of a fit of `Kind` (y, or the four of q).
  template <class Kind>
  std::array<const double*, Kind::kSignals> signals() const noexcept {
    if constexpr (Kind::kSignals == 1) return {y.data()};
    else return {q[0].data(), q[1].data(), q[2].data(), q[3].data()};
  }
};

// A curve's keys (a channel's, or a quaternion node's shared by its three curves), kept within a
// per-frame tolerance by inserting keys at the worst frame (a max-heap of segments) and pruning
// keys that are not needed. Between the encoder's rounds only the key frames are kept; resume()
// rebuilds from them exactly the state the fit had, so that when tolerances tighten it refines
// from the keys it has instead of starting over. The arithmetic is the decoder's own
// (cardinal.h, rotation.h): what is checked here is what plays back.
template <class Kind>
class CurveFitT {
 public:
  static constexpr uint32_t kNone = UINT32_MAX;
  static constexpr uint32_t kCurves = Kind::kCurves;
  using Signals = std::array<const double*, Kind::kSignals>;

  // y: `frames` values per signal (kept by the caller for the fit's life).
  CurveFitT(Signals y, uint32_t frames, Interpolation interp, float s, TangentRule rule, FitScratch& scratch);
  ~CurveFitT();
  CurveFitT(const CurveFitT&) = delete;
  CurveFitT& operator=(const CurveFitT&) = delete;

  // Starts from `keys` (sorted; first and last frame included) with this tolerance and step.
  void reset(const std::vector<uint32_t>& keys, Tolerance tol, double step);
  // Continues a fit that ended with `keys` at `previous_step`: the tolerance is tighter only at
  // `changed` frames (sorted; null: anywhere). Re-measures the segments holding them, or every
  // segment after requantizing when the step changed.
  void resume(const std::vector<uint32_t>& keys, Tolerance tol, double step, double previous_step,
              const std::vector<uint32_t>* changed);
  // Inserts keys at the worst frames until every frame is within tolerance.
  void refine();
  // Removes interior keys whose absence keeps every frame within tolerance: every key after
  // reset(), afterwards only around the keys inserted since the last prune.
  void prune();
  // Least-squares s over the non-key frames: the curve is A + s B (method.md section 3).
  float best_s() const requires(Kind::kCurves == 1);

  size_t key_count() const { return count_; }
  // The key frames; leaves the fit empty and its scratch clean (cheaper than the destructor).
  std::vector<uint32_t> take_keys();

 private:
  struct Entry {
    double ratio;
    uint32_t start, end;
    bool operator<(const Entry& o) const { return ratio < o.ratio; }
  };
  void link_keys(const std::vector<uint32_t>& keys);
  void quantize_at(uint32_t f);
  void link(uint32_t f, uint32_t a, uint32_t b);  // make f a key between keys a and b
  void unlink(uint32_t f);
  // Segment starting at key frame `start`: worst ratio |error| / tol over the frames inside
  // it; queued if over budget.
  void measure(uint32_t start, bool push = true);
  // A linear segment depends on its two keys only: a key inserted or removed between a and b
  // leaves [prev(a), a] and [b, next(b)] as they were, and where every segment's ratio is
  // current (since measure_all) the stored one stands for a re-measurement. The same keys
  // (every corpus file's bytes as before, at 0.05% and 0.5%, and with linear forced), for
  // 3.6% fewer encoding instructions on CMU 01_01 and 2.4% on Bandai walk_normal_001
  // (callgrind, one thread): the first fit tries linear on every channel.
  bool neighbours_stand() const { return interp_ == Interpolation::linear && all_measured_; }
  // measure() of a segment next to a change.
  void measure_neighbour(uint32_t start);
  void measure_all();
  bool try_remove(uint32_t f);

  Signals y_;
  Tolerance tol_;
  double step_ = 1.0;
  Interpolation interp_;
  float s_;
  TangentRule rule_;
  FitScratch& w_;  // the per-frame arrays (a doubly linked list of keys over frames, O(1) edits)
  uint32_t first_ = kNone;
  size_t count_ = 0;
  std::priority_queue<Entry> heap_;  // lazily invalidated: checked against the list when popped
  std::vector<uint32_t> recent_;     // keys inserted since the last prune
  bool prune_all_ = true;
  bool all_measured_ = false;  // every segment's seg_ratio and seg_arg are this fit's
};
using CurveFit = CurveFitT<ChannelCurve>;
using QuatFit = CurveFitT<QuatCurve>;

struct ChannelFitOptions {
  TangentRule rule = TangentRule::step_adjusted;
  bool fit_tension = false;  // least-squares tension per channel, kept only if it saves keys
  float tension = 0.0f;      // used when not fitting
  bool allow_linear = true;  // try linear interpolation too and keep whichever needs fewer keys
  bool force_linear = false; // linear only
};

// One key (or none for zero) if a single quantized value is within tolerance everywhere, with
// the largest power of two up to `step` as its step where that is within tolerance too (and
// always without keys).
// `lo` and `hi` are the smallest and largest of y.
std::optional<EncodedChannel> constant_channel(const double* y, uint32_t frames, double lo, double hi,
                                               Tolerance tol, double step);
// The same for a quaternion node (QuatCurve's signals, its chord tolerance): no key where its
// rotation is within of the reference everywhere, else one where x, y, z at the middle of their
// extents are.
std::optional<std::array<EncodedChannel, 3>> constant_quat(const QuatFit::Signals& y, uint32_t frames,
                                                           const double* lo, const double* hi, Tolerance tol,
                                                           double step);

// Keys at the given frames (sorted, first and last included); values quantized with `step`.
// Channels that are constant within `tol` still collapse to one key (or none if zero).
EncodedChannel fit_channel_at_keys(const std::vector<double>& y, const std::vector<uint32_t>& keys, Tolerance tol,
                                   double step, const ChannelFitOptions& options, FitScratch& scratch);
// The same for a quaternion node (scratch.q holds its signals; tol is its chord tolerance).
std::array<EncodedChannel, 3> fit_quat_at_keys(const std::vector<uint32_t>& keys, Tolerance tol, double step,
                                               const ChannelFitOptions& options, FitScratch& scratch);

// The candidate fits of one channel, or of a quaternion node's three curves, in error mode
// (Cardinal with the given or fitted tension, and linear); the first fit's winner is kept
// across the encoder's tightening rounds as its key frames.
template <class Kind>
class CurveFitter {
 public:
  using Result = std::conditional_t<Kind::kCurves == 1, EncodedChannel, std::array<EncodedChannel, 3>>;
  explicit CurveFitter(const ChannelFitOptions& options) : opt_(options) {}
  // Fits (or refits, from the previous keys) the signals in `scratch` (y, or q) to these
  // tolerances, whose values changed only at `changed` frames since the last call (null:
  // anywhere); returns the candidate with the fewest keys.
  Result fit(Tolerance tol, double step, const std::vector<uint32_t>* changed, FitScratch& scratch);
  // True if fit() with these arguments would return what the last fit() returned: that was a
  // candidate (not a constant channel, which tighter tolerances at the same step cannot make
  // one), the step is the same, and every segment fit() would re-measure for the `changed`
  // frames (sorted) is still within `tol`. The caller then keeps the channel it has: no key
  // list to rebuild, nothing to requantize or compare. From the third round, a quarter (CMU
  // 01_01) to nearly all (Bandai walk_normal_001) of the channels tightened in a round keep
  // their keys; encoding takes 3.7% fewer instructions on 01_01 and 5.8% on that walk
  // (callgrind, one thread), for the same bytes.
  bool holds(Tolerance tol, double step, const std::vector<uint32_t>& changed,
             const typename CurveFitT<Kind>::Signals& y) const;
  bool holds(Tolerance tol, double step, const std::vector<uint32_t>& changed, const double* y) const
    requires(Kind::kSignals == 1)
  {
    return holds(tol, step, changed, typename CurveFitT<Kind>::Signals{y});
  }
  // How many candidates the next fit refits (keep_fewest).
  size_t candidate_count() const { return candidates_.size(); }

 private:
  // Keeps only the candidates with the fewest keys (all of them on a tie): the interpolation
  // and tension are chosen by the first fit, and the rounds that follow refine the winner
  // alone. Measured on the corpus (bench_codec, 42 files) against refitting every candidate
  // each round and taking the fewest keys: 0.6% fewer bytes at 0.05% of the skeleton size and
  // 0.2% fewer at 0.5%, for 24% fewer encoding instructions on CMU 01_01 (callgrind, one
  // thread; 12% on Bandai walk_normal_001). Keeping also those within 5% of the fewest: 0.3%
  // and 0.5% fewer bytes; within 10% plus 2 keys: 0.05% fewer and 0.2% more, for 4% fewer
  // instructions. The cost: Bandai 30 fps clips are 0.7% larger (bench_vs_acl's median, 0.782
  // -> 0.787 of ACL's bytes); keeping every candidate through the second fit too keeps them as
  // they were, for 17.5% fewer instructions on 01_01 and 3.8% on the Bandai walk.
  void keep_fewest();
  struct Candidate {
    Interpolation interp;
    float tension;
    double step = 0.0;            // of the last fit
    std::vector<uint32_t> keys;   // key frames at the end of the last fit
  };
  // Whether every segment of c's keys that holds one of `changed` is within `tol`.
  bool segments_within(const Candidate& c, const typename CurveFitT<Kind>::Signals& y, Tolerance tol,
                       const std::vector<uint32_t>& changed) const;
  ChannelFitOptions opt_;
  std::vector<Candidate> candidates_;
  bool fitted_ = false;  // the last fit() returned candidates_.front()
  bool have_extent_ = false;
  double lo_[Kind::kCurves] = {}, hi_[Kind::kCurves] = {};  // extents of the signals (they do not change between rounds)
};
using ChannelFitter = CurveFitter<ChannelCurve>;
using QuatFitter = CurveFitter<QuatCurve>;

}  // namespace keyanim::offline
