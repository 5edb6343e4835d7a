// The codec core. Per channel: unwrap, choose keys, fit tension, quantize. In error mode the
// world-space tolerance is turned into per-channel, per-frame budgets through the hierarchy,
// and the result is verified by forward kinematics on exactly what a decoder reproduces
// (to_clip + Clip::sample); budgets are tightened only at the frames and channels where a joint
// is over, until every joint and End Site is within the tolerance.
#include "keyanim/offline/encode.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numbers>
#include <sstream>
#include <thread>

#include "keyanim/offline/container.h"
#include "keyanim/offline/curvature.h"
#include "keyanim/offline/fk.h"
#include "keyanim/offline/keyframes.h"
#include "keyanim/version.h"
#include "offline/channel_fit.h"

namespace keyanim::offline {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;
// First guess of the share of the world budget one channel may use: all of it. Errors of the
// channels along a chain rarely peak on the same frame, so this beats any safe split (measured:
// 0.5 costs 2-8% more bytes on CMU clips); verification tightens where it is wrong.
constexpr double kInitialShare = 1.0;
// Rotation error of a joint with nothing measurable below it is budgeted as if a point sat this
// far from it (fraction of the skeleton size; ACL uses a 3 cm shell, about 2% of a human).
constexpr double kShellFraction = 0.02;
// Quantization step as a fraction of the channel's smallest per-frame tolerance (a key is then
// off by at most 0.75 of it). Errors are checked after quantization, so a coarse step costs
// only a few extra keys; measured on four CMU clips, 1.5 is 2.8% smaller than 1.0 at 0.05% of
// the skeleton size (1.25: 0.6%, 1.75: 2.4%, 2.0: 1.8%).
constexpr double kStepFraction = 1.5;
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

// Length of a node's local translation: OFFSET, or its position channels (largest over frames).
double local_translation_length(const Motion& m, uint32_t node) {
  const Joint& j = m.skeleton.joints[node];
  bool has_position = false;
  for (ChannelType t : j.channels) has_position |= !is_rotation(t);
  if (!has_position) return std::hypot(j.offset[0], j.offset[1], j.offset[2]);
  double best = 0.0;
  for (uint32_t f = 0; f < m.frame_count; ++f) {
    std::array<double, 3> t = j.offset;
    for (size_t k = 0; k < j.channels.size(); ++k)
      if (!is_rotation(j.channels[k])) t[channel_axis(j.channels[k])] = m.value(f, j.first_channel + uint32_t(k));
    best = std::max(best, std::hypot(t[0], t[1], t[2]));
  }
  return best;
}

// For every node, the longest path (sum of translation lengths) to any descendant.
std::vector<double> reach_below(const Motion& m) {
  const auto& joints = m.skeleton.joints;
  std::vector<double> len(joints.size()), down(joints.size(), 0.0);
  for (uint32_t i = 0; i < joints.size(); ++i) len[i] = local_translation_length(m, i);
  for (size_t i = joints.size(); i-- > 0;) {  // children come after parents
    const int32_t p = joints[i].parent;
    if (p >= 0) down[size_t(p)] = std::max(down[size_t(p)], len[i] + down[i]);
  }
  return down;
}

// Channels whose error moves node d: translations of d and its ancestors, rotations of its
// strict ancestors.
std::vector<std::vector<uint32_t>> channels_moving_node(const Skeleton& s) {
  std::vector<std::vector<uint32_t>> out(s.joints.size());
  for (uint32_t d = 0; d < s.joints.size(); ++d) {
    for (int32_t a = int32_t(d); a >= 0; a = s.joints[size_t(a)].parent) {
      const Joint& j = s.joints[size_t(a)];
      for (size_t k = 0; k < j.channels.size(); ++k)
        if (!is_rotation(j.channels[k]) || a != int32_t(d)) out[d].push_back(j.first_channel + uint32_t(k));
    }
  }
  return out;
}

// Decodes the clip at every source frame with the runtime sampler, as double values.
void decode_all(const Clip& clip, Motion& out) {
  const uint32_t n = clip.channel_count();
  out.values.assign(size_t(clip.frame_count()) * n, 0.0);
  std::vector<float> row(n);
  Cursor cursor;
  if (cursor.prepare(clip) != Status::ok) throw std::bad_alloc();
  for (uint32_t f = 0; f < clip.frame_count(); ++f) {
    clip.sample(double(f), row, &cursor);
    for (uint32_t c = 0; c < n; ++c) out.values[size_t(f) * n + c] = row[c];
  }
}

// One channel at every source frame, walking the segments in order: the values Clip::sample
// gives for the channel once stored (to_clip's dequantization, eval_segment's operations),
// without building a Clip or searching per frame.
void decode_channel(const EncodedChannel& ch, TangentRule rule, std::vector<float>& out, std::vector<float>& v) {
  const uint32_t* k = ch.frames.data();
  const uint32_t n = uint32_t(ch.frames.size());
  const uint32_t frames = uint32_t(out.size());
  if (n == 0) return std::fill(out.begin(), out.end(), 0.0f);
  v.resize(n);
  for (uint32_t i = 0; i < n; ++i) v[i] = dequantize(ch.q[i], ch.step);
  const float s = tension_to_s(ch.tension);
  uint32_t j = 0;
  SegmentOperands ops;
  for (uint32_t f = 0; f < frames; ++f) {
    if (n == 1 || f <= k[0]) { out[f] = v[0]; continue; }
    if (f >= k[n - 1]) { out[f] = v[n - 1]; continue; }
    if (k[j + 1] <= f || f == k[0] + 1) {  // a new segment, or the first one
      while (k[j + 1] <= f) ++j;
      ops = segment_operands(k, v.data(), n, j, ch.interp, s, rule);
    }
    out[f] = f == k[j] ? v[j] : eval_operands(ops, segment_u(k[j], k[j + 1], float(f)));
  }
}

std::string describe(const EncodeSettings& s, double tol_units, const ErrorReport& e, uint32_t rounds) {
  std::ostringstream o;
  static const char* kModes[] = {"error", "uniform", "manual", "curvature"};
  o << "encoder=keyanim " << KEYANIM_VERSION_STRING << "\n"
    << "keys=" << kModes[int(s.key_mode)] << "\n"
    << "tolerance=" << s.tolerance << (s.tolerance_in_percent ? "%" : "") << "\n"
    << "tolerance_units=" << tol_units << "\n"
    << "tension=" << (s.fit_tension ? std::string("fit") : std::to_string(s.tension)) << "\n"
    << "tangent_rule=" << (s.tangent_rule == TangentRule::step_adjusted ? "step_adjusted" : "uniform") << "\n"
    << "max_error=" << e.max_error << "\n"
    << "rms_error=" << e.rms_error << "\n"
    << "rounds=" << rounds << "\n";
  return o.str();
}

}  // namespace

