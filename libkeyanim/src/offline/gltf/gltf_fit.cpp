// Keys fitted within the world-space tolerance (gltf_fit.h).
#include "gltf_fit.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "gltf_player.h"
#include "keyanim/offline/error.h"
#include "keyanim/offline/number_text.h"

namespace keyanim::offline::gltf {
namespace {

constexpr QuatLerp kLocalLerps[] = {QuatLerp::slerp, QuatLerp::nlerp};  // three.js picks one of these per segment
constexpr uint32_t kMaxRounds = 24;
constexpr double kTighten = 0.8;     // a blamed track's budget shrinks by this per round
constexpr double kBlameShare = 0.6;  // tracks moving a stray point by at least this share of the
                                     // largest contribution are blamed
constexpr uint32_t kWindow = 32;     // nodes a point's movers are walked up at once (walk_movers)

// One node's rotation (k = 4) or translation (k = 3) at every frame of the window.
struct Target {
  uint32_t node = 0;
  int k = 4;
  std::vector<double> exact;             // k per frame; rotations: unit, consecutive frames in one hemisphere
  std::vector<float> value;              // exact rounded to float32, as keys store it
  std::vector<float> rate_in, rate_out;  // rotations: dq/dt per second just before / after the frame
  double budget = 0.0;                   // local: radians, or length units
  bool every_frame = false;              // the last resort: a key at every frame
  std::vector<double> local_error;       // per frame, of the fitted track

