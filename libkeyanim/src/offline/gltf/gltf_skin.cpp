// The skin and its bone mesh (gltf_skin.h).
#include "gltf_skin.h"

#include <array>
#include <cmath>

namespace keyanim::offline::gltf {
namespace {

using V = std::array<double, 3>;

constexpr double kRingAt = 0.1;      // of the bone's length, from its head
constexpr double kRingRadius = 0.1;  // of the bone's length
constexpr double kPi = 3.14159265358979323846;

V cross(const V& a, const V& b) { return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}; }
V scaled(const V& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
double norm(const V& a) { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }

bool has_parent(const Skeleton& sk, size_t j) { return sk.joints[j].parent >= 0 && size_t(sk.joints[j].parent) < j; }

// Rest world positions: OFFSETs added down the hierarchy (parents come first).
std::vector<V> rest_positions(const Skeleton& sk) {
  std::vector<V> w(sk.joints.size());
  for (size_t j = 0; j < sk.joints.size(); ++j) {
    const V base = has_parent(sk, j) ? w[size_t(sk.joints[j].parent)] : V{0, 0, 0};
    for (int a = 0; a < 3; ++a) w[j][size_t(a)] = base[size_t(a)] + sk.joints[j].offset[size_t(a)];
  }
  return w;
}

void add_vertex(Skin& s, const V& at, uint32_t node) {
  for (double x : at) s.positions.push_back(float(x));
  s.joints.push_back(node);
}

// One bipyramid from head (following node p) to tail (following node n): vertices head, tail,
// then the ring counter-clockwise about the bone's direction; faces wound outwards.
void add_bone(Skin& s, const V& head, const V& tail, uint32_t p, uint32_t n) {
  const V d = {tail[0] - head[0], tail[1] - head[1], tail[2] - head[2]};
  const double length = norm(d);
  const V axis = scaled(d, 1.0 / length);
  // A direction across the bone: the world axis least along it, crossed with it.
  int least = 0;
  for (int a = 1; a < 3; ++a)
    if (std::fabs(axis[size_t(a)]) < std::fabs(axis[size_t(least)])) least = a;
  V e{0, 0, 0};
  e[size_t(least)] = 1;
  V u = cross(axis, e);
  u = scaled(u, 1.0 / norm(u));
  const V v = cross(axis, u);
  const uint32_t base = uint32_t(s.joints.size());
  add_vertex(s, head, p);
  add_vertex(s, tail, n);
  for (int k = 0; k < 3; ++k) {
    const double angle = 2.0 * kPi * k / 3.0, r = kRingRadius * length;
    V at;
    for (int a = 0; a < 3; ++a)
      at[size_t(a)] = head[size_t(a)] + kRingAt * d[size_t(a)] + r * (std::cos(angle) * u[size_t(a)] + std::sin(angle) * v[size_t(a)]);
    add_vertex(s, at, p);
  }
  for (uint32_t k = 0; k < 3; ++k) {
    const uint32_t a = base + 2 + k, b = base + 2 + (k + 1) % 3;
    s.indices.insert(s.indices.end(), {a, b, base + 1});  // towards the tail
    s.indices.insert(s.indices.end(), {b, a, base});      // towards the head
  }
}

}  // namespace

Skin make_skin(const Skeleton& sk) {
  Skin s;
  const std::vector<V> rest = rest_positions(sk);
  for (const V& w : rest) {
    const float column_major[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, float(-w[0]), float(-w[1]), float(-w[2]), 1};
    s.inverse_binds.insert(s.inverse_binds.end(), column_major, column_major + 16);
  }
  for (size_t n = 0; n < sk.joints.size(); ++n) {
    if (!has_parent(sk, n) || norm(sk.joints[n].offset) == 0.0) continue;
    const size_t p = size_t(sk.joints[n].parent);
    add_bone(s, rest[p], rest[n], uint32_t(p), uint32_t(n));
  }
  return s;
}

}  // namespace keyanim::offline::gltf