double reference_size(const Motion& m) {
  const double size = skeleton_size(m.skeleton);
  if (size > 0.0) return size;
  Vec3 lo{HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  std::vector<Vec3> pos;
  for (uint32_t f = 0; f < m.frame_count; ++f) {
    world_positions(m.skeleton, m.frame(f), pos);
    for (const Vec3& p : pos)
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  }
  return m.frame_count ? std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]}) : 0.0;
}

std::string EncodeSettings::validate() const {
  if (!(tolerance > 0.0) || !std::isfinite(tolerance)) return "tolerance must be a positive number";
  if (tolerance_in_percent && tolerance > 100.0) return "tolerance in percent must be at most 100";
  if (uniform_interval < 1) return "uniform interval must be at least 1";
  if (!(tension >= -1.0f && tension <= 1.0f)) return "tension must be in [-1, 1]";
  if (zstd_level < 1 || zstd_level > 22) return "zstd level must be in 1..22";
  if (key_mode == KeyMode::manual && manual_frames.empty()) return "manual key mode needs a list of frames";
  return {};
}

void unwrap_degrees(std::vector<double>& y) {
  for (size_t f = 1; f < y.size(); ++f) {
    const double d = y[f] - y[f - 1];
    y[f] = y[f - 1] + d - 360.0 * std::round(d / 360.0);
  }
}

