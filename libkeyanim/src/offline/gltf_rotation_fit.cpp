// Quaternion keys fitted within the world-space tolerance (gltf_rotation_fit.h).
#include "gltf_rotation_fit.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "gltf_player.h"

namespace keyanim::offline::gltf {
namespace {

constexpr QuatLerp kLocalLerps[] = {QuatLerp::slerp, QuatLerp::nlerp};  // three.js picks one of these per segment
constexpr uint32_t kMaxRounds = 24;
constexpr double kTighten = 0.5;        // a blamed joint's angle budget shrinks by this per round
constexpr double kBlameShare = 0.3;     // joints moving a stray point by at least this share of the
                                        // largest contribution are blamed

// One joint's rotation at every frame of the window, as the keys would store it.
struct Target {
  uint32_t node = 0;
  std::vector<Quat> q;                 // unit, consecutive frames in one hemisphere
  std::vector<float> value;            // q rounded to float32, 4 per frame
  std::vector<float> rate_in, rate_out;  // dq/dt per second just before / after the frame, float32
  double angle = 0.0;                  // local budget, radians
  bool every_frame = false;            // the last resort: a key at every frame
  std::vector<double> local_error;     // per frame: angle between the fitted and the target rotation
};

// Rotation angle between unit q and p (any length): 4 asin(chord / 2) of the normalised pair.
double rotation_angle(const Quat& q, const double* p) {
  const double len = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3]);
  const double s = (q[0] * p[0] + q[1] * p[1] + q[2] * p[2] + q[3] * p[3] < 0.0 ? -1.0 : 1.0) / len;
  double chord2 = 0.0;
  for (int i = 0; i < 4; ++i) chord2 += (q[i] - s * p[i]) * (q[i] - s * p[i]);
  return 4.0 * std::asin(std::min(1.0, 0.5 * std::sqrt(chord2)));
}

Target make_target(const NodeCurves& node, const std::vector<ChannelCurve>& curves, uint32_t index,
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
    t.q.push_back(q);
    for (int i = 0; i < 4; ++i) {
      t.value.push_back(float(q[i]));
      t.rate_in.push_back(float(in[i]));
      t.rate_out.push_back(float(out[i]));
    }
  }
  return t;
}

// Segment from frame index a to b as `interp` keys; true when every frame between stays
// within the target's angle under every reading.
bool segment_ok(const Target& t, const Window& w, Interp interp, uint32_t a, uint32_t b) {
  const double ta = float(w.time(w.first + a)), tb = float(w.time(w.first + b));
  double out[4];
  for (uint32_t i = a + 1; i < b; ++i)
    for (QuatLerp lerp : kLocalLerps) {
      eval_segment(interp, 4, lerp, &t.value[4 * a], &t.rate_out[4 * a], &t.rate_in[4 * b], &t.value[4 * b], ta, tb,
                   w.time(w.first + i), out);
      if (!(rotation_angle(t.q[i], out) <= t.angle)) return false;
      if (interp == Interp::cubic) break;  // one reading only
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
  s.components = 4;
  s.interp = keys.size() == 1 ? Interp::linear : interp;
  for (size_t k = 0; k < keys.size(); ++k) {
    const uint32_t i = keys[k];
    s.times.push_back(float(w.time(w.first + i)));
    const float* v = &t.value[4 * i];
    if (s.interp == Interp::linear) {
      s.values.insert(s.values.end(), v, v + 4);
      continue;
    }
    static const float kZero[4] = {};  // the first in-tangent and the last out-tangent are unused
    const float* in = k == 0 ? kZero : &t.rate_in[4 * i];
    const float* out = k + 1 == keys.size() ? kZero : &t.rate_out[4 * i];
    s.values.insert(s.values.end(), in, in + 4);
    s.values.insert(s.values.end(), v, v + 4);
    s.values.insert(s.values.end(), out, out + 4);
  }
  return s;
}

size_t sampler_bytes(const Sampler& s) { return s.times.size() * 4 + s.values.size() * 4; }

// Fits the target at its current budget (the smaller of LINEAR and CUBICSPLINE) and records
// the local error of the result at every frame.
Sampler fit(Target& t, const Window& w) {
  Sampler best = make_sampler(t, w, Interp::linear, greedy_keys(t, w, Interp::linear));
  if (!t.every_frame) {
    Sampler cubic = make_sampler(t, w, Interp::cubic, greedy_keys(t, w, Interp::cubic));
    if (sampler_bytes(cubic) < sampler_bytes(best)) best = std::move(cubic);
  }
  t.local_error.assign(w.frames(), 0.0);
  double out[4];
  for (uint32_t i = 0; i < w.frames(); ++i)
    for (QuatLerp lerp : kQuatLerps) {
      eval_sampler(best, w.time(w.first + i), lerp, out);
      t.local_error[i] = std::max(t.local_error[i], rotation_angle(t.q[i], out));
    }
  return best;
}

double distance(const Vec3& a, const Vec3& b) { return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]); }

