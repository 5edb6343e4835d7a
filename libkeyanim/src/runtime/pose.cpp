// Euler channels to quaternions, translations, and forward kinematics in binary32. The rules
// are those of spec/FORMAT.md Appendix B (the encoder's forward kinematics): a node's rotation
// is the product of its rotation channels in their order (intrinsic), R = R_1 R_2 R_3; as
// quaternions q = q_1 q_2 q_3 with q_axis(a) = (sin(a/2) axis, cos(a/2)).
#include "runtime/pose.h"

#include <algorithm>

#include "internal/trig.h"

namespace keyanim::internal {
namespace {

// q = q * (rotation by the angle whose half has sine s and cosine c about `axis`).
inline void rotate_by(float* q, int axis, float s, float c) noexcept {
  const float x = q[0], y = q[1], z = q[2], w = q[3];
  switch (axis) {
    case 0: q[0] = w * s + x * c, q[1] = y * c + z * s, q[2] = z * c - y * s, q[3] = w * c - x * s; break;
    case 1: q[0] = x * c - z * s, q[1] = w * s + y * c, q[2] = z * c + x * s, q[3] = w * c - y * s; break;
    default: q[0] = x * c + y * s, q[1] = y * c - x * s, q[2] = w * s + z * c, q[3] = w * c - z * s; break;
  }
}

// v rotated by unit quaternion q: v + 2 w (u x v) + 2 u x (u x v), u = q.xyz.
inline void rotate_vector(const float* q, const float* v, float* out) noexcept {
  const float tx = 2.0f * (q[1] * v[2] - q[2] * v[1]);
  const float ty = 2.0f * (q[2] * v[0] - q[0] * v[2]);
  const float tz = 2.0f * (q[0] * v[1] - q[1] * v[0]);
  out[0] = v[0] + q[3] * tx + (q[1] * tz - q[2] * ty);
  out[1] = v[1] + q[3] * ty + (q[2] * tx - q[0] * tz);
  out[2] = v[2] + q[3] * tz + (q[0] * ty - q[1] * tx);
}

// a * b (Hamilton product).
inline void multiply(const float* a, const float* b, float* out) noexcept {
  const float x = a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1];
  const float y = a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0];
  const float z = a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3];
  const float w = a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2];
  out[0] = x, out[1] = y, out[2] = z, out[3] = w;
}

constexpr uint32_t kAngles = 64;  // rotation channels converted per batch

}  // namespace

void local_transforms(const Image& img, uint32_t first, uint32_t last, const float* values, PositionReading reading,
                      Transform* out) noexcept {
  const auto& joints = img.skeleton.joints;
  const uint32_t column0 = first < last ? joints[first].first_channel : 0;
  float angles[kAngles], sines[kAngles], cosines[kAngles];
  uint32_t node = first;
  while (node < last) {
    // Nodes [node, end) whose rotation channels fit one batch (a node has at most 6 channels).
    uint32_t end = node, count = 0;
    for (; end < last; ++end) {
      uint32_t r = 0;
      for (ChannelType t : joints[end].channels) r += is_rotation(t);
      if (count + r > kAngles) break;
      for (size_t k = 0; k < joints[end].channels.size(); ++k)
        if (is_rotation(joints[end].channels[k])) angles[count++] = values[joints[end].first_channel + k - column0];
    }
    half_sincos_deg(angles, sines, cosines, count);
    uint32_t a = 0;
    for (; node < end; ++node) {
      const Joint& j = joints[node];
      Transform& t = out[node - first];
      t = Transform{};
      const float* offset = img.node_offset.data() + 3 * size_t(node);
      std::copy(offset, offset + 3, t.translation);
      for (size_t k = 0; k < j.channels.size(); ++k) {
        const ChannelType type = j.channels[k];
        const int axis = channel_axis(type);
        if (is_rotation(type)) {
          rotate_by(t.rotation, axis, sines[a], cosines[a]);
          ++a;
        } else {
          const float v = values[j.first_channel + k - column0];
          t.translation[axis] = reading == PositionReading::add ? offset[axis] + v : v;
        }
      }
    }
  }
}

void compose_model(const Image& img, Transform* out) noexcept {
  const auto& joints = img.skeleton.joints;
  for (size_t i = 0; i < joints.size(); ++i) {
    const int32_t p = joints[i].parent;
    if (p < 0) continue;  // parents come first: out[p] is already in model space
    const Transform& parent = out[p];
    Transform& t = out[i];
    float moved[3], q[4];
    rotate_vector(parent.rotation, t.translation, moved);
    multiply(parent.rotation, t.rotation, q);
    for (int k = 0; k < 3; ++k) t.translation[k] = parent.translation[k] + moved[k];
    std::copy(q, q + 4, t.rotation);
  }
}

}  // namespace keyanim::internal
