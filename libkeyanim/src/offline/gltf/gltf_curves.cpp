// Clip channels as curves, and translations mapped exactly onto glTF samplers (gltf_curves.h).
#include "gltf_curves.h"

#include <algorithm>
#include <numbers>

#include "keyanim/cardinal.h"

namespace keyanim::offline::gltf {

ChannelCurve::ChannelCurve(const Clip& clip, uint32_t channel) : clip_(&clip), channel_(channel) {
  const ChannelInfo info = clip.channel(channel);
  interp_ = info.interp;
  s_ = tension_to_s(info.tension);
  rule_ = clip.tangent_rule();
  frames_.resize(info.key_count);
  values_.resize(info.key_count);
  // Cannot fail: the channel exists and the spans hold key_count entries.
  (void)clip.channel_keys(channel, frames_, values_);
}

float ChannelCurve::value(double frame_position) const noexcept {
  float v = 0.0f;
  (void)clip_->sample_channel(channel_, static_cast<float>(frame_position), v);  // the channel exists; positions are finite
  return v;
}

double ChannelCurve::slope(uint32_t f, bool from_left) const noexcept {
  const size_t n = frames_.size();
  if (n < 2) return 0.0;
  const uint32_t first = frames_.front(), last = frames_.back();
  if (from_left ? (f <= first || f > last) : (f < first || f >= last)) return 0.0;
  // The segment [k_j, k_j+1] holding f on that side: k_j < f <= k_j+1 (left), k_j <= f < k_j+1.
  const uint32_t probe = from_left ? f - 1 : f;
  const uint32_t j = uint32_t(std::upper_bound(frames_.begin(), frames_.end(), probe) - frames_.begin()) - 1;
  const SegmentOperands seg = segment_operands(frames_.data(), values_.data(), uint32_t(n), j, interp_, s_, rule_);
  const Operands<float>& o = seg.o;
  const double len = double(frames_[j + 1] - frames_[j]);
  if (seg.linear) return double(o.d) / len;
  const double u = double(f - frames_[j]) / len;
  // Derivatives of h01, h10, h11 (cardinal.h's hermite).
  const double dh01 = -6.0 * u * u + 6.0 * u;
  const double dh10 = 3.0 * u * u - 4.0 * u + 1.0;
  const double dh11 = 3.0 * u * u - 2.0 * u;
  return (dh01 * double(o.d) + dh10 * double(o.m0) + dh11 * double(o.m1)) / len;
}

bool ChannelCurve::constant_at(double v) const noexcept {
  if (frames_.empty()) return v == 0.0;
  return std::all_of(values_.begin(), values_.end(), [v](float x) { return double(x) == v; });
}

NodeCurves node_curves(const Joint& joint) {
  NodeCurves n;
  n.offset = joint.offset;
  for (size_t k = 0; k < joint.channels.size(); ++k) {
    const ChannelType t = joint.channels[k];
    const int32_t c = int32_t(joint.first_channel + k);
    if (is_rotation(t)) n.rotation.push_back({channel_axis(t), c});
    else n.translation[size_t(channel_axis(t))] = c;  // a later channel of an axis replaces (as FK)
  }
  return n;
}

bool translation_at_rest(const NodeCurves& node, const std::vector<ChannelCurve>& curves) {
  for (int a = 0; a < 3; ++a)
    if (node.translation[a] >= 0 && !curves[size_t(node.translation[a])].constant_at(node.offset[a])) return false;
  return true;
}

bool rotation_at_rest(const NodeCurves& node, const std::vector<ChannelCurve>& curves) {
  return std::all_of(node.rotation.begin(), node.rotation.end(),
                     [&](const auto& r) { return curves[size_t(r[1])].constant_at(0.0); });
}

std::array<float, 3> translation_at(const NodeCurves& node, const std::vector<ChannelCurve>& curves,
                                    double frame_position) {
  std::array<float, 3> t;
  for (size_t a = 0; a < 3; ++a) {
    const int32_t c = node.translation[a];
    t[a] = c >= 0 ? curves[size_t(c)].value(frame_position) : static_cast<float>(node.offset[a]);
  }
  return t;
}

Sampler translation_sampler(const NodeCurves& node, const std::vector<ChannelCurve>& curves, const Window& window) {
  std::vector<uint32_t> knots{window.first, window.last};
  bool linear = true;
  for (int a = 0; a < 3; ++a) {
    if (node.translation[a] < 0) continue;
    const ChannelCurve& curve = curves[size_t(node.translation[a])];
    linear = linear && curve.piecewise_linear();
    for (uint32_t k : curve.key_frames())
      if (k > window.first && k < window.last) knots.push_back(k);
  }
  std::sort(knots.begin(), knots.end());
  knots.erase(std::unique(knots.begin(), knots.end()), knots.end());

  Sampler s;
  s.components = 3;
  s.interp = linear || knots.size() == 1 ? Interp::linear : Interp::cubic;
  for (size_t i = 0; i < knots.size(); ++i) {
    const uint32_t k = knots[i];
    s.times.push_back(static_cast<float>(window.time(k)));
    const std::array<float, 3> value = translation_at(node, curves, k);
    if (s.interp == Interp::linear) {
      s.values.insert(s.values.end(), value.begin(), value.end());
      continue;
    }
    // In-tangent, value, out-tangent, per second: a Hermite tangent per frame over frame_time.
    // The first in-tangent and the last out-tangent are never used; they are written as 0.
    float tangents[2][3] = {};
    for (int a = 0; a < 3; ++a) {
      const int32_t c = node.translation[a];
      if (c < 0) continue;
      if (i > 0) tangents[0][a] = static_cast<float>(curves[size_t(c)].slope(k, true) / window.frame_time);
      if (i + 1 < knots.size()) tangents[1][a] = static_cast<float>(curves[size_t(c)].slope(k, false) / window.frame_time);
    }
    s.values.insert(s.values.end(), tangents[0], tangents[0] + 3);
    s.values.insert(s.values.end(), value.begin(), value.end());
    s.values.insert(s.values.end(), tangents[1], tangents[1] + 3);
  }
  return s;
}

Sampler resampled_translation(const NodeCurves& node, const std::vector<ChannelCurve>& curves,
                              const std::vector<double>& positions, const std::vector<double>& times) {
  Sampler s;
  s.components = 3;
  for (size_t i = 0; i < positions.size(); ++i) {
    s.times.push_back(static_cast<float>(times[i]));
    const std::array<float, 3> value = translation_at(node, curves, positions[i]);
    s.values.insert(s.values.end(), value.begin(), value.end());
  }
  return s;
}

Sampler resampled_rotation(const NodeCurves& node, const std::vector<ChannelCurve>& curves,
                           const std::vector<double>& positions, const std::vector<double>& times) {
  Sampler s;
  s.components = 4;
  Quat prev{0, 0, 0, 1};
  for (size_t i = 0; i < positions.size(); ++i) {
    Quat q = rotation_at(node, curves, positions[i]);
    // Consecutive keys in one hemisphere: every player then takes the short way.
    if (prev[0] * q[0] + prev[1] * q[1] + prev[2] * q[2] + prev[3] * q[3] < 0.0)
      for (double& v : q) v = -v;
    prev = q;
    s.times.push_back(static_cast<float>(times[i]));
    for (double v : q) s.values.push_back(static_cast<float>(v));
  }
  return s;
}

namespace {

// The derivative per degree of a rotation about one axis (fk.h: axis_quaternion).
Quat axis_quat_derivative(int axis, double degrees) {
  double s, c;
  sin_cos_deg(0.5 * degrees, s, c);
  constexpr double k = std::numbers::pi / 360.0;  // d(half angle, radians) / d(degrees)
  Quat q{0, 0, 0, -s * k};
  q[size_t(axis)] = c * k;
  return q;
}

}  // namespace

Quat rotation_at(const NodeCurves& node, const std::vector<ChannelCurve>& curves, double frame_position) {
  Quat q{0, 0, 0, 1};
  for (const auto& [axis, c] : node.rotation)
    q = quat_multiply(q, axis_quaternion(axis, curves[size_t(c)].value(frame_position)));
  return q;
}

Quat rotation_rate(const NodeCurves& node, const std::vector<ChannelCurve>& curves, uint32_t f, bool from_left,
                   double frame_time) {
  // Product rule over Q = q_1 q_2 ... q_m: sum over i of q_1..q_i-1 (dq_i/dt) q_i+1..q_m.
  const size_t m = node.rotation.size();
  std::vector<Quat> q(m), dq(m);
  for (size_t i = 0; i < m; ++i) {
    const auto& [axis, c] = node.rotation[i];
    const double a = curves[size_t(c)].value(f);
    const double rate = curves[size_t(c)].slope(f, from_left) / frame_time;  // degrees per second
    q[i] = axis_quaternion(axis, a);
    dq[i] = axis_quat_derivative(axis, a);
    for (double& v : dq[i]) v *= rate;
  }
  Quat sum{0, 0, 0, 0};
  for (size_t i = 0; i < m; ++i) {
    Quat term{0, 0, 0, 1};
    for (size_t k = 0; k < m; ++k) term = quat_multiply(term, k == i ? dq[k] : q[k]);
    for (int e = 0; e < 4; ++e) sum[e] += term[e];
  }
  return sum;
}

}  // namespace keyanim::offline::gltf