// Initial budgets: the angle that moves the farthest point the joint carries (over the window)
// by the tolerance, as if the joint were the only source of error.
void initial_angles(std::vector<Target>& targets, const Skeleton& sk, const Reference& ref, double tolerance) {
  std::vector<double> reach(sk.joints.size(), 0.0);
  for (uint32_t i = 0; i < ref.window().frames(); ++i)
    for (uint32_t p = 0; p < ref.point_count(); ++p) {
      if (!ref.measured(p)) continue;
      const uint32_t o = ref.owner(p);
      for (int32_t a = ref.moved_by_owner(p) ? int32_t(o) : sk.joints[o].parent; a >= 0; a = sk.joints[a].parent)
        reach[a] = std::max(reach[a], distance(ref.point(i, p), ref.point(i, uint32_t(a))));
    }
  for (Target& t : targets) t.angle = reach[t.node] > 0.0 ? tolerance / reach[t.node] : 1.0;
}

// Joints to tighten: for each stray point, the rotating joints above it whose local error,
// times their distance to the point, is a large share of the largest such contribution.
std::vector<bool> blame(const std::vector<Violation>& violations, const std::vector<Target>& targets,
                        const std::vector<int32_t>& target_of, const Skeleton& sk, const Reference& ref) {
  std::vector<bool> marked(targets.size(), false);
  std::vector<std::pair<int32_t, double>> chain;
  for (const Violation& v : violations) {
    chain.clear();
    double largest = 0.0;
    const uint32_t o = ref.owner(v.point);
    for (int32_t a = ref.moved_by_owner(v.point) ? int32_t(o) : sk.joints[o].parent; a >= 0; a = sk.joints[a].parent) {
      const int32_t ti = target_of[a];
      if (ti < 0) continue;
      const double c = targets[ti].local_error[v.frame_index] *
                       distance(ref.point(v.frame_index, v.point), ref.point(v.frame_index, uint32_t(a)));
      chain.push_back({ti, c});
      largest = std::max(largest, c);
    }
    for (const auto& [ti, c] : chain)
      if (largest > 0.0 && c >= kBlameShare * largest) marked[ti] = true;
  }
  return marked;
}

std::string describe_failure(const Skeleton& sk, const Reference& ref, const CheckResult& r, double tolerance) {
  std::ostringstream o;
  const uint32_t node = ref.owner(r.worst_point);
  o << "float32 glTF keys cannot hold the tolerance " << tolerance << ": error " << r.max_error << " at "
    << (sk.joints[node].end_site ? "the End Site of " + sk.joints[sk.joints[node].parent].name : sk.joints[node].name)
    << (ref.moved_by_owner(r.worst_point) ? " (shell point)" : "") << ", frame "
    << ref.window().first + r.worst_frame_index << " (use a larger --error)";
  return o.str();
}

}  // namespace

bool fit_rotations(Model& model, const std::vector<NodeCurves>& nodes, const std::vector<ChannelCurve>& curves,
                   const Reference& reference, double tolerance, uint32_t& rounds, std::string& error) {
  const Skeleton& sk = model.skeleton;
  const Window& w = reference.window();
  std::vector<Target> targets;
  std::vector<int32_t> target_of(sk.joints.size(), -1);
  for (uint32_t j = 0; j < sk.joints.size(); ++j) {
    if (nodes[j].rotation.empty() || rotation_at_rest(nodes[j], curves)) continue;
    target_of[j] = int32_t(targets.size());
    targets.push_back(make_target(nodes[j], curves, j, w));
  }
  initial_angles(targets, sk, reference, tolerance);
  std::vector<bool> refit(targets.size(), true);
  for (rounds = 1;; ++rounds) {
    for (size_t i = 0; i < targets.size(); ++i)
      if (refit[i]) model.nodes[targets[i].node].rotation = fit(targets[i], w);
    const CheckResult r = check_model(model, reference, tolerance);
    if (r.violations.empty()) return true;
    refit = blame(r.violations, targets, target_of, sk, reference);
    bool any = false;
    for (size_t i = 0; i < targets.size(); ++i) {
      if (!refit[i] || targets[i].every_frame) {
        refit[i] = false;
        continue;
      }
      any = true;
      targets[i].angle *= kTighten;
      targets[i].every_frame = rounds >= kMaxRounds;
    }
    if (!any) {
      error = describe_failure(sk, reference, r, tolerance);
      return false;
    }
  }
}

}  // namespace keyanim::offline::gltf
