// Issue 22's lever "rotations as quaternion curves" and "key times shared per joint", measured
// before anyone builds it.
//
//   probe_rotation_curves [--json] [--clip NAME] [--corpus DIR] [--threads N]
//
// For every clip of the corpus groups CMU 120 fps (cmu/) and Bandai 30 fps (bandai/), chosen as
// bench_vs_acl chooses them, at the encoder's defaults (0.05% of the skeleton size, shell 2%):
//  1. Euler, one round: every rotation channel fitted once by the encoder's own ChannelFitter at
//     its base budget (base_tolerances, factor 1 at every frame, the step of round 0). Per joint,
//     the largest angle over frames between its original local rotation and the one rebuilt
//     from the fitted channels (FORMAT Appendix B: intrinsic, R = R1 R2 R3).
//  2. Quaternion, one round: each joint's local rotation as a unit quaternion per frame, made
//     sign-continuous, its 4 components fitted as channels by the same fitter with one tolerance
//     t (and the step the encoder derives from a budget t). q' is rebuilt from the 4 curves and
//     normalized. t is bisected per joint so that the quaternion fit's worst angle is as large
//     as possible without exceeding the Euler fit's worst angle for that joint.
//     The same with w rebuilt (clip.w_rebuilt, joint.quat_w_rebuilt): x, y, z of the w >= 0
//     hemisphere fitted, w = sqrt(max(0, 1 - x^2 - y^2 - z^2)); x, y, z jump where the
//     continuous w crosses 0 (w_crossing_joints counts the joints that ever do).
//  3. Keys (sum over channels), key times shared per joint (distinct key frames over a joint's
//     rotation channels), and as the reference what offline::encode ships for the rotation
//     channels at the same settings (its world-space rounds tighten the budgets).
// Key counts are a proxy for bytes, not bytes: a key's value bits depend on its channel's step,
// and a quaternion component's step comes from t, an Euler channel's from its budget in degrees.
// Neither fit is verified in world space here; both are one round, so they compare like with
// like, and encoder_rotation_keys shows how far one round is from what ships.
//
// Checks that stop the probe (exit 1): a clip that does not load; an Euler joint worse than the
// sum of its channels' budgets (each channel is within its budget at every frame, and angles of
// composed rotations add at most); a rebuilt channel off its signal at a key frame by more than
// half its step (plus binary32 rounding); the probe's tolerance or shell differing from encode's.
// Exit codes: 0 done; 1 a clip or a check failed; 2 bad arguments.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <numbers>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "keyanim/cardinal.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/error.h"
#include "keyanim/offline/fk.h"
#include "keyanim/offline/metrics.h"
#include "offline/encode/budget.h"
#include "offline/encode/channel_fit.h"
#include "offline/encode/signals.h"
#include "offline/parallel.h"
#include "corpus_groups.h"

namespace fs = std::filesystem;
namespace ko = keyanim::offline;
using nlohmann::json;
using bench::CorpusClip;
using bench::find_clips;

