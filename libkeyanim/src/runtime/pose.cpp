// Stored values to quaternions, translations, and forward kinematics in binary32. The rules
// are those of spec/FORMAT.md Appendix B (the encoder's forward kinematics): an Euler node's
// rotation is the product of its rotation channels in their order (intrinsic), R = R_1 R_2
// R_3; as quaternions q = q_1 q_2 q_3 with q_axis(a) = (sin(a/2) axis, cos(a/2)). A quaternion
// node's (version 5) is its reference times (x, y, z, w), w rebuilt, normalized
// (keyanim/rotation.h's stored_rotation, 4 or 8 nodes a register).
#include "runtime/pose.h"

#include <algorithm>
#include <cstddef>
#include <cstring>

#include "internal/cpu.h"
#include "internal/prefetch.h"
#include "internal/trig.h"
#include "keyanim/rotation.h"
#include "runtime/quat_lanes.h"

namespace keyanim::internal {
namespace {

// q * (rotation about `axis` by the angle whose half has sine s and cosine c), q = (x, y, z, w):
// each component is one product with c plus one signed product with s,
//   X: (x c + w s, y c + z s, z c - y s, w c - x s)
//   Y: (x c - z s, y c + w s, z c + x s, w c - y s)
//   Z: (x c + y s, y c - x s, z c + w s, w c - z s).
// The axis is the same in every lane (a group's), so the choice is made once for all lanes.
template <class V>
KEYANIM_INLINE inline QuatLanes<V> rotate_by(const QuatLanes<V>& q, uint32_t axis, const V& s, const V& c) noexcept {
  switch (axis) {
    case 0: return {q.x * c + q.w * s, q.y * c + q.z * s, q.z * c - q.y * s, q.w * c - q.x * s};
    case 1: return {q.x * c - q.z * s, q.y * c + q.w * s, q.z * c + q.x * s, q.w * c - q.y * s};
    default: return {q.x * c + q.y * s, q.y * c - q.x * s, q.z * c + q.w * s, q.w * c - q.z * s};
  }
}

// The values of `lanes` nodes (the rest 0) at their columns, values[column[l] - column0],
// gathered into registers (the first parameter only picks the register type: F4 or F8).
KEYANIM_INLINE inline F4 gather_lanes(const F4*, const float* values, const uint32_t* column, uint32_t column0,
                                      uint32_t lanes) noexcept {
  auto angle = [&](uint32_t l) KEYANIM_INLINE { return l < lanes ? values[column[l] - column0] : 0.0f; };
  return F4::set(angle(0), angle(1), angle(2), angle(3));
}
#if KEYANIM_WIDE_LANES
KEYANIM_INLINE inline F8 gather_lanes(const F8*, const float* values, const uint32_t* column, uint32_t column0,
                                      uint32_t lanes) noexcept {
  auto angle = [&](uint32_t l) KEYANIM_INLINE { return l < lanes ? values[column[l] - column0] : 0.0f; };
  return F8(V8f{angle(0), angle(1), angle(2), angle(3), angle(4), angle(5), angle(6), angle(7)});
}
#endif

// The rotations of `lanes` nodes of a group from its node i, in the registers of one V.
template <class V>
KEYANIM_INLINE inline void lane_rotations(const EulerGroups& eg, const EulerGroups::Group& g, uint32_t i, uint32_t lanes,
                                          const float* values, uint32_t column0, uint32_t first,
                                          Transform* out) noexcept {
  QuatLanes<V> q{V(0.0f), V(0.0f), V(0.0f), V(1.0f)};
  for (uint32_t k = 0; k < g.steps; ++k) {
    const uint32_t* column = eg.column.data() + g.column_first + size_t(k) * g.node_count + i;
    V s, c;
    half_sincos_deg(gather_lanes(static_cast<const V*>(nullptr), values, column, column0, lanes), s, c);
    q = rotate_by(q, g.axis[k], s, c);
  }
  store_rotations(q, eg.node.data() + g.node_first + i, first, lanes, out);
}

// The rotations of a group's nodes [begin, end) (indices into the group), out[node - first]:
// 8 at a time when kWide while more than 4 are left, then 4.
template <bool kWide>
KEYANIM_INLINE inline void group_rotations(const EulerGroups& eg, const EulerGroups::Group& g, uint32_t begin,
                                           uint32_t end, const float* values, uint32_t column0, uint32_t first,
                                           Transform* out) noexcept {
  for (uint32_t i = begin; i < end;) {
    const uint32_t left = end - i;
#if KEYANIM_WIDE_LANES
    if (kWide && left > 4) {
      lane_rotations<F8>(eg, g, i, std::min(8u, left), values, column0, first, out);
      i += 8;
      continue;
    }
#endif
    lane_rotations<F4>(eg, g, i, std::min(4u, left), values, column0, first, out);
    i += 4;
  }
}

// Quaternion nodes i .. i + lanes - 1 (of the image's, lanes <= V's) from their stored x, y, z
// in `values`: gathered into registers (padding lanes read zeros), then store_quat_rotations.
template <class V>
KEYANIM_INLINE inline void quat_lane_rotations(const Image& img, uint32_t i, uint32_t lanes, const float* values,
                                               uint32_t column0, uint32_t first, Transform* out) noexcept {
  const uint32_t* column = img.quat_column.data() + i;
  V xyz[3];
  for (uint32_t k = 0; k < 3; ++k)  // column[l] + k's value: unsigned, column[l] - (column0 - k) is that
    xyz[k] = gather_lanes(static_cast<const V*>(nullptr), values, column, column0 - k, lanes);
  store_quat_rotations(img, i, lanes, xyz[0], xyz[1], xyz[2], first, out);
}

// The rotations of the image's quaternion nodes [begin, end) (indices into its quaternion
// arrays), out[node - first]: 8 at a time when kWide while more than 4 are left, then 4.
template <bool kWide>
KEYANIM_INLINE inline void quat_rotations(const Image& img, uint32_t begin, uint32_t end, const float* values,
                                          uint32_t column0, uint32_t first, Transform* out) noexcept {
  for (uint32_t i = begin; i < end;) {
    const uint32_t left = end - i;
#if KEYANIM_WIDE_LANES
    if (kWide && left > 4) {
      quat_lane_rotations<F8>(img, i, std::min(8u, left), values, column0, first, out);
      i += 8;
      continue;
    }
#endif
    quat_lane_rotations<F4>(img, i, std::min(4u, left), values, column0, first, out);
    i += 4;
  }
}

// The first index of `sorted` (ascending, n entries) whose value is >= x.
KEYANIM_INLINE inline uint32_t lower_index(const uint32_t* sorted, uint32_t n, uint32_t x) noexcept {
  return static_cast<uint32_t>(std::lower_bound(sorted, sorted + n, x) - sorted);
}

#if KEYANIM_SSE2
// The products and sums of the scalar twins below, in their order, lanes x, y, z (w): a - b is
// a + (-b) and (-a) b is -(a b) exactly, so the bits are the scalar twins' (tests/scalar).
template <int a, int b, int c, int d>
KEYANIM_INLINE inline __m128 shuffle(__m128 v) noexcept {
  return _mm_shuffle_ps(v, v, _MM_SHUFFLE(d, c, b, a));
}
KEYANIM_INLINE inline __m128 flip(__m128 v, bool x, bool y, bool z, bool w) noexcept {
  return _mm_xor_ps(v, _mm_castsi128_ps(_mm_set_epi32(w ? INT32_MIN : 0, z ? INT32_MIN : 0, y ? INT32_MIN : 0,
                                                      x ? INT32_MIN : 0)));
}
KEYANIM_INLINE inline __m128 multiply(__m128 a, __m128 b) noexcept {
  const __m128 t1 = _mm_mul_ps(shuffle<3, 3, 3, 3>(a), b);
  const __m128 t2 = _mm_mul_ps(shuffle<0, 0, 0, 0>(a), flip(shuffle<3, 2, 1, 0>(b), false, true, false, true));
  const __m128 t3 = _mm_mul_ps(shuffle<1, 1, 1, 1>(a), flip(shuffle<2, 3, 0, 1>(b), false, false, true, true));
  const __m128 t4 = _mm_mul_ps(shuffle<2, 2, 2, 2>(a), flip(shuffle<1, 0, 3, 2>(b), true, false, false, true));
  return _mm_add_ps(_mm_add_ps(_mm_add_ps(t1, t2), t3), t4);
}
KEYANIM_INLINE inline __m128 rotate_vector(__m128 q, __m128 v) noexcept {
  const __m128 cross = _mm_sub_ps(_mm_mul_ps(shuffle<1, 2, 0, 3>(q), shuffle<2, 0, 1, 3>(v)),
                                  _mm_mul_ps(shuffle<2, 0, 1, 3>(q), shuffle<1, 2, 0, 3>(v)));
  const __m128 t = _mm_mul_ps(_mm_set1_ps(2.0f), cross);
  const __m128 turn = _mm_sub_ps(_mm_mul_ps(shuffle<1, 2, 0, 3>(q), shuffle<2, 0, 1, 3>(t)),
                                 _mm_mul_ps(shuffle<2, 0, 1, 3>(q), shuffle<1, 2, 0, 3>(t)));
  return _mm_add_ps(_mm_add_ps(v, _mm_mul_ps(shuffle<3, 3, 3, 3>(q), t)), turn);
}
#else
// v rotated by unit quaternion q: v + 2 w (u x v) + 2 u x (u x v), u = q.xyz.
KEYANIM_INLINE inline void rotate_vector(const float* q, const float* v, float* out) noexcept {
  const float tx = 2.0f * (q[1] * v[2] - q[2] * v[1]);
  const float ty = 2.0f * (q[2] * v[0] - q[0] * v[2]);
  const float tz = 2.0f * (q[0] * v[1] - q[1] * v[0]);
  out[0] = v[0] + q[3] * tx + (q[1] * tz - q[2] * ty);
  out[1] = v[1] + q[3] * ty + (q[2] * tx - q[0] * tz);
  out[2] = v[2] + q[3] * tz + (q[0] * ty - q[1] * tx);
}

// a * b (Hamilton product).
KEYANIM_INLINE inline void multiply(const float* a, const float* b, float* out) noexcept {
  const float x = a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1];
  const float y = a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0];
  const float z = a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3];
  const float w = a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2];
  out[0] = x, out[1] = y, out[2] = z, out[3] = w;
}
#endif

