#include "offline/encode/signals.h"

#include <algorithm>
#include <cmath>

#include "keyanim/offline/encode.h"
#include "keyanim/offline/error.h"
#include "keyanim/offline/fk.h"
#include "keyanim/offline/number_text.h"
#include "offline/encode/rotations.h"
#include "offline/encode/spare.h"
#include "offline/parallel.h"

namespace keyanim::offline {
namespace {

// Keys are binary32 at runtime: a value (or a position) beyond its range cannot play back.
constexpr double kMaxMagnitude = 1e37;
constexpr uint32_t kCheckWindow = 256;  // frames per FK job

// Which value, and what is wrong with it: NaN and infinities (which a BVH reader refuses, with
// its line and column, but a motion built in memory can hold) are not "too large".
Error bad_value(const Motion& m, size_t i) {
  const uint32_t n_ch = m.channel_count();
  const uint32_t c = uint32_t(i % n_ch), f = uint32_t(i / n_ch);
  std::string name = "channel " + std::to_string(c);
  for (const Joint& j : m.skeleton.joints)
    if (c >= j.first_channel && c - j.first_channel < j.channels.size())
      name += " (" + j.name + " " + channel_name(j.channels[c - j.first_channel]) + ")";
  const double v = m.values[i];
  const std::string what = std::isnan(v)   ? "is NaN (not a number): a key cannot hold it"
                           : std::isinf(v) ? std::string("is ") + (v > 0 ? "+" : "-") + "inf: a key cannot hold it"
                                           : "is " + general_text(v, 9) +
                                                 ", beyond what binary32 keys can hold (|v| > 1e37)";
  return Error(ErrorKind::malformed, name + " of frame " + std::to_string(f) + " " + what);
}

// No world position of any frame is farther from the origin than this: rotations keep lengths,
// so a node is at most the sum, over it and its ancestors, of |OFFSET| and the longest
// translation its position channels can make (each at its largest magnitude `largest`, either
// reading). Rounding in FK adds a few ulps per level, far inside the halved limit it is held to.
double reach_bound(const Skeleton& s, const std::vector<double>& largest) {
  std::vector<double> reach(s.joints.size(), 0.0);
  double most = 0.0;
  for (size_t j = 0; j < s.joints.size(); ++j) {
    const Joint& joint = s.joints[j];
    double t = 0.0;
    for (size_t k = 0; k < joint.channels.size(); ++k)
      if (!is_rotation(joint.channels[k])) t += largest[joint.first_channel + k] * largest[joint.first_channel + k];
    const Vec3& o = joint.offset;
    reach[j] = std::sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]) + std::sqrt(t);
    if (joint.parent >= 0 && size_t(joint.parent) < j) reach[j] += reach[size_t(joint.parent)];
    most = std::max(most, reach[j]);
  }
  return most;
}

}  // namespace

void check_motion(const Motion& m, unsigned threads) {
  const uint32_t n_ch = m.channel_count();
  if (m.values.size() != size_t(n_ch) * m.frame_count)
    throw Error(ErrorKind::invalid_argument,
                "motion has " + std::to_string(m.values.size()) + " values, expected frames x channels");
  std::vector<double> largest(n_ch, 0.0);  // per channel, of |value|
  for (size_t row = 0; row < m.values.size(); row += n_ch)
    for (size_t c = 0; c < n_ch; ++c) {
      const double v = std::fabs(m.values[row + c]);
      if (!(v <= kMaxMagnitude)) throw bad_value(m, row + c);
      largest[c] = std::max(largest[c], v);
    }
  if (reach_bound(m.skeleton, largest) <= kMaxMagnitude / 2) return;  // no frame can overflow
  const size_t windows = (size_t(m.frame_count) + kCheckWindow - 1) / kCheckWindow;
  std::vector<uint8_t> overflow(windows, 0);
  parallel_for(windows, threads, [&](size_t w, unsigned) {
    std::vector<Vec3> a, b;
    auto check = [&](const std::vector<Vec3>& pos) {
      for (const Vec3& p : pos)
        if (!(std::fabs(p[0]) <= kMaxMagnitude && std::fabs(p[1]) <= kMaxMagnitude && std::fabs(p[2]) <= kMaxMagnitude))
          overflow[w] = 1;
    };
    const uint32_t end = uint32_t(std::min<size_t>(m.frame_count, (w + 1) * kCheckWindow));
    for (uint32_t f = uint32_t(w * kCheckWindow); f < end && !overflow[w]; f += 2) {  // two frames at a time
      const double* row = m.values.data() + size_t(f) * n_ch;
      world_positions(m.skeleton, row, f + 1 < end ? row + n_ch : row, nullptr, a, b);
      check(a), check(b);
    }
  });
  if (std::find(overflow.begin(), overflow.end(), 1) != overflow.end())
    throw Error(ErrorKind::malformed, "joint positions overflow (beyond 1e37 in file units)");
}