namespace {

// encode.cpp's kStepFraction and fit_options() (both private to it): the step is the largest
// power of 2^(1/4) within 2x the smallest tolerance, and the fit is Cardinal at tension 0 or
// linear, whichever has fewer keys. Kept equal by hand; a change there must be made here.
constexpr double kStepFraction = 2.0;
ko::ChannelFitOptions default_fit_options() {
  const ko::EncodeSettings s;
  ko::ChannelFitOptions o;
  o.rule = s.tangent_rule;
  o.fit_tension = s.fit_tension;
  o.tension = s.tension;
  o.allow_linear = s.allow_linear;
  o.force_linear = s.force_linear;
  return o;
}
// Bisection steps on t (geometric), after the bracket is found.
constexpr int kBisections = 12;

struct ProbeError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// ---- One channel: fit once, play back as a decoder would.

// The channel's value at every frame, by the decoder's arithmetic (cardinal.h).
std::vector<double> play(const ko::EncodedChannel& ch, uint32_t frames) {
  std::vector<float> v(ch.q.size());
  for (size_t i = 0; i < v.size(); ++i) v[i] = keyanim::dequantize(ch.q[i], ch.step);
  const float s = keyanim::tension_to_s(ch.tension);
  const uint32_t n = uint32_t(v.size());
  std::vector<double> out(frames);
  for (uint32_t f = 0; f < frames; ++f)
    out[f] = keyanim::eval_channel(ch.frames.data(), v.data(), n, float(f), ch.interp, s,
                                   keyanim::TangentRule::step_adjusted);
  return out;
}

// Fitted once from scratch, as round 0 of the encoder fits it: budgets.tolerance(c) and
// budgets.step(c) with nothing held. scratch.y holds the signal.
ko::EncodedChannel fit_once(const ko::Budgets& budgets, uint32_t c, ko::FitScratch& scratch) {
  ko::ChannelFitter fitter(default_fit_options());
  return fitter.fit(budgets.tolerance(c), budgets.step(c, kStepFraction), nullptr, scratch);
}

// A played-back channel must sit on its signal at its key frames within half its step (plus
// the rounding of the key to binary32). A channel of 0 or 1 key is a constant: not checked.
void check_keys(const ko::EncodedChannel& ch, const std::vector<double>& y, const std::vector<double>& played,
                const std::string& what) {
  if (ch.frames.size() < 2) return;
  for (uint32_t f : ch.frames) {
    const double off = std::fabs(played[f] - y[f]);
    if (off > 0.5 * ch.step + 1.2e-7 * std::fabs(y[f]) + 1e-30)
      throw ProbeError(what + ": frame " + std::to_string(f) + " is off its key by " + std::to_string(off) +
                       " (step " + std::to_string(ch.step) + ")");
  }
}

std::vector<uint32_t> union_frames(const std::vector<const ko::EncodedChannel*>& chans) {
  std::vector<uint32_t> all;
  for (const ko::EncodedChannel* c : chans) all.insert(all.end(), c->frames.begin(), c->frames.end());
  std::sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end()), all.end());
  return all;
}

// ---- Rotations

using ko::Quat;

double dot(const Quat& a, const Quat& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]; }

Quat normalized(Quat q) {
  const double n = std::sqrt(dot(q, q));
  for (double& x : q) x /= n;
  return q;
}

// 2 acos(|<a, b>|) for unit a, b, computed as 4 atan2(|a - b|, |a + b|) with b's sign taken
// nearest a: the same angle, without acos' loss of half the digits near 1.
double angle(const Quat& a, const Quat& b) {
  const double sign = dot(a, b) < 0.0 ? -1.0 : 1.0;
  double d = 0.0, s = 0.0;
  for (size_t i = 0; i < 4; ++i) {
    d += (a[i] - sign * b[i]) * (a[i] - sign * b[i]);
    s += (a[i] + sign * b[i]) * (a[i] + sign * b[i]);
  }
  return 4.0 * std::atan2(std::sqrt(d), std::sqrt(s));
}

// A joint of the probe: a node with at least one rotation channel.
struct JointProbe {
  uint32_t node = 0;
  std::vector<uint32_t> rot;  // its rotation channels (frame columns)
  // Euler, one round
  uint64_t euler_keys = 0, euler_union = 0;
  double euler_err = 0.0;     // radians
  double budget_sum = 0.0;    // radians: the sum of its rotation channels' budgets
  // Quaternion, one round, at the chosen t: 4 components (w stored), and 3 (w rebuilt)
  struct Choice {
    uint64_t keys = 0, union_times = 0;
    double err = 0.0, t = 0.0;
    int fits = 0;             // fits tried
    bool matched = true;      // a t with err <= euler_err was found
  } q4, q3;
  bool still = false;         // its rotation is the same at every frame
  bool w_crosses = false;     // the sign-continuous w changes sign
  // The encoder's output
  uint64_t encoder_keys = 0, encoder_union = 0;
};

std::vector<JointProbe> probe_joints(const keyanim::Skeleton& s) {
  std::vector<JointProbe> out;
  for (uint32_t j = 0; j < s.joints.size(); ++j) {
    JointProbe p;
    p.node = j;
    const keyanim::Joint& joint = s.joints[j];
    for (size_t k = 0; k < joint.channels.size(); ++k)
      if (keyanim::is_rotation(joint.channels[k])) p.rot.push_back(joint.first_channel + uint32_t(k));
    if (!p.rot.empty()) out.push_back(std::move(p));
  }
  return out;
}