  bool rotation() const noexcept { return k == 4; }
  // Local error of `got` at frame index i: rotation angle, or distance.
  double error(uint32_t i, const double* got) const {
    const double* want = &exact[size_t(k) * i];
    if (!rotation()) return std::hypot(got[0] - want[0], got[1] - want[1], got[2] - want[2]);
    // 4 asin(chord / 2) between the unit target and `got` normalised, in the nearer hemisphere.
    const double len = std::sqrt(got[0] * got[0] + got[1] * got[1] + got[2] * got[2] + got[3] * got[3]);
    const double dot = want[0] * got[0] + want[1] * got[1] + want[2] * got[2] + want[3] * got[3];
    const double s = (dot < 0.0 ? -1.0 : 1.0) / len;
    double chord2 = 0.0;
    for (int c = 0; c < 4; ++c) chord2 += (want[c] - s * got[c]) * (want[c] - s * got[c]);
    return 4.0 * std::asin(std::min(1.0, 0.5 * std::sqrt(chord2)));
  }
};

Target rotation_target(const NodeCurves& node, const std::vector<ChannelCurve>& curves, uint32_t index,
                       const Window& w) {
  Target t;
  t.node = index;
  Quat prev{0, 0, 0, 1};
  for (uint32_t f = w.first; f <= w.last; ++f) {
    Quat q = rotation_at(node, curves, f);
    Quat in = rotation_rate(node, curves, f, true, w.frame_time);
    Quat out = rotation_rate(node, curves, f, false, w.frame_time);
    if (prev[0] * q[0] + prev[1] * q[1] + prev[2] * q[2] + prev[3] * q[3] < 0.0)
      for (int i = 0; i < 4; ++i) q[i] = -q[i], in[i] = -in[i], out[i] = -out[i];
    prev = q;
    for (int i = 0; i < 4; ++i) {
      t.exact.push_back(q[i]);
      t.value.push_back(float(q[i]));
      t.rate_in.push_back(float(in[i]));
      t.rate_out.push_back(float(out[i]));
    }
  }
  return t;
}

Target translation_target(const NodeCurves& node, const std::vector<ChannelCurve>& curves, uint32_t index,
                          const Window& w) {
  Target t;
  t.node = index;
  t.k = 3;
  for (uint32_t f = w.first; f <= w.last; ++f)
    for (float v : translation_at(node, curves, f)) t.exact.push_back(v), t.value.push_back(v);
  return t;
}

// Segment from frame index a to b as `interp` keys; true when every frame between stays within
// the target's budget under every reading.
bool segment_ok(const Target& t, const Window& w, Interp interp, uint32_t a, uint32_t b) {
  const double ta = float(w.time(w.first + a)), tb = float(w.time(w.first + b));
  const size_t k = size_t(t.k);
  const float* out0 = interp == Interp::cubic ? &t.rate_out[k * a] : nullptr;
  const float* in1 = interp == Interp::cubic ? &t.rate_in[k * b] : nullptr;
  double got[4];
  for (uint32_t i = a + 1; i < b; ++i)
    for (QuatLerp lerp : kLocalLerps) {
      eval_segment(interp, t.k, lerp, &t.value[k * a], out0, in1, &t.value[k * b], ta, tb, w.time(w.first + i), got);
      if (!(t.error(i, got) <= t.budget)) return false;
      if (interp == Interp::cubic || !t.rotation()) break;  // one reading only
    }
  return true;
}

// Greedy keys: from each key, the farthest next key whose segment is within budget (found by
// doubling, then bisection). The first and last frames are always keys.
std::vector<uint32_t> greedy_keys(const Target& t, const Window& w, Interp interp) {
  const uint32_t n = w.frames();
  std::vector<uint32_t> keys{0};
  uint32_t a = 0;
  while (a + 1 < n) {
    uint32_t good = a + 1, bad = n;
    if (!t.every_frame) {
      for (uint32_t step = 2;; step *= 2) {
        const uint32_t b = std::min(a + step, n - 1);
        if (b <= good) break;
        if (!segment_ok(t, w, interp, a, b)) {
          bad = b;
          break;
        }
        good = b;
        if (b == n - 1) break;
      }
      while (bad - good > 1 && bad < n) {
        const uint32_t mid = good + (bad - good) / 2;
        (segment_ok(t, w, interp, a, mid) ? good : bad) = mid;
      }
    }
    keys.push_back(good);
    a = good;
  }
  return keys;
}

Sampler make_sampler(const Target& t, const Window& w, Interp interp, const std::vector<uint32_t>& keys) {
  Sampler s;
  s.components = t.k;
  s.interp = keys.size() == 1 ? Interp::linear : interp;
  const size_t k = size_t(t.k);
  for (size_t n = 0; n < keys.size(); ++n) {
    const size_t i = keys[n];
    s.times.push_back(float(w.time(w.first + uint32_t(i))));
    const float* v = &t.value[k * i];
    if (s.interp == Interp::linear) {
      s.values.insert(s.values.end(), v, v + k);
      continue;
    }
    static const float kZero[4] = {};  // the first in-tangent and the last out-tangent are unused
    const float* in = n == 0 ? kZero : &t.rate_in[k * i];
    const float* out = n + 1 == keys.size() ? kZero : &t.rate_out[k * i];
    s.values.insert(s.values.end(), in, in + k);
    s.values.insert(s.values.end(), v, v + k);
    s.values.insert(s.values.end(), out, out + k);
  }
  return s;
}

size_t sampler_bytes(const Sampler& s) { return s.times.size() * 4 + s.values.size() * 4; }

// Fits the target at its current budget (rotations: the smaller of LINEAR and CUBICSPLINE,
// unless linear_only) and records the local error of the result at every frame.
Sampler fit(Target& t, const Window& w, bool linear_only) {
  Sampler best = make_sampler(t, w, Interp::linear, greedy_keys(t, w, Interp::linear));
  if (t.rotation() && !linear_only && !t.every_frame) {
    Sampler cubic = make_sampler(t, w, Interp::cubic, greedy_keys(t, w, Interp::cubic));
    if (sampler_bytes(cubic) < sampler_bytes(best)) best = std::move(cubic);
  }
  t.local_error.assign(w.frames(), 0.0);
  double got[4];
  for (uint32_t i = 0; i < w.frames(); ++i)
    for (QuatLerp lerp : kQuatLerps) {
      eval_sampler(best, w.time(w.first + i), lerp, got);
      t.local_error[i] = std::max(t.local_error[i], t.error(i, got));
    }
  return best;
}

double distance(const Vec3& a, const Vec3& b) { return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]); }