ChannelLayout channel_layout(const Skeleton& s, const std::vector<QuatNode>& quats) {
  ChannelLayout out;
  out.node.resize(s.channel_count());
  out.rotation.resize(out.node.size());
  for (size_t j = 0; j < s.joints.size(); ++j) {
    const Joint& joint = s.joints[j];
    for (size_t k = 0; k < joint.channels.size(); ++k) {
      out.node[joint.first_channel + k] = uint32_t(j);
      out.rotation[joint.first_channel + k] = is_rotation(joint.channels[k]);
    }
  }
  out.stored = internal::stored_kinds(s, quats);
  out.quats = quats;
  out.quat_of.assign(out.node.size(), UINT32_MAX);
  for (uint32_t i = 0; i < quats.size(); ++i) {
    const uint32_t c = internal::first_quat_channel(s, quats[i].node);
    out.quat_of[c] = out.quat_of[c + 1] = out.quat_of[c + 2] = i;
  }
  return out;
}

void channel_signal(const Motion& m, const ChannelLayout& layout, uint32_t c, std::vector<double>& out) {
  if (layout.stored[c] != internal::Stored::value) {
    std::array<std::vector<double>, 4> q;
    quat_signals(m, layout.quats[layout.quat_of[c]], q);
    out = std::move(q[size_t(layout.stored[c]) - 1]);
    return;
  }
  const size_t stride = layout.node.size();  // not m.channel_count(): that walks the skeleton
  out.resize(m.frame_count);
  for (uint32_t f = 0; f < m.frame_count; ++f) out[f] = m.values[size_t(f) * stride + c];
  if (layout.rotation[c]) unwrap_degrees(out);
}

Signals::Signals(const Motion& m, const ChannelLayout& layout, size_t budget, unsigned threads)
    : frames_(m.frame_count), budget_(budget) {
  const size_t channels = layout.node.size();
  if (channels == 0 || frames_ == 0 || size_t(frames_) * channels * sizeof(double) > budget) {
    drop_spare<double>();
    return;
  }
  values_ = take_spare<double>();
  values_.resize(size_t(frames_) * channels);
  parallel_for(channels, threads, [&](size_t c, unsigned) {
    if (layout.stored[c] == internal::Stored::quat_x) {  // a quaternion node's three at once
      std::array<std::vector<double>, 4> q;
      quat_signals(m, layout.quats[layout.quat_of[c]], q);
      for (size_t k = 0; k < 3; ++k) std::copy(q[k].begin(), q[k].end(), values_.begin() + ptrdiff_t((c + k) * frames_));
      return;
    }
    if (layout.stored[c] != internal::Stored::value) return;  // y, z: with x
    std::vector<double> column;  // once per channel: not worth a per-thread buffer kept afterwards
    channel_signal(m, layout, uint32_t(c), column);
    std::copy(column.begin(), column.end(), values_.begin() + ptrdiff_t(c * frames_));
  });
}

Signals::~Signals() { give_spare(std::move(values_), budget_); }

void Signals::get(const Motion& m, const ChannelLayout& layout, uint32_t c, std::vector<double>& out) const {
  if (values_.empty()) return channel_signal(m, layout, c, out);
  const double* column = values_.data() + size_t(c) * frames_;
  out.assign(column, column + frames_);
}

void Signals::get_quat(const Motion& m, const ChannelLayout& layout, uint32_t quat,
                       std::array<std::vector<double>, 4>& out) const {
  if (values_.empty()) {
    quat_signals(m, layout.quats[quat], out);
  } else {
    const uint32_t c = internal::first_quat_channel(m.skeleton, layout.quats[quat].node);
    for (uint32_t k = 0; k < 3; ++k) get(m, layout, c + k, out[k]);
  }
  // w rebuilt from x, y, z either way (not quat_signals' own w, which can differ in its last
  // bit): a clip's bytes must not depend on whether its signals fit the budget.
  out[3].resize(out[0].size());
  for (size_t f = 0; f < out[0].size(); ++f) {
    const double x = out[0][f], y = out[1][f], z = out[2][f];
    out[3][f] = std::sqrt(std::max(0.0, 1.0 - (x * x + y * y + z * z)));
  }
}

void unwrap_degrees(std::vector<double>& y) {
  for (size_t f = 1; f < y.size(); ++f) {
    const double d = y[f] - y[f - 1];
    // round(d / 360) is 0 exactly when |d| < 180: skip the libm call then (same result).
    y[f] = std::fabs(d) < 180.0 ? y[f - 1] + d : y[f - 1] + d - 360.0 * std::round(d / 360.0);
  }
}

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

}  // namespace keyanim::offline