// Every joint's original local rotation per frame (rot[joint][frame]), sign-continuous.
std::vector<std::vector<Quat>> original_rotations(const ko::Motion& m, const std::vector<JointProbe>& joints) {
  std::vector<std::vector<Quat>> out(joints.size(), std::vector<Quat>(m.frame_count));
  for (size_t i = 0; i < joints.size(); ++i) {
    const keyanim::Joint& joint = m.skeleton.joints[joints[i].node];
    for (uint32_t f = 0; f < m.frame_count; ++f) {
      Quat q = normalized(ko::local_quaternion(joint, m.frame(f)));
      if (f > 0 && dot(q, out[i][f - 1]) < 0.0)
        for (double& x : q) x = -x;
      out[i][f] = q;
    }
  }
  return out;
}

// ---- 1. Euler, one round

// Fits every rotation channel once at its base budget and measures each joint's worst angle.
void euler_round(const ko::Motion& m, const ko::Budgets& budgets, std::vector<JointProbe>& joints,
                 const std::vector<std::vector<Quat>>& orig) {
  const ko::ChannelLayout layout = ko::channel_layout(m.skeleton);
  ko::Motion played = m;  // rotation columns replaced by what a decoder plays
  ko::FitScratch scratch;
  scratch.prepare(m.frame_count);
  const uint32_t stride = m.channel_count();
  for (JointProbe& p : joints) {
    std::vector<ko::EncodedChannel> chans;
    for (uint32_t c : p.rot) {
      ko::channel_signal(m, layout, c, scratch.y);
      chans.push_back(fit_once(budgets, c, scratch));
      const std::vector<double> v = play(chans.back(), m.frame_count);
      check_keys(chans.back(), scratch.y, v, "Euler channel " + std::to_string(c));
      for (uint32_t f = 0; f < m.frame_count; ++f) played.values[size_t(f) * stride + c] = v[f];
      p.euler_keys += chans.back().frames.size();
      p.budget_sum += budgets.tolerance(c).base * std::numbers::pi / 180.0;
    }
    std::vector<const ko::EncodedChannel*> ptrs;
    for (const auto& ch : chans) ptrs.push_back(&ch);
    p.euler_union = union_frames(ptrs).size();
  }
  for (size_t i = 0; i < joints.size(); ++i) {
    const keyanim::Joint& joint = m.skeleton.joints[joints[i].node];
    for (uint32_t f = 0; f < m.frame_count; ++f)
      joints[i].euler_err =
          std::max(joints[i].euler_err, angle(orig[i][f], normalized(ko::local_quaternion(joint, played.frame(f)))));
  }
}

// ---- 2. Quaternion, one round

struct QuatFit {
  uint64_t keys = 0, union_times = 0;
  double err = 0.0;
};

// How a joint's quaternion is stored: 4 sign-continuous components, or x, y, z of the w >= 0
// hemisphere with w rebuilt as sqrt(max(0, 1 - x^2 - y^2 - z^2)) (x, y, z then jump where the
// continuous w crosses 0).
enum class QuatForm { w_stored, w_rebuilt };

// The components of `q` (sign-continuous) in `form` fitted at tolerance t, played back,
// normalized and measured against q.
QuatFit fit_quaternion(const keyanim::Skeleton& s, const std::vector<Quat>& q, QuatForm form, double t,
                       ko::FitScratch& scratch) {
  const uint32_t frames = uint32_t(q.size()), n = form == QuatForm::w_stored ? 4 : 3;
  const ko::Budgets budgets(s, std::vector<double>(n, t), frames);
  std::vector<ko::EncodedChannel> chans(n);
  std::vector<std::vector<double>> played(n);
  QuatFit r;
  std::vector<const ko::EncodedChannel*> ptrs;
  for (uint32_t k = 0; k < n; ++k) {
    for (uint32_t f = 0; f < frames; ++f)
      scratch.y[f] = form == QuatForm::w_rebuilt && q[f][3] < 0.0 ? -q[f][k] : q[f][k];
    chans[k] = fit_once(budgets, k, scratch);
    played[k] = play(chans[k], frames);
    check_keys(chans[k], scratch.y, played[k], "quaternion component " + std::to_string(k));
    r.keys += chans[k].frames.size();
    ptrs.push_back(&chans[k]);
  }
  r.union_times = union_frames(ptrs).size();
  for (uint32_t f = 0; f < frames; ++f) {
    Quat p{played[0][f], played[1][f], played[2][f], 0.0};
    p[3] = n == 4 ? played[3][f] : std::sqrt(std::max(0.0, 1.0 - p[0] * p[0] - p[1] * p[1] - p[2] * p[2]));
    r.err = std::max(r.err, angle(q[f], normalized(p)));
  }
  return r;
}