// Calls visit(node, rotation, lever) for each track moving each of the points at frame index i:
// its rotating ancestors (its owner too for shell points), with the distance from the node to
// the point as the lever arm, and its translated ones (the owner and every ancestor); then
// walked() after each point. Walking every ancestor of every point is quadratic in the depth (a
// chain of 16,000 joints: 10 s), so a walk stops kWindow nodes up and hands the point on to
// the joint at its top, which stands for it with their distance added to its lever arms (a
// bound, by the triangle inequality) and is walked in turn, once for everything handed on to it
// at that frame. Skeletons up to kWindow deep get every lever arm exactly, as if walked to the root.
template <typename Visit, typename Walked>
void walk_movers(const Skeleton& sk, const Reference& ref, uint32_t i, const std::vector<uint32_t>& points,
                 Visit visit, Walked walked) {
  std::vector<double> handed(sk.joints.size(), -1.0);  // per joint: the farthest point handed on (-1: none)
  const auto walk = [&](uint32_t start, bool own_rotation, const Vec3& at, double radius) {
    for (uint32_t a = start, n = 1;; a = uint32_t(sk.joints[a].parent), ++n) {
      if (a != start || own_rotation) visit(a, true, distance(at, ref.point(i, a)) + radius);
      visit(a, false, 0.0);
      if (sk.joints[a].parent < 0) break;
      if (n == kWindow) {
        handed[a] = std::max(handed[a], distance(at, ref.point(i, a)) + radius);
        break;
      }
    }
    walked();
  };
  for (uint32_t p : points) walk(ref.owner(p), ref.moved_by_owner(p), ref.point(i, p), 0.0);
  for (uint32_t w = uint32_t(handed.size()); w-- > 0;)  // parents first: a joint's walk hands on to an earlier one
    if (handed[w] >= 0.0) walk(uint32_t(sk.joints[w].parent), true, ref.point(i, w), handed[w]);
}

// Initial budgets, as if each track were the only source of error: a rotation moves the
// farthest point the joint carries (over the window) by the tolerance; a translation moves
// its points by the tolerance.
void initial_budgets(std::vector<Target>& targets, const Skeleton& sk, const Reference& ref, double tolerance) {
  std::vector<double> reach(sk.joints.size(), 0.0);
  std::vector<uint32_t> measured;
  for (uint32_t p = 0; p < ref.point_count(); ++p)
    if (ref.measured(p)) measured.push_back(p);
  for (uint32_t i = 0; i < ref.window().frames(); ++i)
    walk_movers(
        sk, ref, i, measured,
        [&](uint32_t a, bool rotation, double lever) {
          if (rotation) reach[a] = std::max(reach[a], lever);
        },
        [] {});
  for (Target& t : targets)
    t.budget = !t.rotation() ? tolerance : reach[t.node] > 0.0 ? tolerance / reach[t.node] : 1.0;
}

// Tracks to tighten: for each stray point, the tracks moving it whose local error (times the
// lever arm for rotations) is a large share of the largest such contribution.
std::vector<bool> blame(const std::vector<Violation>& violations, const std::vector<Target>& targets,
                        const std::vector<int32_t> (&target_of)[2], const Skeleton& sk, const Reference& ref) {
  std::vector<bool> marked(targets.size(), false);
  std::vector<std::pair<int32_t, double>> chain;
  double largest = 0.0;
  std::vector<uint32_t> points;
  for (size_t v = 0; v < violations.size();) {  // check_model lists them frame by frame
    const uint32_t i = violations[v].frame_index;
    points.clear();
    for (; v < violations.size() && violations[v].frame_index == i; ++v) points.push_back(violations[v].point);
    const auto visit = [&](uint32_t a, bool rotation, double lever) {
      const int32_t ti = target_of[rotation][a];
      if (ti < 0) return;
      double c = targets[size_t(ti)].local_error[i];
      if (rotation) c *= lever;
      chain.push_back({ti, c});
      largest = std::max(largest, c);
    };
    const auto walked = [&] {
      for (const auto& [ti, c] : chain)
        if (largest > 0.0 && c >= kBlameShare * largest) marked[size_t(ti)] = true;
      chain.clear();
      largest = 0.0;
    };
    walk_movers(sk, ref, i, points, visit, walked);
  }
  return marked;
}

