// Euler channels to quaternions, translations, and forward kinematics in binary32. The rules
// are those of spec/FORMAT.md Appendix B (the encoder's forward kinematics): a node's rotation
// is the product of its rotation channels in their order (intrinsic), R = R_1 R_2 R_3; as
// quaternions q = q_1 q_2 q_3 with q_axis(a) = (sin(a/2) axis, cos(a/2)).
#include "runtime/pose.h"

#include <algorithm>

#include "internal/trig.h"

namespace keyanim::internal {
namespace {

// q * (rotation about `axis` by the angle whose half has sine s and cosine c), q = (x, y, z, w):
// each component is one product with c plus one signed product with s,
//   X: (x c + w s, y c + z s, z c - y s, w c - x s)
//   Y: (x c - z s, y c + w s, z c + x s, w c - y s)
//   Z: (x c + y s, y c - x s, z c + w s, w c - z s).
#if KEYANIM_SSE2
// In one register: q c + t s, t a signed permutation of q per axis. The products and sums are
// those above (a + (-b) is a - b, and addition commutes), so the bits are the scalar twin's
// (tests/scalar checks it).
[[gnu::always_inline]] inline __m128 rotate_by(__m128 q, uint32_t axis, float s, float c) noexcept {
  const __m128 neg23 = _mm_castsi128_ps(_mm_set_epi32(INT32_MIN, INT32_MIN, 0, 0));
  const __m128 neg03 = _mm_castsi128_ps(_mm_set_epi32(INT32_MIN, 0, 0, INT32_MIN));
  const __m128 neg13 = _mm_castsi128_ps(_mm_set_epi32(INT32_MIN, 0, INT32_MIN, 0));
  __m128 t;
  switch (axis) {
    case 0: t = _mm_xor_ps(_mm_shuffle_ps(q, q, _MM_SHUFFLE(0, 1, 2, 3)), neg23); break;   // (w, z, -y, -x)
    case 1: t = _mm_xor_ps(_mm_shuffle_ps(q, q, _MM_SHUFFLE(1, 0, 3, 2)), neg03); break;   // (-z, w, x, -y)
    default: t = _mm_xor_ps(_mm_shuffle_ps(q, q, _MM_SHUFFLE(2, 3, 0, 1)), neg13); break;  // (y, -x, w, -z)
  }
  return _mm_add_ps(_mm_mul_ps(q, _mm_set1_ps(c)), _mm_mul_ps(t, _mm_set1_ps(s)));
}
#else
inline void rotate_by(float* q, uint32_t axis, float s, float c) noexcept {
  const float x = q[0], y = q[1], z = q[2], w = q[3];
  switch (axis) {
    case 0: q[0] = x * c + w * s, q[1] = y * c + z * s, q[2] = z * c - y * s, q[3] = w * c - x * s; break;
    case 1: q[0] = x * c - z * s, q[1] = y * c + w * s, q[2] = z * c + x * s, q[3] = w * c - y * s; break;
    default: q[0] = x * c + y * s, q[1] = y * c - x * s, q[2] = z * c + w * s, q[3] = w * c - z * s; break;
  }
}
#endif

// Node `node`'s rotation, its angles' half sines and cosines at s[k - base], c[k - base].
inline void node_rotation(const Image& img, uint32_t node, uint32_t base, const float* s, const float* c,
                          float* rotation) noexcept {
  const uint8_t* axis = img.rot_axis.data();
  const uint32_t begin = img.rot_first[node], end = img.rot_first[node + 1];
#if KEYANIM_SSE2
  __m128 q = _mm_set_ps(1.0f, 0.0f, 0.0f, 0.0f);
  for (uint32_t k = begin; k < end; ++k) q = rotate_by(q, axis[k], s[k - base], c[k - base]);
  _mm_storeu_ps(rotation, q);
#else
  rotation[0] = rotation[1] = rotation[2] = 0.0f, rotation[3] = 1.0f;
  for (uint32_t k = begin; k < end; ++k) rotate_by(rotation, axis[k], s[k - base], c[k - base]);
#endif
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

constexpr uint32_t kAngles = 64;  // rotation channels converted per batch (>= 6, a node's most)

}  // namespace

void local_transforms(const Image& img, uint32_t first, uint32_t last, const float* values, PositionReading reading,
                      Transform* out) noexcept {
  if (first >= last) return;
  const uint32_t column0 = img.skeleton.joints[first].first_channel;  // values[0]'s column
  const uint32_t* rot_first = img.rot_first.data();
  const uint32_t* rot_column = img.rot_column.data();
  alignas(16) float angles[kAngles], sines[kAngles], cosines[kAngles];
  for (uint32_t node = first; node < last;) {
    // Nodes [node, end) whose rotation channels fit one batch: one gather, one conversion.
    const uint32_t base = rot_first[node];
    uint32_t end = node + 1;
    while (end < last && rot_first[end + 1] - base <= kAngles) ++end;
    const uint32_t count = rot_first[end] - base;
    for (uint32_t k = 0; k < count; ++k) angles[k] = values[rot_column[base + k] - column0];
    half_sincos_deg(angles, sines, cosines, count);
    for (; node < end; ++node) {
      Transform& t = out[node - first];
      const float* offset = img.node_offset.data() + 3 * size_t(node);
      t.translation[0] = offset[0], t.translation[1] = offset[1], t.translation[2] = offset[2];
      t.reserved = 0.0f;
      for (uint32_t m = img.move_first[node]; m < img.move_first[node + 1]; ++m) {
        const Image::Move move = img.moves[m];
        const float v = values[move.column - column0];
        t.translation[move.axis] = reading == PositionReading::add ? offset[move.axis] + v : v;
      }
      node_rotation(img, node, base, sines, cosines, t.rotation);
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