void keep(JointProbe::Choice& c, const QuatFit& r, double t) {
  c.keys = r.keys, c.union_times = r.union_times, c.err = r.err, c.t = t;
}

// The largest t found whose fit is within the Euler fit's worst angle: a bracket [lo, hi]
// (lo within, hi over), then geometric bisection; the within fit with the largest error is kept.
void match_quaternion(const keyanim::Skeleton& s, const std::vector<Quat>& q, QuatForm form, JointProbe& p,
                      ko::FitScratch& scratch) {
  JointProbe::Choice& c = form == QuatForm::w_stored ? p.q4 : p.q3;
  const double target = p.euler_err;
  auto within = [&](double t) {
    const QuatFit r = fit_quaternion(s, q, form, t, scratch);
    ++c.fits;
    const bool ok = r.err <= target;
    if (ok && (c.t == 0.0 || r.err > c.err)) keep(c, r, t);
    return ok;
  };
  if (p.still || !(target > 0.0)) {
    // Nothing to match: the joint as the fitter takes it, at a quarter of its Euler budget in
    // radians (a component off by t moves the rotation by at most about 4 t).
    const double t = p.budget_sum / 3.0 / 4.0;
    keep(c, fit_quaternion(s, q, form, t, scratch), t);
    c.matched = c.err <= target;
    ++c.fits;
    return;
  }
  double lo = target / 8.0, hi = target;
  while (!within(lo) && lo > target * 1e-6) hi = lo, lo /= 8.0;
  if (c.t == 0.0) {  // never within: keep the finest fit tried, flagged
    keep(c, fit_quaternion(s, q, form, lo, scratch), lo);
    c.matched = false;
    return;
  }
  while (within(hi) && hi < target * 64.0) lo = hi, hi *= 2.0;
  for (int i = 0; i < kBisections; ++i) {
    const double mid = std::sqrt(lo * hi);
    (within(mid) ? lo : hi) = mid;
  }
}

// ---- 3. The encoder's output, for reference

void encoder_reference(const ko::Motion& m, unsigned threads, double tol_units, double shell,
                       std::vector<JointProbe>& joints) {
  ko::EncodeSettings settings;
  settings.threads = threads;
  const ko::EncodeResult r = ko::encode(m, settings);
  if (std::fabs(r.tolerance_units - tol_units) > 1e-12 * tol_units || std::fabs(r.shell_units - shell) > 1e-12 * shell)
    throw ProbeError("the probe's tolerance or shell differs from encode's");
  for (JointProbe& p : joints) {
    std::vector<const ko::EncodedChannel*> ptrs;
    for (uint32_t c : p.rot) ptrs.push_back(&r.clip.channels[c]), p.encoder_keys += r.clip.channels[c].frames.size();
    p.encoder_union = union_frames(ptrs).size();
  }
}

// ---- A clip

json joint_json(const keyanim::Skeleton& s, const JointProbe& p) {
  constexpr double deg = 180.0 / std::numbers::pi;
  auto choice = [&](const JointProbe::Choice& c) {
    return json{{"keys", c.keys}, {"union_times", c.union_times}, {"err_deg", c.err * deg}, {"t", c.t},
                {"fits", c.fits}, {"matched", c.matched}};
  };
  return {{"name", s.joints[p.node].name}, {"euler_keys", p.euler_keys}, {"quat_keys", p.q4.keys},
          {"euler_union_times", p.euler_union}, {"quat_union_times", p.q4.union_times},
          {"encoder_keys", p.encoder_keys}, {"encoder_union_times", p.encoder_union},
          {"euler_err_deg", p.euler_err * deg}, {"budget_sum_deg", p.budget_sum * deg},
          {"quat", choice(p.q4)}, {"quat_w_rebuilt", choice(p.q3)}, {"still", p.still}, {"w_crosses_0", p.w_crosses}};
}

