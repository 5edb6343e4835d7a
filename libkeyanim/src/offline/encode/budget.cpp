#include "offline/encode/budget.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>

namespace keyanim::offline {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

// Length of a node's local translation: OFFSET, or with its position channels (largest over
// frames and over both readings: the channel's value, or OFFSET plus it). `stride` is the
// motion's channel count.
double local_translation_length(const Motion& m, const Joint& j, size_t stride) {
  bool has_position = false;
  for (ChannelType t : j.channels) has_position |= !is_rotation(t);
  if (!has_position) return std::hypot(j.offset[0], j.offset[1], j.offset[2]);
  double best = 0.0;
  for (uint32_t f = 0; f < m.frame_count; ++f) {
    const double* row = m.values.data() + size_t(f) * stride + j.first_channel;
    std::array<double, 3> replaced = j.offset, added = j.offset;
    for (size_t k = 0; k < j.channels.size(); ++k) {
      if (is_rotation(j.channels[k])) continue;
      const size_t axis = size_t(channel_axis(j.channels[k]));
      replaced[axis] = row[k], added[axis] = j.offset[axis] + row[k];
    }
    best = std::max({best, std::hypot(replaced[0], replaced[1], replaced[2]), std::hypot(added[0], added[1], added[2])});
  }
  return best;
}

// Steps are powers of 2^(1/4): a quarter octave apart, finer than halving, so that a channel
// keyed at nearly every frame (its bytes are then its values' bits) is not quantized up to
// twice as finely as its tolerance needs; and the same few values from channel to channel,
// so that CHAN's steps compress (a 20-frame Bandai clip: 2165 -> 2043 bytes at 0.5%).
constexpr double kQuarterOctaves[4] = {1.0, 1.189207115002721, 1.4142135623730951, 1.681792830507429};

// A rotation that moves no measured point (a leaf joint without a shell) has this budget.
constexpr double kMaxRotationBudget = 180.0;

// x rounded toward zero to float; never 0 for x > 0 (the budget stays a budget).
float round_down(double x) noexcept {
  float f = static_cast<float>(x);
  if (double(f) > x) f = std::nextafter(f, 0.0f);
  return std::max(f, std::numeric_limits<float>::denorm_min());
}

}  // namespace

std::vector<double> reach_below(const Motion& m, double shell) {
  const auto& joints = m.skeleton.joints;
  const size_t stride = m.channel_count();
  std::vector<double> len(joints.size()), down(joints.size(), 0.0);
  for (size_t i = 0; i < joints.size(); ++i) {
    len[i] = local_translation_length(m, joints[i], stride);
    if (!joints[i].end_site) down[i] = shell;  // its own shell points
  }
  for (size_t i = joints.size(); i-- > 0;) {  // children come after parents
    const int32_t p = joints[i].parent;
    if (p >= 0 && size_t(p) < i) down[size_t(p)] = std::max(down[size_t(p)], len[i] + down[i]);
  }
  return down;
}

std::vector<double> base_tolerances(const Motion& m, double tol_units, double shell) {
  const std::vector<double> down = reach_below(m, shell);
  std::vector<double> base(m.channel_count());
  for (size_t j = 0; j < m.skeleton.joints.size(); ++j) {
    const Joint& joint = m.skeleton.joints[j];
    const double rotation = down[j] > 0.0 ? std::min(kMaxRotationBudget, tol_units / down[j] * kDegPerRad)
                                          : kMaxRotationBudget;
    for (size_t k = 0; k < joint.channels.size(); ++k)
      base[joint.first_channel + k] = is_rotation(joint.channels[k]) ? rotation : tol_units;
  }
  return base;
}

Budgets::Budgets(const Skeleton& skeleton, std::vector<double> base, uint32_t frames)
    : skeleton_(&skeleton),
      frames_(frames),
      base_(std::move(base)),
      factor_(base_.size() * size_t(frames), 1.0f),
      min_factor_(base_.size(), 1.0f),
      dirty_(base_.size(), 1),
      words_((size_t(frames) + 63) / 64),
      changed_(base_.size() * words_, 0),
      own_(skeleton.joints.size(), 1.0),
      own_shell_(skeleton.joints.size(), 1.0),
      below_(skeleton.joints.size(), 1.0) {}

Tolerance Budgets::tolerance(uint32_t c) const noexcept {
  return {base_[c], factor_.data() + size_t(c) * frames_};
}

double Budgets::step(uint32_t c, double fraction, double held) const noexcept {
  const double limit = fraction * min_tolerance(c);
  const int e = std::ilogb(limit);
  const double mantissa = std::ldexp(limit, -e);  // in [1, 2)
  int k = 3;
  while (k > 0 && kQuarterOctaves[k] > mantissa) --k;
  const double step = std::ldexp(kQuarterOctaves[k], e);
  return step < held && step > 0.5 * held ? held : step;
}

void Budgets::tighten(uint32_t frame, const std::vector<NodeRatio>& over) {
  const auto& joints = skeleton_->joints;
  const size_t n = joints.size();
  for (const NodeRatio& o : over) {
    own_[o.node] = std::min(own_[o.node], o.ratio);
    if (o.shell) own_shell_[o.node] = std::min(own_shell_[o.node], o.ratio);
  }
  // Smallest ratio strictly below each node, children before parents.
  for (size_t i = n; i-- > 0;) {
    const int32_t p = joints[i].parent;
    if (p >= 0 && size_t(p) < i) below_[size_t(p)] = std::min(below_[size_t(p)], std::min(own_[i], below_[i]));
  }
  for (size_t j = 0; j < n; ++j) {
    const Joint& joint = joints[j];
    const double rotation = std::min(own_shell_[j], below_[j]), translation = std::min(own_[j], below_[j]);
    own_[j] = own_shell_[j] = below_[j] = 1.0;
    for (size_t k = 0; k < joint.channels.size(); ++k) {
      const double r = is_rotation(joint.channels[k]) ? rotation : translation;
      if (!(r < 1.0)) continue;
      const size_t c = joint.first_channel + k;
      uint64_t* bits = changed_.data() + c * words_;
      if (!dirty_[c]) std::fill(bits, bits + words_, 0), dirty_[c] = 1;  // first tightening this round
      float& f = factor_[c * frames_ + frame];
      f = round_down(double(f) * r);
      min_factor_[c] = std::min(min_factor_[c], f);
      bits[frame / 64] |= uint64_t(1) << (frame % 64);
    }
  }
}

std::vector<uint32_t> Budgets::take_dirty() {
  std::vector<uint32_t> out;
  for (uint32_t c = 0; c < channel_count(); ++c)
    if (dirty_[c]) out.push_back(c), dirty_[c] = 0;
  return out;
}

void Budgets::changed_frames(uint32_t c, std::vector<uint32_t>& out) const {
  out.clear();
  const uint64_t* bits = changed_.data() + size_t(c) * words_;
  for (size_t w = 0; w < words_; ++w)
    for (uint64_t b = bits[w]; b != 0; b &= b - 1) out.push_back(uint32_t(w * 64 + size_t(std::countr_zero(b))));
}

}  // namespace keyanim::offline
