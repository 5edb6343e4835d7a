#include "offline/encode/rotations.h"

#include <algorithm>
#include <cmath>

#include "internal/quat_layout.h"
#include "keyanim/offline/fk.h"

namespace keyanim::offline {
namespace {

// The largest half-angle from the reference a quaternion node's rotation may reach: w of its
// relative rotation stays at or above cos of it (0.3: rotations up to 145 degrees from the
// reference). Rebuilding w = sqrt(1 - x^2 - y^2 - z^2) turns an error e in x, y, z into about
// e / w in w, so the nodes stored stay within a factor 3.3 of the best case. On the 28 CMU 120
// fps and Bandai 30 fps corpus clips at 0.05%, the total bytes against Euler channels' were
// 0.960 with 0.15, 0.958 with 0.3 and 0.957 with 0.5 (which keeps more joints Euler).
constexpr double kMinRelativeW = 0.3;

double dot(const Quat& a, const Quat& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]; }

Quat normalized(Quat q) {
  const double n = std::sqrt(dot(q, q));
  for (double& x : q) x /= n;
  return q;
}

// conj(ref) * q normalized, on the w >= 0 side: the relative rotation a decoder rebuilds
// (ref * it is q, whatever |ref|, once normalized).
Quat relative(const Quat& ref, const Quat& q) {
  Quat r = normalized(quat_multiply({-ref[0], -ref[1], -ref[2], ref[3]}, q));
  if (r[3] < 0.0)
    for (double& x : r) x = -x;
  return r;
}

Quat reference_quat(const QuatNode& n) {
  double q[4];
  reference_of(n, q);
  return {q[0], q[1], q[2], q[3]};
}

// The smallest w of node j's rotation relative to n's reference over the clip (stopping below
// kMinRelativeW: the node is not taken).
double min_relative_w(const Motion& m, const Joint& joint, const QuatNode& n, size_t stride) {
  const Quat ref = reference_quat(n);
  double min_w = 1.0;
  for (uint32_t f = 0; f < m.frame_count && min_w >= kMinRelativeW; ++f)
    min_w = std::min(min_w, relative(ref, local_quaternion(joint, m.values.data() + size_t(f) * stride))[3]);
  return min_w;
}

// `q` (unit, w >= 0) as a reference: x, y, z in units of 2^-15, within the unit ball.
QuatNode quantized_reference(uint32_t node, const Quat& q) {
  QuatNode n;
  n.node = node;
  for (double scale = 1.0;; scale *= 1.0 - 1.0 / 65536.0) {
    for (int k = 0; k < 3; ++k)
      n.reference[k] = static_cast<int16_t>(std::clamp(std::round(q[size_t(k)] * scale / kReferenceUnit), -32768.0, 32767.0));
    if (internal::valid_reference(n.reference)) return n;
  }
}

// Whether joint's three rotation channels (from its channel `first`) hold one value each over
// the clip (a still joint, a one-frame pose).
bool still_rotation(const Motion& m, const Joint& joint, uint32_t first, size_t stride) {
  const double* row0 = m.values.data() + joint.first_channel + first;
  for (uint32_t f = 1; f < m.frame_count; ++f)
    for (uint32_t k = 0; k < 3; ++k)
      if (row0[size_t(f) * stride + k] != row0[k]) return false;
  return true;
}

}  // namespace

std::vector<QuatNode> choose_quat_nodes(const Motion& m) {
  std::vector<QuatNode> out;
  const size_t stride = m.channel_count();  // once: Motion::frame walks the skeleton
  for (uint32_t j = 0; j < m.skeleton.joints.size(); ++j) {
    const Joint& joint = m.skeleton.joints[j];
    uint32_t first = 0;
    if (!quaternion_capable(joint, &first) || m.frame_count == 0) continue;
    // A still rotation costs three constants either way; as Euler channels it saves the QUAT
    // entry (a one-frame pose of 173 joints: 4,592 bytes as quaternions, 4,296 as Euler).
    if (still_rotation(m, joint, first, stride)) continue;
    // The identity, which costs no bytes, where the rotation stays near the rest pose's
    // (most joints); else the mean of its sign-continuous quaternions (their chordal mean).
    QuatNode n;
    n.node = j;
    if (min_relative_w(m, joint, n, stride) >= kMinRelativeW) {
      out.push_back(n);
      continue;
    }
    Quat sum{0, 0, 0, 0}, prev{0, 0, 0, 1};
    for (uint32_t f = 0; f < m.frame_count; ++f) {
      Quat q = local_quaternion(joint, m.values.data() + size_t(f) * stride);
      if (dot(q, prev) < 0.0)
        for (double& x : q) x = -x;
      for (int k = 0; k < 4; ++k) sum[size_t(k)] += q[size_t(k)];
      prev = q;
    }
    if (!(dot(sum, sum) > 0.0)) continue;
    Quat mean = normalized(sum);
    if (mean[3] < 0.0)
      for (double& x : mean) x = -x;
    n = quantized_reference(j, mean);
    if (min_relative_w(m, joint, n, stride) >= kMinRelativeW) out.push_back(n);
  }
  return out;
}

void quat_signals(const Motion& m, const QuatNode& n, std::array<std::vector<double>, 4>& out) {
  const Joint& joint = m.skeleton.joints[n.node];
  const Quat ref = reference_quat(n);
  for (auto& v : out) v.resize(m.frame_count);
  const size_t stride = m.channel_count();
  for (uint32_t f = 0; f < m.frame_count; ++f) {
    const Quat r = relative(ref, local_quaternion(joint, m.values.data() + size_t(f) * stride));
    for (size_t k = 0; k < 4; ++k) out[k][f] = r[k];
  }
}

}  // namespace keyanim::offline

namespace keyanim::offline {

void stored_row(const Motion& m, const QuatForms& quats, uint32_t f, double* out) {
  const size_t stride = m.values.size() / std::max<size_t>(m.frame_count, 1);
  const double* row = m.values.data() + size_t(f) * stride;
  std::copy(row, row + stride, out);
  for (size_t i = 0; i < quats.reference.size(); ++i) {
    const Quat r = relative(quats.reference[i], local_quaternion(m.skeleton.joints[quats.node[i]], row));
    for (size_t k = 0; k < 3; ++k) out[quats.column[i] + k] = r[k];
  }
}

}  // namespace keyanim::offline