double ratio(uint64_t a, uint64_t b) { return b ? double(a) / double(b) : 0.0; }

json probe_clip(const CorpusClip& c, unsigned threads) {
  const ko::Motion& m = c.motion;
  const auto start = std::chrono::steady_clock::now();
  const double size = ko::reference_size(m);
  const ko::EncodeSettings defaults;
  const double tol_units = defaults.tolerance / 100.0 * size, shell = defaults.shell / 100.0 * size;
  std::vector<JointProbe> joints = probe_joints(m.skeleton);
  const std::vector<std::vector<Quat>> orig = original_rotations(m, joints);
  const ko::Budgets budgets(m.skeleton, ko::base_tolerances(m, tol_units, shell), m.frame_count);
  euler_round(m, budgets, joints, orig);
  for (const JointProbe& p : joints)
    if (p.euler_err > p.budget_sum * (1.0 + 1e-9) + 1e-12)
      throw ProbeError(c.name + ": joint " + m.skeleton.joints[p.node].name + " rebuilt off by " +
                       std::to_string(p.euler_err) + " rad, more than its budgets' sum " + std::to_string(p.budget_sum));
  std::vector<ko::FitScratch> scratch(ko::parallel_workers(joints.size(), threads));
  for (ko::FitScratch& s : scratch) s.prepare(m.frame_count), s.y.resize(m.frame_count);
  ko::parallel_for(joints.size(), threads, [&](size_t i, unsigned w) {
    JointProbe& p = joints[i];
    const std::vector<Quat>& q = orig[i];
    p.still = std::all_of(q.begin(), q.end(), [&](const Quat& x) { return x == q[0]; });
    p.w_crosses = std::any_of(q.begin(), q.end(), [](const Quat& x) { return x[3] < 0.0; }) &&
                  std::any_of(q.begin(), q.end(), [](const Quat& x) { return x[3] > 0.0; });
    match_quaternion(m.skeleton, q, QuatForm::w_stored, p, scratch[w]);
    match_quaternion(m.skeleton, q, QuatForm::w_rebuilt, p, scratch[w]);
  });
  encoder_reference(m, threads, tol_units, shell, joints);

  uint64_t ek = 0, qk = 0, eu = 0, qu = 0, rk = 0, ru = 0, unmatched = 0, still = 0, crossing = 0;
  uint64_t q3k = 0, q3u = 0, unmatched3 = 0;
  json detail = json::array();
  for (const JointProbe& p : joints) {
    ek += p.euler_keys, qk += p.q4.keys, eu += p.euler_union, qu += p.q4.union_times;
    q3k += p.q3.keys, q3u += p.q3.union_times, unmatched3 += !p.q3.matched;
    rk += p.encoder_keys, ru += p.encoder_union;
    unmatched += !p.q4.matched, still += p.still, crossing += p.w_crosses;
    detail.push_back(joint_json(m.skeleton, p));
  }
  const double seconds = double(m.frame_count) * m.frame_time;
  return {{"name", c.name}, {"group", c.group}, {"frames", m.frame_count}, {"seconds", seconds},
          {"joints", joints.size()}, {"tol_units", tol_units}, {"shell_units", shell},
          {"euler_keys", ek}, {"quat_keys", qk}, {"quat_over_euler", ratio(qk, ek)},
          {"euler_union_times", eu}, {"quat_union_times", qu}, {"union_quat_over_euler", ratio(qu, eu)},
          {"encoder_rotation_keys", rk}, {"encoder_over_euler_keys", ratio(rk, ek)},
          {"encoder_rotation_union_times", ru}, {"unmatched_joints", unmatched}, {"still_joints", still},
          {"w_crossing_joints", crossing},
          {"w_rebuilt", {{"quat_keys", q3k}, {"quat_over_euler", ratio(q3k, ek)}, {"quat_union_times", q3u},
                         {"union_quat_over_euler", ratio(q3u, eu)}, {"unmatched_joints", unmatched3}}},
          {"probe_seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()},
          {"joints_detail", detail}};
}

// ---- Groups

json spread(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  const double median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  return {{"median", median}, {"min", v.front()}, {"max", v.back()}};
}

// Per group: median, min and max over clips of each ratio (for the quaternion ratios the worst
// is the max); keys per joint per second pooled over the group (sum of keys / sum of joint
// seconds).
json summarize(const json& clips) {
  json groups = json::object();
  for (const char* g : {"cmu120", "bandai30"}) {
    std::vector<double> qe, ue, re, q3e, u3e;
    double joint_seconds = 0;
    uint64_t ek = 0, qk = 0, eu = 0, qu = 0, rk = 0, unmatched = 0, crossing = 0, joints = 0;
    uint64_t q3k = 0, unmatched3 = 0;
    for (const json& c : clips) {
      if (c["group"] != g) continue;
      qe.push_back(c["quat_over_euler"]), ue.push_back(c["union_quat_over_euler"]);
      re.push_back(c["encoder_over_euler_keys"]);
      q3e.push_back(c["w_rebuilt"]["quat_over_euler"]), u3e.push_back(c["w_rebuilt"]["union_quat_over_euler"]);
      q3k += c["w_rebuilt"]["quat_keys"].get<uint64_t>(), unmatched3 += c["w_rebuilt"]["unmatched_joints"].get<uint64_t>();
      joint_seconds += c["joints"].get<double>() * c["seconds"].get<double>();
      ek += c["euler_keys"].get<uint64_t>(), qk += c["quat_keys"].get<uint64_t>();
      eu += c["euler_union_times"].get<uint64_t>(), qu += c["quat_union_times"].get<uint64_t>();
      rk += c["encoder_rotation_keys"].get<uint64_t>(), unmatched += c["unmatched_joints"].get<uint64_t>();
      crossing += c["w_crossing_joints"].get<uint64_t>(), joints += c["joints"].get<uint64_t>();
    }
    if (qe.empty()) continue;
    groups[g] = {{"clips", qe.size()}, {"joints", joints}, {"quat_over_euler", spread(qe)},
                 {"union_quat_over_euler", spread(ue)}, {"encoder_over_euler_keys", spread(re)},
                 {"euler_keys", ek}, {"quat_keys", qk}, {"euler_union_times", eu}, {"quat_union_times", qu},
                 {"encoder_rotation_keys", rk}, {"unmatched_joints", unmatched}, {"w_crossing_joints", crossing},
                 {"euler_keys_per_joint_s", double(ek) / joint_seconds},
                 {"quat_keys_per_joint_s", double(qk) / joint_seconds},
                 {"euler_union_per_joint_s", double(eu) / joint_seconds},
                 {"quat_union_per_joint_s", double(qu) / joint_seconds},
                 {"encoder_keys_per_joint_s", double(rk) / joint_seconds},
                 {"w_rebuilt", {{"quat_over_euler", spread(q3e)}, {"union_quat_over_euler", spread(u3e)},
                                {"quat_keys", q3k}, {"quat_keys_per_joint_s", double(q3k) / joint_seconds},
                                {"unmatched_joints", unmatched3}}}};
  }
  return groups;
}

void print_table(const json& clips, const json& groups) {
  std::printf("%-44s %8s %8s %6s %8s %8s %6s %8s %5s %5s\n", "clip", "euler", "quat", "q/e", "e_union", "q_union",
              "q/e", "encoder", "unm", "w0x");
  for (const json& c : clips)
    std::printf("%-44s %8llu %8llu %6.3f %8llu %8llu %6.3f %8llu %5llu %5llu\n", c["name"].get<std::string>().c_str(),
                (unsigned long long)c["euler_keys"].get<uint64_t>(), (unsigned long long)c["quat_keys"].get<uint64_t>(),
                c["quat_over_euler"].get<double>(), (unsigned long long)c["euler_union_times"].get<uint64_t>(),
                (unsigned long long)c["quat_union_times"].get<uint64_t>(), c["union_quat_over_euler"].get<double>(),
                (unsigned long long)c["encoder_rotation_keys"].get<uint64_t>(),
                (unsigned long long)c["unmatched_joints"].get<uint64_t>(),
                (unsigned long long)c["w_crossing_joints"].get<uint64_t>());
  for (const auto& [g, x] : groups.items())
    std::printf("%s: quat/euler keys median %.3f max %.3f; union median %.3f max %.3f; encoder/euler keys median "
                "%.3f [%.3f, %.3f]; keys/joint/s euler %.2f quat %.2f\n",
                g.c_str(), x["quat_over_euler"]["median"].get<double>(), x["quat_over_euler"]["max"].get<double>(),
                x["union_quat_over_euler"]["median"].get<double>(), x["union_quat_over_euler"]["max"].get<double>(),
                x["encoder_over_euler_keys"]["median"].get<double>(), x["encoder_over_euler_keys"]["min"].get<double>(),
                x["encoder_over_euler_keys"]["max"].get<double>(), x["euler_keys_per_joint_s"].get<double>(),
                x["quat_keys_per_joint_s"].get<double>());
  for (const auto& [g, x] : groups.items())
    std::printf("%s, w rebuilt: quat/euler keys median %.3f max %.3f; union median %.3f max %.3f; joints crossing "
                "w = 0: %llu of %llu\n",
                g.c_str(), x["w_rebuilt"]["quat_over_euler"]["median"].get<double>(),
                x["w_rebuilt"]["quat_over_euler"]["max"].get<double>(),
                x["w_rebuilt"]["union_quat_over_euler"]["median"].get<double>(),
                x["w_rebuilt"]["union_quat_over_euler"]["max"].get<double>(),
                (unsigned long long)x["w_crossing_joints"].get<uint64_t>(), (unsigned long long)x["joints"].get<uint64_t>());
}

struct Options {
  bool json_out = false;
  std::string clip, corpus = KEYANIM_CORPUS_DIR;
  unsigned threads = 1;
};

int usage_error(const std::string& why) {
  std::fprintf(stderr,
               "probe_rotation_curves: %s\nusage: probe_rotation_curves [--json] [--clip NAME] [--corpus DIR] "
               "[--threads N]\n",
               why.c_str());
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--json") {
      o.json_out = true;
    } else if ((a == "--clip" || a == "--corpus" || a == "--threads") && i + 1 < argc) {
      const std::string v = argv[++i];
      if (a == "--clip") o.clip = v;
      if (a == "--corpus") o.corpus = v;
      if (a == "--threads") o.threads = unsigned(std::stoul(v));
    } else {
      return usage_error("unknown or incomplete argument " + a);
    }
  }
  try {
    const auto start = std::chrono::steady_clock::now();
    const std::vector<CorpusClip> clips = find_clips(o.corpus, o.clip);
    if (clips.empty()) return usage_error("no CMU 120 fps or Bandai 30 fps clip in " + o.corpus);
    json list = json::array();
    for (const CorpusClip& c : clips) {
      try {
        list.push_back(probe_clip(c, o.threads));
      } catch (const std::exception& e) {
        throw ProbeError(c.path.string() + ": " + e.what());
      }
      std::fprintf(stderr, "%s: %.1f s\n", c.name.c_str(), list.back()["probe_seconds"].get<double>());
    }
    const json groups = summarize(list);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (o.json_out) {
      std::cout << json{{"tolerance_percent", ko::EncodeSettings{}.tolerance},
                        {"shell_percent", ko::EncodeSettings{}.shell},
                        {"bisections", kBisections},
                        {"run_seconds", seconds},
                        {"notes", "key counts are a proxy for bytes: value bits differ (a quaternion component's "
                                  "step comes from t, an Euler channel's from its budget); one round each, "
                                  "no world-space verification"},
                        {"groups", groups},
                        {"clips", list}}
                       .dump(1)
                << "\n";
    } else {
      print_table(list, groups);
      std::printf("run time %.1f s\n", seconds);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "probe_rotation_curves: %s\n", e.what());
    return 1;
  }
  return 0;
}