std::string describe_failure(const Skeleton& sk, const Reference& ref, const CheckResult& r, double tolerance) {
  std::ostringstream o;
  const uint32_t node = ref.owner(r.worst_point);
  o << "float32 glTF keys cannot hold the tolerance " << general_text(tolerance) << ": error "
    << general_text(r.max_error) << " at "
    << (sk.joints[node].end_site ? "the End Site of " + sk.joints[sk.joints[node].parent].name : sk.joints[node].name)
    << (ref.moved_by_owner(r.worst_point) ? " (shell point)" : "") << ", frame "
    << ref.window().first + r.worst_frame_index << " (use a larger --error)";
  return o.str();
}

}  // namespace

uint32_t fit_keys(Model& model, const std::vector<NodeCurves>& nodes, const std::vector<ChannelCurve>& curves,
                  const Reference& reference, double tolerance, bool linear_only,
                  const std::function<void(EncodeStage, double)>& progress) {
  const Skeleton& sk = model.skeleton;
  const Window& w = reference.window();
  std::vector<Target> targets;
  std::vector<int32_t> target_of[2] = {std::vector<int32_t>(sk.joints.size(), -1),   // translations
                                       std::vector<int32_t>(sk.joints.size(), -1)};  // rotations
  for (uint32_t j = 0; j < sk.joints.size(); ++j) {
    if (!nodes[j].rotation.empty() && !rotation_at_rest(nodes[j], curves)) {
      target_of[1][j] = int32_t(targets.size());
      targets.push_back(rotation_target(nodes[j], curves, j, w));
    }
    if (linear_only && !translation_at_rest(nodes[j], curves)) {
      target_of[0][j] = int32_t(targets.size());
      targets.push_back(translation_target(nodes[j], curves, j, w));
    }
  }
  initial_budgets(targets, sk, reference, tolerance);
  std::vector<bool> refit(targets.size(), true), marked;
  const auto report = [&](EncodeStage stage, double f) {
    if (progress) progress(stage, f);
  };
  CheckResult r;
  for (uint32_t rounds = 1;; ++rounds) {
    const size_t todo = size_t(std::count(refit.begin(), refit.end(), true));
    size_t done = 0;
    bool changed = rounds == 1;
    for (size_t i = 0; i < targets.size(); ++i) {
      if (!refit[i]) continue;
      NodeAnimation& anim = model.nodes[targets[i].node];
      std::optional<Sampler>& track = targets[i].rotation() ? anim.rotation : anim.translation;
      Sampler s = fit(targets[i], w, linear_only);
      changed = changed || track != s;
      track = std::move(s);
      report(EncodeStage::fitting, double(++done) / double(todo));
    }
    report(EncodeStage::fitting, 1.0);
    // A tighter budget often gives the same keys (a budget well above what the keys reach):
    // then the model, its check and the blame are the last round's, and only the budgets shrink.
    if (changed) {
      r = check_model(model, reference, tolerance, [&](double f) { report(EncodeStage::verifying, f); });
      if (r.violations.empty()) return rounds;
      marked = blame(r.violations, targets, target_of, sk, reference);
    } else {
      report(EncodeStage::verifying, 1.0);
    }
    refit = marked;
    bool any = false;
    for (size_t i = 0; i < targets.size(); ++i) {
      if (!refit[i] || targets[i].every_frame) {
        refit[i] = false;
        continue;
      }
      any = true;
      targets[i].budget *= kTighten;
      targets[i].every_frame = rounds >= kMaxRounds;
    }
    if (!any) throw Error(ErrorKind::limit, describe_failure(sk, reference, r, tolerance));
  }
}

}  // namespace keyanim::offline::gltf
