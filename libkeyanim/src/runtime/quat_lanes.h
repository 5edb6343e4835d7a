// Quaternions in SIMD lanes, one component per register (4 nodes with F4, 8 with F8 in the AVX2
// copies): a quaternion node's rotation from its stored x, y, z (keyanim/rotation.h), and the
// stores of each lane's quaternion to its node's Transform. Shared by pose.cpp and
// quat_tracks.cpp; internal linkage, so that each file's copies compiled for a CPU level stay
// its own.
#pragma once
#include <algorithm>
#include <cstdint>

#include "internal/cpu.h"
#include "internal/simd.h"
#include "internal/simd8.h"
#include "keyanim/pose.h"
#include "keyanim/rotation.h"
#include "runtime/image.h"

namespace keyanim::internal {
namespace {

// Four (F4) or eight (F8: the AVX2 copy) nodes' rotations, one component per register: lane i
// is node i's quaternion.
template <class V>
struct QuatLanes {
  V x, y, z, w;
};

// Each lane's quaternion to its node's Transform, out[node - first].
KEYANIM_INLINE inline void store_rotations(QuatLanes<F4> q, const uint32_t* node, uint32_t first, uint32_t lanes,
                                           Transform* out) noexcept {
  transpose(q.x, q.y, q.z, q.w);  // now lane rows: node 0's (x, y, z, w) in q.x, node 1's in q.y, ...
  const F4* row[4] = {&q.x, &q.y, &q.z, &q.w};
  for (uint32_t l = 0; l < lanes; ++l) row[l]->store(out[node[l] - first].rotation);
}
#if KEYANIM_WIDE_LANES
KEYANIM_INLINE inline void store_rotations(const QuatLanes<F8>& q, const uint32_t* node, uint32_t first,
                                           uint32_t lanes, Transform* out) noexcept {
  store_rotations(QuatLanes<F4>{q.x.low(), q.y.low(), q.z.low(), q.w.low()}, node, first, std::min(lanes, 4u), out);
  if (lanes > 4)
    store_rotations(QuatLanes<F4>{q.x.high(), q.y.high(), q.z.high(), q.w.high()}, node + 4, first, lanes - 4, out);
}
#endif

// The rotations of the image's quaternion nodes i .. i + lanes - 1 (lanes <= V's) from their
// stored x, y, z in registers: stored_rotation in every lane, out[node - first]. Lanes past
// `lanes` are computed and not stored: their references are the identity padding, or, where
// i + V's lanes passes quat_lanes (i need not be a multiple of 4 in a partial pose), the next
// row's floats and, for the w row, up to 7 floats after Quat_Reference. Those lie inside IMAG,
// whose Record_Offset array follows with a tail of 8 entries (asserted below), so no load
// leaves the image's bytes, and no branch is taken per group for it.
template <class V>
KEYANIM_INLINE inline void store_quat_rotations(const Image& img, uint32_t i, uint32_t lanes, const V& x, const V& y,
                                                const V& z, uint32_t first, Transform* out) noexcept {
  static_assert(sizeof(V) - sizeof(float) <= 4 * kImageTailEntries, "a w-row load may pass Quat_Reference's end");
  const float* ref = img.quat_reference.data() + i;
  const V r[4] = {V::load(ref), V::load(ref + img.quat_lanes), V::load(ref + 2 * size_t(img.quat_lanes)),
                  V::load(ref + 3 * size_t(img.quat_lanes))};
  V q[4];
  stored_rotation<V>(r, x, y, z, q, [](V a) KEYANIM_INLINE { return sqrt_lanes(a); },
                     [](V a) KEYANIM_INLINE { return max0(a); });
  store_rotations(QuatLanes<V>{q[0], q[1], q[2], q[3]}, img.quat_node.data() + i, first, lanes, out);
}

}  // namespace
}  // namespace keyanim::internal