static_assert(offsetof(Transform, reserved) == offsetof(Transform, translation) + 3 * sizeof(float),
              "a node's translation and reserved are one 4-float copy of Rig::node_offset");

template <bool kWide>
KEYANIM_INLINE inline void local_impl(const Image& img, uint32_t first, uint32_t last, const float* values,
                                     PositionReading reading, Transform* out, bool tracks_done) noexcept {
  const Rig& rig = *img.rig;
  const uint32_t column0 = rig.skeleton.joints[first].first_channel;  // values[0]'s column
  // Translations: OFFSETs (and reserved = 0), then the position channels.
  for (uint32_t node = first; node < last; ++node)
    std::memcpy(out[node - first].translation, rig.node_offset.data() + 4 * size_t(node), 4 * sizeof(float));
  // A whole pose (the usual call) needs no search for where its nodes start and end.
  const bool whole = first == 0 && last == rig.skeleton.joints.size();
  const Rig::Move* moves = rig.moves.data();
  const auto by_node = [](const Rig::Move& m, uint32_t node) { return m.node < node; };
  const Rig::Move* m = whole ? moves : std::lower_bound(moves, moves + rig.moves.size(), first, by_node);
  for (; m != moves + rig.moves.size() && m->node < last; ++m) {
    const float v = values[m->column - column0];
    float& t = out[m->node - first].translation[m->axis];
    t = reading == PositionReading::add ? rig.node_offset[4 * size_t(m->node) + m->axis] + v : v;
  }
  // Rotations, group by group: the group's nodes in [first, last).
  const EulerGroups& eg = *img.euler;
  for (const EulerGroups::Group& g : eg.groups) {
    const uint32_t* node = eg.node.data() + g.node_first;
    const uint32_t begin = whole ? 0 : lower_index(node, g.node_count, first);
    const uint32_t end = whole ? g.node_count : lower_index(node, g.node_count, last);
    group_rotations<kWide>(eg, g, begin, end, values, column0, first, out);
  }
  // The quaternion nodes: the tracks, then the others, each group in node order.
  const uint32_t groups[3] = {0, img.quat_tracks, static_cast<uint32_t>(img.quat_node.size())};
  for (int g = tracks_done ? 1 : 0; g < 2; ++g) {
    const uint32_t* node = img.quat_node.data() + groups[g];
    const uint32_t n = groups[g + 1] - groups[g];
    const uint32_t begin = whole ? 0 : lower_index(node, n, first);
    const uint32_t end = whole ? n : lower_index(node, n, last);
    quat_rotations<kWide>(img, groups[g] + begin, groups[g] + end, values, column0, first, out);
  }
}

