// The codec core, as a driver over its pieces: input checks and channel signals (signals.h),
// per-channel, per-frame budgets through the hierarchy (budget.h), fitting (channel_fit.h),
// verification on exactly what a decoder reproduces (verify.h), all on parallel_for
// (parallel.h). In error mode the world-space tolerance becomes budgets; each round fits the
// channels whose budgets changed, verifies the frames whose values changed, and tightens
// budgets only at the frames and channels where a node is over, until every measured point
// (joints, End Sites, shell points; under both readings of position channels where they
// differ: metrics.h) is within the tolerance. Memory: the motion, each channel's budgets (4 bytes per value) and
// keys, and windows of frames.
#include "keyanim/offline/encode.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "keyanim/offline/container.h"
#include "keyanim/offline/curvature.h"
#include "keyanim/offline/keyframes.h"
#include "offline/encode/budget.h"
#include "offline/encode/channel_fit.h"
#include "offline/encode/notes.h"
#include "offline/encode/rotations.h"
#include "offline/encode/signals.h"
#include "offline/encode/verify.h"
#include "offline/parallel.h"
#include "keyanim/offline/number_text.h"

namespace keyanim::offline {
namespace {

// Every channel's first budget is the whole tolerance (budget.h): errors of the channels along
// a chain rarely peak on the same frame, so this beats any safe split (measured: half of it
// costs 2-8% more bytes on CMU clips); verification tightens where it is wrong.
// Quantization step as a fraction of the channel's smallest per-frame tolerance (a key is then
// off by at most that tolerance; Budgets::step). Errors are checked after quantization, so a
// coarse step costs only a few extra keys. Measured on the corpus (bench_codec, 41 files) with
// the steps of Budgets::step, held (kStepHoldRounds), against 1.5: 2.0 takes 2.1% fewer bytes
// at 0.05% of the skeleton size and 0.9% more at 0.5% (1.75: 1.3% fewer, 1.5% more); with
// quarter octaves and no hold, 2.25 and 2.5 lost at 0.5% (2.5% and 6.4% more than 1.5).
constexpr double kStepFraction = 2.0;
// Tightening multiplies a tolerance by the ratio it is over times a margin. A margin near 1
// wastes no budget but needs more rounds (0.97 throughout fails to converge in 40 rounds on
// half the corpus), so it falls with the rounds. Measured on the 17 CMU 120 fps clips against
// a fixed 0.9: 3.3% smaller at 0.05% and 4.1% at 0.5% of the skeleton size, for about a
// quarter more encoding time. The last rounds tighten hard, so that convergence does not
// depend on the schedule's first steps.
double tighten_margin(uint32_t round) {
  return round < 10 ? 0.98 : round < 20 ? 0.93 : round < 30 ? 0.8 : 0.5;
}
constexpr uint32_t kMaxRounds = 50;
// Steps are held until this round: the last rounds follow the smallest tolerance, so that
// convergence does not depend on the hold. Measured on the corpus (bench_codec, 41 files)
// with powers of 2^(1/4) against quarter octaves below the base and no hold: 1.9% fewer bytes
// at 0.05% of the skeleton size, 3.3% at 0.5% (the hold alone: 0.9% and 1.6%; the powers
// alone: 0.1% fewer and 0.9% more); the largest ratio to ACL among Bandai 30 fps clips 1.030
// -> 0.983 at 0.05%, 1.097 -> 1.034 at 0.5%. Holding from round 10 or 20: 1.1% and 3.1%, 0.7%
// and 1.5% fewer; holding until the step falls below 0.6 of it (not 0.5): 1.6% and 2.9%.
constexpr uint32_t kStepHoldRounds = 40;
// Frames per verification job: small enough that a job's decoded rows stay in cache.
constexpr uint32_t kVerifyWindow = 128;
// Windows per batch of verification (verify_and_tighten): 8,192 frames.
constexpr size_t kVerifyBatch = 64;
// The original's points are posed once for all rounds where they take at most this (verify.h:
// OriginalPoints; 96 bytes per node, frame and reading): every Bandai clip of the corpus but
// its 1,901-frame one, and 12 of its 17 CMU 120 fps clips (38 nodes, one reading: up to 2,300
// frames). Small next to the process's own footprint; a long clip, whose memory is a target,
// poses them with each frame. (16 MiB would take CMU 01_01 too: 5.9% fewer instructions, but
// its peak 13.5 -> 23.3 MB.)
// The same bytes on every corpus file; `keyanim encode -j 1` (callgrind): Bandai walk_normal_001
// 131.8 M -> 125.9 M instructions, bow_feminine_001 109.1 M -> 103.2 M, dash_normal_001 (20
// frames) 23.1 M -> 22.6 M; CPU time of encode 10.9 -> 10.5 ms, 9.5 -> 9.0 ms (best of three
// medians of 11, one process).
constexpr size_t kOriginalPointsBudget = size_t(8) << 20;
// A quaternion node's first budget, as a multiple of the angle of its rotation channels'
// (each of which an Euler channel spends whole: three of them may take up to three times it
// together), and its step: the largest power of 2^(1/4) within this fraction of its smallest
// angle tolerance. Measured on the 17 CMU 120 fps and 11 Bandai 30 fps corpus clips at 0.05%
// (file bytes against Euler channels', median per group), scale x step: 1.0 x 0.7: 0.957 /
// 1.009; 1.3 x 0.7: 0.955 / 0.994; 1.6 x 0.5, 0.6, 0.7, 0.8, 1.0: 0.972 / 0.997, 0.951 /
// 0.991, 0.954 / 0.991, 0.957 / 0.995, 0.992 / 1.010; 2.0 x 0.7: 0.951 / 0.991.
constexpr double kQuatBudgetScale = 1.6;
constexpr double kQuatStepFraction = 0.7;
constexpr double kRadPerDeg = 3.14159265358979323846 / 180.0;

// Every channel's signal is made once for all rounds where it takes at most this (signals.h:
// Signals, 8 bytes per value): every corpus clip, up to 1M values (CMU 01_01 has 264,192);
// the rounds read the motion's columns again on longer ones, whose memory is a target.
constexpr size_t kSignalsBudget = size_t(8) << 20;

// Freed memory goes back to the system on long clips: glibc keeps the scattered pages of many
// small vectors (each channel's keys, reallocated every round), and the phases after the
// rounds would add their peak on top (memory is a target: bench_codec's
// peak_rss_over_bvh_bytes; `keyanim encode` on 11,008 frames peaks at 25.5 MB with the trim,
// 33.1 MB without). On short clips there is little to return and returning it costs more than
// it saves: the pages come back as faults in the phases after (writing, or the next clip's
// encode). Trimming only from 2^19 values (4 MB of motion; CMU 01_01 has 264,192): encode and
// write_kanim on one thread, median CPU time of 15 in one process, Bandai walk_normal_001 15.1
// -> 13.3 ms, run_normal_001 2.8 -> 2.2 ms, CMU 01_01 229 -> 203 ms, for 1.5 MB more peak
// memory on 01_01 (12.0 -> 13.5 MB).
constexpr size_t kTrimFromValues = size_t(1) << 19;
void release_free_memory(const Motion& m) {
#if defined(__GLIBC__)
  if (m.values.size() >= kTrimFromValues) malloc_trim(0);
#else
  (void)m;
#endif
}

// settings.progress, if any, with `done` of `total`.
void report(const EncodeSettings& s, EncodeStage stage, size_t done, size_t total) {
  if (s.progress) s.progress(stage, total ? double(done) / double(total) : 1.0);
}

ChannelFitOptions fit_options(const EncodeSettings& s) {
  ChannelFitOptions o;
  o.rule = s.tangent_rule;
  o.fit_tension = s.fit_tension;
  o.tension = s.tension;
  o.allow_linear = s.allow_linear && s.key_mode == KeyMode::error;
  o.force_linear = s.force_linear;
  return o;
}

// What one encode needs across its rounds.
struct Job {
  const Motion& m;
  const EncodeSettings& settings;
  double tol_units;
  double shell;  // file units
  unsigned threads;
  std::vector<uint32_t> fixed_keys;  // uniform and manual modes
  ChannelLayout layout;
  EncodedClip& enc;
  QuatForms quats;  // enc.quat_nodes, for FK of the stored values
};

// The fitters of an encode: one per channel, and one per quaternion node (its three channels'
// ChannelFitters are not used).
struct Fitters {
  std::vector<ChannelFitter> channel;
  std::vector<QuatFitter> quat;
};

struct FitWorker {
  FitScratch fit;
  std::vector<uint32_t> changed;
};

// One unit of a round's fit: channel c, or the quaternion node whose x channel is c (its three
// channels, fitted together on shared keys). Returns the frame ranges whose values changed
// (round > 0) in `ranges`.
void fit_unit(const Job& job, uint32_t round, const Budgets& budgets, Fitters& fitters, const Signals& signals,
              uint32_t c, FitWorker& s, std::vector<std::pair<uint32_t, uint32_t>>& ranges) {
  const Motion& m = job.m;
  const ChannelFitOptions options = fit_options(job.settings);
  const bool quat = job.layout.stored[c] == internal::Stored::quat_x;
  // A channel's step is held (Budgets::step) in the rounds before kStepHoldRounds.
  const EncodedChannel& last = job.enc.channels[c];
  const bool hold = round > 0 && round < kStepHoldRounds && last.frames.size() >= 2;
  const double fraction = quat ? kQuatStepFraction * kRadPerDeg * kQuatBudgetScale : kStepFraction;
  const double step = budgets.step(c, fraction, hold ? last.step : 0.0);
  if (round > 0 && job.settings.key_mode == KeyMode::error) budgets.changed_frames(c, s.changed);
  const bool error = job.settings.key_mode == KeyMode::error;
  auto keys_of = [&](const std::vector<double>& y) {
    return job.settings.key_mode == KeyMode::curvature ? curvature_keys(y) : job.fixed_keys;
  };
  auto store = [&](uint32_t at, EncodedChannel&& ch) {
    if (round > 0) {
      std::vector<std::pair<uint32_t, uint32_t>> r;
      changed_ranges(job.enc.channels[at], ch, m.frame_count, r);
      ranges.insert(ranges.end(), r.begin(), r.end());
    }
    job.enc.channels[at] = std::move(ch);
  };
  if (!quat) {
    signals.get(m, job.layout, c, s.fit.y);
    const Tolerance tol = budgets.tolerance(c);
    ChannelFitter& fitter = fitters.channel[c];
    if (!error) return store(c, fit_channel_at_keys(s.fit.y, keys_of(s.fit.y), tol, step, options, s.fit));
    if (round == 0 || !fitter.holds(tol, step, s.changed, s.fit.y.data()))
      store(c, fitter.fit(tol, step, round > 0 ? &s.changed : nullptr, s.fit));  // else it still holds
    return;
  }
  // A quaternion node: its rotation channels' budget (degrees, the same for the three) as the
  // chord of an angle in radians.
  const uint32_t q = job.layout.quat_of[c];
  signals.get_quat(m, job.layout, q, s.fit.q);
  const Tolerance degrees = budgets.tolerance(c);
  const Tolerance tol = chord_tolerance({degrees.base * kRadPerDeg * kQuatBudgetScale, degrees.factor});
  std::array<EncodedChannel, 3> fitted;
  if (!error) {
    std::vector<uint32_t> keys = keys_of(s.fit.q[0]);
    if (job.settings.key_mode == KeyMode::curvature) {  // where any of the three turns
      for (size_t k = 1; k < 3; ++k) {
        const std::vector<uint32_t> more = keys_of(s.fit.q[k]);
        keys.insert(keys.end(), more.begin(), more.end());
      }
      std::sort(keys.begin(), keys.end());
      keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    }
    fitted = fit_quat_at_keys(keys, tol, step, options, s.fit);
  } else {
    QuatFitter& fitter = fitters.quat[q];
    if (round > 0 && fitter.holds(tol, step, s.changed, s.fit.signals<QuatCurve>())) return;
    fitted = fitter.fit(tol, step, round > 0 ? &s.changed : nullptr, s.fit);
  }
  for (uint32_t k = 0; k < 3; ++k) store(c + k, std::move(fitted[k]));
}

// Fits the channels whose budgets changed (all of them in round 0) and marks the frames whose
// decoded values may have changed. A quaternion node's three channels are one unit (its x's).
void fit_channels(const Job& job, uint32_t round, Budgets& budgets, Fitters& fitters, FrameMarks& marks,
                  const Signals& signals) {
  std::vector<uint32_t> refit = budgets.take_dirty();
  for (uint32_t& c : refit)  // y and z are tightened with x: their unit is x's
    c -= job.layout.stored[c] == internal::Stored::quat_y ? 1 : job.layout.stored[c] == internal::Stored::quat_z ? 2 : 0;
  refit.erase(std::unique(refit.begin(), refit.end()), refit.end());
  std::vector<FitWorker> workers(parallel_workers(refit.size(), job.threads));
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> ranges(refit.size());
  std::atomic<size_t> done{0};  // counted by every worker, reported by worker 0 (the caller's thread)
  // Units are fitted independently: the result does not depend on the threads.
  parallel_for(refit.size(), job.threads, [&](size_t i, unsigned w) {
    fit_unit(job, round, budgets, fitters, signals, refit[i], workers[w], ranges[i]);
    const size_t d = ++done;
    if (w == 0) report(job.settings, EncodeStage::fitting, d, refit.size());
  });
  report(job.settings, EncodeStage::fitting, 1, 1);
  for (size_t i = 0; i < refit.size(); ++i)
    for (const auto& [a, b] : ranges[i]) marks.mark(job.layout.node[refit[i]], a, b);
}

// Tightens, frame after frame, each channel that moves an over-budget node at that frame by
// the largest ratio any of its nodes needs. True if there was any.
bool tighten_over(const Job& job, uint32_t round, Budgets& budgets, const std::vector<std::vector<OverNode>>& over) {
  bool any = false;
  std::vector<NodeRatio> at_frame;
  for (const std::vector<OverNode>& list : over) {
    for (size_t i = 0; i < list.size();) {
      const uint32_t f = list[i].frame;
      at_frame.clear();
      for (; i < list.size() && list[i].frame == f; ++i)
        at_frame.push_back({list[i].node, tighten_margin(round) * job.tol_units / list[i].error, list[i].shell != 0});
      budgets.tighten(f, at_frame);
      any = true;
    }
  }
  return any;
}

// Verifies the marked frames; tightens budgets where a node is over. False if none is.
// Windows are verified in batches, each batch's overs applied (in frame order) before the
// next: the first rounds find most nodes of most frames over, and holding every window's list
// at once was a fifth of the peak memory on long clips. Verification reads only the channels
// and the marks, never the budgets, so the result is that of one batch.
bool verify_and_tighten(const Job& job, uint32_t round, Budgets& budgets, FrameMarks& marks,
                        const OriginalPoints& originals) {
  const uint32_t frames = job.m.frame_count;
  const size_t windows = (size_t(frames) + kVerifyWindow - 1) / kVerifyWindow;
  const size_t batch = std::min(windows, kVerifyBatch);
  std::vector<std::vector<OverNode>> over(batch);
  std::vector<VerifyScratch> scratch(parallel_workers(batch, job.threads));
  std::atomic<size_t> done{0};  // as in fit_channels
  bool any = false;
  for (size_t first_window = 0; first_window < windows; first_window += batch) {
    const size_t count = std::min(batch, windows - first_window);
    parallel_for(count, job.threads, [&](size_t i, unsigned t) {
      const uint32_t first = uint32_t((first_window + i) * kVerifyWindow);
      over[i].clear();
      verify_window(job.m, job.enc.channels, job.enc.tangent_rule, job.tol_units, job.shell, first,
                    std::min(kVerifyWindow, frames - first), marks, over[i], scratch[t], &originals,
                    job.quats.empty() ? nullptr : &job.quats);
      const size_t d = ++done;
      if (t == 0) report(job.settings, EncodeStage::verifying, d, windows);
    });
    over.resize(count);
    any |= tighten_over(job, round, budgets, over);
  }
  report(job.settings, EncodeStage::verifying, 1, 1);
  marks.clear_moved();
  return any;
}

// Fits every channel; in error mode, rounds of verification and tightening until every node is
// within the tolerance. Returns the number of rounds; throws Error (limit) if that never comes.
uint32_t fit_within_tolerance(const Job& job) {
  const Motion& m = job.m;
  Budgets budgets(m.skeleton, base_tolerances(m, job.tol_units, job.shell), m.frame_count);
  Fitters fitters{std::vector<ChannelFitter>(m.channel_count(), ChannelFitter(fit_options(job.settings))),
                  std::vector<QuatFitter>(job.enc.quat_nodes.size(), QuatFitter(fit_options(job.settings)))};
  FrameMarks marks(m.frame_count, m.skeleton.joints.size());
  marks.mark_all();
  const bool rounds = job.settings.key_mode == KeyMode::error;
  const OriginalPoints originals = rounds ? OriginalPoints(m, job.shell, kOriginalPointsBudget, job.threads)
                                          : OriginalPoints();
  const Signals signals = rounds ? Signals(m, job.layout, kSignalsBudget, job.threads) : Signals();
  for (uint32_t round = 0;; ++round) {
    fit_channels(job, round, budgets, fitters, marks, signals);
    if (!rounds || m.frame_count == 0) return round + 1;
    if (!verify_and_tighten(job, round, budgets, marks, originals)) return round + 1;
    if (round + 1 >= kMaxRounds)
      throw Error(ErrorKind::limit, "could not reach the tolerance of " + general_text(job.tol_units) +
                                        " units after " + std::to_string(kMaxRounds) +
                                        " rounds (below float32 precision?)");
  }
}

}  // namespace

void EncodeSettings::validate() const {
  auto invalid = [](const char* why) { throw Error(ErrorKind::invalid_argument, why); };
  if (!(tolerance > 0.0) || !std::isfinite(tolerance)) invalid("tolerance must be a positive number");
  if (tolerance_in_percent && tolerance > 100.0) invalid("tolerance in percent must be at most 100");
  if (!(shell >= 0.0) || !std::isfinite(shell)) invalid("shell distance must be a number >= 0");
  if (shell_in_percent && shell > 100.0) invalid("shell distance in percent must be at most 100");
  if (uniform_interval < 1) invalid("uniform interval must be at least 1");
  if (!(tension >= -1.0f && tension <= 1.0f)) invalid("tension must be in [-1, 1]");
  if (zstd_level && (*zstd_level < 1 || *zstd_level > 22)) invalid("zstd level must be in 1..22");
  if (key_mode == KeyMode::manual && manual_frames.empty()) invalid("manual key mode needs a list of frames");
}

namespace {

// A motion without channels: every frame is the skeleton's rest pose, in the motion and in any
// decode, so one frame holds all there is to fit and to measure. Encoded as one frame, then
// given its frame count back: the work follows the input's size, not the count a small file
// may declare (13 KB of BVH can declare 2^24 frames), and the bytes are what encoding every
// frame gives (the same keys, none; the same error, 0 at frame 0; the same notes).
EncodeResult encode_still(const Motion& m, const EncodeSettings& settings) {
  if (!m.values.empty())
    throw Error(ErrorKind::invalid_argument,
                "motion has " + std::to_string(m.values.size()) + " values, expected frames x channels");
  EncodeSettings one_frame = settings;
  if (settings.key_mode == KeyMode::manual) {
    manual_keys(settings.manual_frames, m.frame_count);  // refused as for the whole motion
    one_frame.manual_frames = {0};
  }
  Motion still;
  still.skeleton = m.skeleton;
  still.frame_count = 1;
  still.frame_time = m.frame_time;
  EncodeResult r = encode(still, one_frame);
  r.clip.frame_count = m.frame_count;
  r.clip.notes = encoder_notes(settings, r.tolerance_units, m.skeleton, r.error, r.iterations);
  try {
    validate_encoded_clip(r.clip);  // e.g. a frame time of 0 with several frames
  } catch (const Error& e) {
    throw Error(ErrorKind::malformed, "cannot be stored: " + e.message());
  }
  return r;
}

}  // namespace

EncodeResult encode(const Motion& m, const EncodeSettings& settings) {
  settings.validate();
  if (m.channel_count() == 0 && m.frame_count > 1) return encode_still(m, settings);
  const unsigned threads = resolve_threads(settings.threads);
  check_motion(m, threads);
  // Tolerance in file units. A skeleton with no extent (a lone root) falls back to its path.
  const double size = reference_size(m);
  const double tol_units = settings.tolerance_in_percent ? settings.tolerance / 100.0 * size : settings.tolerance;
  if (!(tol_units > 0.0))
    throw Error(ErrorKind::invalid_argument,
                "the skeleton has no extent, so a tolerance in percent means nothing: give it in file units");
  const double shell = settings.shell_in_percent ? settings.shell / 100.0 * size : settings.shell;
  EncodeResult out;
  EncodedClip& enc = out.clip;
  enc.skeleton = m.skeleton;
  enc.frame_count = m.frame_count;
  enc.frame_time = m.frame_time;
  enc.tangent_rule = settings.tangent_rule;
  enc.channels.resize(m.channel_count());
  if (settings.rotations == Rotations::quaternion) enc.quat_nodes = choose_quat_nodes(m);
  Job job{m, settings, tol_units, shell, threads, {}, channel_layout(m.skeleton, enc.quat_nodes), enc,
          QuatForms(m.skeleton, enc.quat_nodes)};
  if (settings.key_mode == KeyMode::uniform) job.fixed_keys = uniform_keys(m.frame_count, settings.uniform_interval);
  if (settings.key_mode == KeyMode::manual) job.fixed_keys = manual_keys(settings.manual_frames, m.frame_count);
  const uint32_t rounds = fit_within_tolerance(job);
  release_free_memory(m);  // the rounds' budgets and fits, before the measurement takes its own

  // A clip the container cannot store (a frame time of 0 with several frames, a value whose
  // quantized integer overflows in the fixed-key modes) is an error, not a result.
  try {
    validate_encoded_clip(enc);
  } catch (const Error& e) {
    throw Error(ErrorKind::malformed, "cannot be stored: " + e.message());
  }
  report(settings, EncodeStage::measuring, 0, 1);
  out.error = measure_encoded(m, enc, shell, threads);
  report(settings, EncodeStage::measuring, 1, 1);
  out.tolerance_units = tol_units;
  out.shell_units = shell;
  out.iterations = rounds;
  out.total_keys = 0;
  for (const EncodedChannel& ch : enc.channels) out.total_keys += ch.frames.size();
  enc.notes = encoder_notes(settings, tol_units, m.skeleton, out.error, out.iterations);
  release_free_memory(m);  // the measurement's clip, before the caller writes the file
  return out;
}

}  // namespace keyanim::offline