bool encode(const Motion& m, const EncodeSettings& settings, EncodeResult& out, std::string& error) {
  error = settings.validate();
  if (!error.empty()) return false;
  const uint32_t n_ch = m.channel_count();
  const uint32_t n_fr = m.frame_count;
  if (m.values.size() != size_t(n_ch) * n_fr) {
    error = "motion has " + std::to_string(m.values.size()) + " values, expected frames x channels";
    return false;
  }

  // Tolerance in file units. A skeleton with no extent (a lone root) falls back to its path.
  const std::vector<Vec3> orig_pos = world_positions_all(m);
  const size_t n_nodes = m.skeleton.joints.size();
  // Keys are binary32 at runtime: a value (or a position) beyond its range cannot play back.
  constexpr double kMaxMagnitude = 1e37;
  for (double v : m.values) {
    if (!(std::fabs(v) <= kMaxMagnitude)) {
      error = "a channel value is beyond what binary32 keys can hold (|v| > 1e37)";
      return false;
    }
  }
  for (const Vec3& p : orig_pos) {
    if (!(std::fabs(p[0]) <= kMaxMagnitude && std::fabs(p[1]) <= kMaxMagnitude && std::fabs(p[2]) <= kMaxMagnitude)) {
      error = "joint positions overflow (beyond 1e37 in file units)";
      return false;
    }
  }
  const double size = reference_size(m);
  const double tol_units = settings.tolerance_in_percent ? settings.tolerance / 100.0 * size : settings.tolerance;
  if (!(tol_units > 0.0)) {
    error = "the skeleton has no extent, so a tolerance in percent means nothing: give it in file units";
    return false;
  }

  // Signals, unwrapped where they are angles.
  std::vector<std::vector<double>> sig(n_ch);
  std::vector<bool> rot(n_ch);
  for (uint32_t c = 0; c < n_ch; ++c) {
    sig[c] = m.channel(c);
    const uint32_t j = m.skeleton.joint_of_channel(c);
    rot[c] = is_rotation(m.skeleton.joints[j].channels[c - m.skeleton.joints[j].first_channel]);
    if (rot[c]) unwrap_degrees(sig[c]);
  }

  // Per-channel base tolerance: the world budget divided by how far the channel's error travels.
  const std::vector<double> down = reach_below(m);
  const double shell = kShellFraction * size;
  std::vector<double> base_tol(n_ch);
  for (uint32_t c = 0; c < n_ch; ++c) {
    const uint32_t j = m.skeleton.joint_of_channel(c);
    base_tol[c] = rot[c] ? kInitialShare * tol_units / std::max(down[j], shell) * kDegPerRad
                         : kInitialShare * tol_units;
  }

  ChannelFitOptions fit_opt;
  fit_opt.rule = settings.tangent_rule;
  fit_opt.fit_tension = settings.fit_tension;
  fit_opt.tension = settings.tension;
  fit_opt.allow_linear = settings.allow_linear && settings.key_mode == KeyMode::error;
  fit_opt.force_linear = settings.force_linear;

  // Fixed key lists for the modes that do not look at the error.
  std::vector<uint32_t> fixed_keys;
  if (settings.key_mode == KeyMode::uniform) fixed_keys = uniform_keys(n_fr, settings.uniform_interval);
  if (settings.key_mode == KeyMode::manual && !manual_keys(settings.manual_frames, n_fr, fixed_keys, error))
    return false;

  EncodedClip& enc = out.clip;
  enc = EncodedClip{};
  enc.skeleton = m.skeleton;
  enc.frame_count = n_fr;
  enc.frame_time = m.frame_time;
  enc.tangent_rule = settings.tangent_rule;
  enc.channels.resize(n_ch);

  std::vector<std::vector<double>> tol(n_ch);
  for (uint32_t c = 0; c < n_ch; ++c) tol[c].assign(n_fr, base_tol[c]);
  std::vector<bool> dirty(n_ch, true);
  std::vector<std::vector<uint32_t>> changed(n_ch);  // frames whose tolerance just changed
  std::vector<ChannelFitter> fitters;
  fitters.reserve(n_ch);
  for (uint32_t c = 0; c < n_ch; ++c) fitters.emplace_back(sig[c], fit_opt);
  const auto moving = channels_moving_node(m.skeleton);

  Motion decoded;
  decoded.skeleton = m.skeleton;
  decoded.frame_count = n_fr;
  decoded.frame_time = m.frame_time;
  decoded.values.assign(size_t(n_fr) * n_ch, 0.0);
  // Trigonometry of the decoded rotations, redone only where a value changes (FK's main cost).
  std::vector<double> sines(decoded.values.size()), cosines(decoded.values.size());
  std::vector<Vec3> pos;
  std::vector<uint8_t> check(n_fr, 1);  // frames to verify: values changed, or over last round
  std::vector<uint32_t> refit;
  const double surely_within = tol_units * tol_units * (1.0 - 1e-9);
  std::vector<double> ratio(n_ch, 1.0);  // per channel, the tightening the current frame needs
  std::vector<uint32_t> touched;         // channels with ratio < 1 at the current frame
  const uint32_t threads = settings.threads ? settings.threads : std::max(1u, std::thread::hardware_concurrency());
  uint32_t round = 0;
  for (;; ++round) {
    refit.clear();
    for (uint32_t c = 0; c < n_ch; ++c)
      if (dirty[c]) refit.push_back(c), dirty[c] = false;
    // Channels are fitted independently: spread them over threads (the result does not depend
    // on how).
    std::atomic<size_t> next{0};
    auto fit_some = [&] {
      for (size_t i; (i = next.fetch_add(1)) < refit.size();) {
        const uint32_t c = refit[i];
        // The step halves (rather than follows the smallest tolerance) so that tightening a few
        // frames rarely requantizes the whole channel.
        const double min_tol = n_fr ? *std::min_element(tol[c].begin(), tol[c].end()) : base_tol[c];
        double step = kStepFraction * base_tol[c];
        while (step > kStepFraction * min_tol) step *= 0.5;
        switch (settings.key_mode) {
          case KeyMode::error: enc.channels[c] = fitters[c].fit(tol[c], step, round ? &changed[c] : nullptr); break;
          case KeyMode::curvature: enc.channels[c] = fit_channel_at_keys(sig[c], curvature_keys(sig[c]), tol[c], step, fit_opt); break;
          default: enc.channels[c] = fit_channel_at_keys(sig[c], fixed_keys, tol[c], step, fit_opt); break;
        }
      }
    };
    std::vector<std::thread> pool;
    for (uint32_t t = 1; t < std::min<size_t>(threads, refit.size()); ++t) pool.emplace_back(fit_some);
    fit_some();
    for (std::thread& t : pool) t.join();
    if (settings.key_mode != KeyMode::error || n_fr == 0) break;

    // Verify by FK on what the decoder produces, on the frames whose values changed (and those
    // still over budget). Where a node is over budget, every channel that moves it is tightened
    // at that frame by the ratio it is over (plus a margin).
    std::vector<float> column(n_fr), key_values;
    for (uint32_t c : refit) {
      decode_channel(enc.channels[c], enc.tangent_rule, column, key_values);
      for (uint32_t f = 0; f < n_fr; ++f) {
        const size_t at = size_t(f) * n_ch + c;
        double& old = decoded.values[at];
        if (column[f] != old || round == 0) {
          old = column[f], check[f] = 1;
          if (rot[c]) sin_cos_deg(old, sines[at], cosines[at]);
        }
      }
    }
    // Each channel that moves an over-budget node is tightened at that frame by the largest
    // ratio any of its nodes needs. Frames come in order, so each channel's changed frames do too.
    bool over = false;
    for (uint32_t f = 0; f < n_fr; ++f) {
      if (!check[f]) continue;
      check[f] = 0;
      const size_t row = size_t(f) * n_ch;
      world_positions(m.skeleton, decoded.values.data() + row, sines.data() + row, cosines.data() + row, pos);
      for (size_t d = 0; d < n_nodes; ++d) {
        const Vec3& a = orig_pos[f * n_nodes + d];
        // The formula of measure_error, so that what passes here passes the final report; the
        // square is compared first against a bound safely inside it (sqrt is correctly rounded).
        const double dx = pos[d][0] - a[0], dy = pos[d][1] - a[1], dz = pos[d][2] - a[2];
        const double sq = dx * dx + dy * dy + dz * dz;
        if (sq <= surely_within) continue;
        const double e = std::sqrt(sq);
        if (e <= tol_units) continue;
        over = true;
        check[f] = 1;
        const double r = tighten_margin(round) * tol_units / e;  // < 1
        for (uint32_t c : moving[d]) {
          if (ratio[c] == 1.0) touched.push_back(c);
          ratio[c] = std::min(ratio[c], r);
        }
      }
      for (uint32_t c : touched) {
        if (!dirty[c]) changed[c].clear(), dirty[c] = true;  // first tightening of this round
        tol[c][f] *= ratio[c];
        changed[c].push_back(f);
        ratio[c] = 1.0;
      }
      touched.clear();
    }
    if (!over) break;
    if (round + 1 >= kMaxRounds) {
      error = "could not reach the tolerance of " + std::to_string(tol_units) +
              " units after " + std::to_string(kMaxRounds) + " rounds (below float32 precision?)";
      return false;
    }
  }

  // A clip the container cannot store (a frame time of 0 with several frames, a value whose
  // quantized integer overflows in the fixed-key modes) is an error, not a result.
  if (std::string why = validate_encoded_clip(enc); !why.empty()) {
    error = "cannot be stored: " + why;
    return false;
  }
  decode_all(to_clip(enc), decoded);
  out.error = measure_error(m, decoded);
  out.tolerance_units = tol_units;
  out.iterations = round + 1;
  out.total_keys = 0;
  for (const EncodedChannel& ch : enc.channels) out.total_keys += ch.frames.size();
  enc.notes = describe(settings, tol_units, out.error, out.iterations);
  return true;
}

}  // namespace keyanim::offline