KEYANIM_INLINE inline void compose_impl(const Image& img, Transform* out) noexcept {
  const auto& joints = img.rig->skeleton.joints;
  for (size_t i = 0; i < joints.size(); ++i) {
    const int32_t p = joints[i].parent;
    if (p < 0) continue;  // parents come first: out[p] is already in model space
    const Transform& parent = out[p];
    Transform& t = out[i];
#if KEYANIM_SSE2
    const __m128 pq = _mm_loadu_ps(parent.rotation);
    const __m128 moved = rotate_vector(pq, _mm_loadu_ps(t.translation));  // lane 3: reserved's, dropped
    const __m128 keep3 = _mm_castsi128_ps(_mm_set_epi32(0, -1, -1, -1));
    _mm_storeu_ps(t.translation, _mm_and_ps(_mm_add_ps(_mm_loadu_ps(parent.translation), moved), keep3));
    _mm_storeu_ps(t.rotation, multiply(pq, _mm_loadu_ps(t.rotation)));
#else
    float moved[3], q[4];
    rotate_vector(parent.rotation, t.translation, moved);
    multiply(parent.rotation, t.rotation, q);
    for (int k = 0; k < 3; ++k) t.translation[k] = parent.translation[k] + moved[k];
    std::copy(q, q + 4, t.rotation);
#endif
  }
}

