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
  if (first >= last) return;
  const Image::PoseStep* steps = img.pose_steps.data();
  const uint32_t* at = img.pose_first.data();
  const uint32_t column0 = at[first] < at[last] ? steps[at[first]].column : 0;
  float angles[kAngles], sines[kAngles], cosines[kAngles];
  uint32_t node = first;
  while (node < last) {
    // Nodes [node, end) whose rotation channels fit one batch (a node has at most 6 channels).
    uint32_t end = node, count = 0;
    for (; end < last && count + (at[end + 1] - at[end]) <= kAngles; ++end)
      for (uint32_t s = at[end]; s < at[end + 1]; ++s)
        if (steps[s].rotation) angles[count++] = values[steps[s].column - column0];
    half_sincos_deg(angles, sines, cosines, count);
    uint32_t a = 0;
    for (; node < end; ++node) {
      Transform& t = out[node - first];
      t = Transform{};
      const float* offset = img.node_offset.data() + 3 * size_t(node);
      std::copy(offset, offset + 3, t.translation);
      for (uint32_t s = at[node]; s < at[node + 1]; ++s) {
        const Image::PoseStep step = steps[s];
        if (step.rotation) {
          rotate_by(t.rotation, step.axis, sines[a], cosines[a]);
          ++a;
        } else {
          const float v = values[step.column - column0];
          t.translation[step.axis] = reading == PositionReading::add ? offset[step.axis] + v : v;
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