// One copy per CPU level (internal/cpu.h), 8 lanes at v3.
KEYANIM_V3_TARGET void local_v3(const Image& img, uint32_t first, uint32_t last, const float* values,
                                PositionReading reading, Transform* out, bool tracks_done) noexcept {
  local_impl<KEYANIM_WIDE_LANES != 0>(img, first, last, values, reading, out, tracks_done);
}
void local_plain(const Image& img, uint32_t first, uint32_t last, const float* values, PositionReading reading,
                 Transform* out, bool tracks_done) noexcept {
  local_impl<false>(img, first, last, values, reading, out, tracks_done);
}
KEYANIM_V3_TARGET void compose_v3(const Image& img, Transform* out) noexcept { compose_impl(img, out); }
void compose_plain(const Image& img, Transform* out) noexcept { compose_impl(img, out); }

}  // namespace

void local_transforms(const Image& img, uint32_t first, uint32_t last, const float* values, PositionReading reading,
                      Transform* out, bool tracks_done) noexcept {
  if (first >= last) return;
  cpu_level() == CpuLevel::v3 ? local_v3(img, first, last, values, reading, out, tracks_done)
                              : local_plain(img, first, last, values, reading, out, tracks_done);
}

void prefetch_pose_tables(const Image& img, Transform* out, uint32_t nodes) noexcept {
  const Rig& rig = *img.rig;
  prefetch_array(img.euler->groups.data(), img.euler->groups.size());
  prefetch_array(img.euler->column.data(), img.euler->column.size());
  prefetch_array(img.euler->node.data(), img.euler->node.size());
  prefetch_array(rig.node_offset.data(), rig.node_offset.size());
  prefetch_array(rig.moves.data(), rig.moves.size());
  prefetch_array<true>(out, nodes);
}

void compose_model(const Image& img, Transform* out) noexcept {
  cpu_level() == CpuLevel::v3 ? compose_v3(img, out) : compose_plain(img, out);
}

}  // namespace keyanim::internal
