// An independent forward kinematics for the tests: the points a skinned mesh sees (joints, End
// Sites, and three shell points per joint at distance d along its local x, y and z axes), in
// long double, written from spec/FORMAT.md Appendix B without the library's fk.h, so that the
// error the encoder guarantees is checked by code that shares nothing with it. (It takes the
// Skeleton and PositionReading types from the runtime's headers: data, not arithmetic.)
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "keyanim/pose.h"
#include "keyanim/skeleton.h"

namespace keyanim::test {

using LVec = std::array<long double, 3>;
using LMat = std::array<std::array<long double, 3>, 3>;  // rows

// Position channels on a node: Blender replaces the OFFSET component, three.js adds the value
// to it (keyanim::PositionReading).
using Reading = keyanim::PositionReading;

inline LMat lmul(const LMat& a, const LMat& b) {
  LMat r{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) r[i][j] += a[i][k] * b[k][j];
  return r;
}

inline LVec lapply(const LMat& m, const LVec& v) {
  return {m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2], m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
          m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2]};
}

// The right-handed rotation by `deg` degrees about axis 0 (X), 1 (Y) or 2 (Z).
inline LMat axis_rotation(int axis, long double deg) {
  const long double r = deg * 3.14159265358979323846264338327950288L / 180.0L;
  const long double c = std::cos(r), s = std::sin(r);
  LMat m{};
  m[axis][axis] = 1;
  const int a = (axis + 1) % 3, b = (axis + 2) % 3;
  m[a][a] = c, m[a][b] = -s, m[b][a] = s, m[b][b] = c;
  return m;
}

// Every measured point of one frame row of channel values: per node its position (joints and
// End Sites), then per joint (not End Site) three shell points. `shell` = 0: no shell points.
inline std::vector<LVec> measured_points(const Skeleton& sk, const double* row, long double shell, Reading reading) {
  const size_t n = sk.joints.size();
  std::vector<LVec> pos(n);
  std::vector<LMat> rot(n);
  uint32_t column = 0;  // channels in node order (Appendix B)
  for (size_t i = 0; i < n; ++i) {
    const Joint& j = sk.joints[i];
    LVec t = {j.offset[0], j.offset[1], j.offset[2]};
    LMat r = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
    for (ChannelType c : j.channels) {
      const long double v = row[column++];
      const int axis = static_cast<int>(c) % 3;
      if (static_cast<int>(c) >= 3)
        r = lmul(r, axis_rotation(axis, v));  // intrinsic, in the listed order
      else
        t[axis] = reading == Reading::replace ? v : j.offset[axis] + v;
    }
    if (j.parent < 0) {
      pos[i] = t;
      rot[i] = r;
    } else {
      const LVec moved = lapply(rot[j.parent], t);
      for (int k = 0; k < 3; ++k) pos[i][k] = pos[j.parent][k] + moved[k];
      rot[i] = lmul(rot[j.parent], r);
    }
  }
  std::vector<LVec> out = pos;
  if (shell > 0)
    for (size_t i = 0; i < n; ++i) {
      if (sk.joints[i].end_site) continue;
      for (int axis = 0; axis < 3; ++axis)  // column `axis` of the world rotation: the local axis
        out.push_back({pos[i][0] + shell * rot[i][0][axis], pos[i][1] + shell * rot[i][1][axis],
                       pos[i][2] + shell * rot[i][2][axis]});
    }
  return out;
}

// Per node, the largest distance between rows a and b over its measured points (`all`), and
// over its shell points alone (`shell`; 0 for an End Site or without a shell).
struct NodeError {
  long double all = 0, shell = 0;
};
inline std::vector<NodeError> node_errors(const Skeleton& sk, const double* a, const double* b, long double shell,
                                          Reading reading) {
  const std::vector<LVec> pa = measured_points(sk, a, shell, reading), pb = measured_points(sk, b, shell, reading);
  auto distance = [&](size_t p) {
    return std::sqrt((pa[p][0] - pb[p][0]) * (pa[p][0] - pb[p][0]) + (pa[p][1] - pb[p][1]) * (pa[p][1] - pb[p][1]) +
                     (pa[p][2] - pb[p][2]) * (pa[p][2] - pb[p][2]));
  };
  const size_t n = sk.joints.size();
  std::vector<NodeError> out(n);
  size_t next_shell = n;  // shell points follow the nodes, three per joint in node order
  for (size_t i = 0; i < n; ++i) {
    out[i].all = distance(i);
    if (shell <= 0 || sk.joints[i].end_site) continue;
    for (int axis = 0; axis < 3; ++axis) out[i].shell = std::max(out[i].shell, distance(next_shell++));
    out[i].all = std::max(out[i].all, out[i].shell);
  }
  return out;
}

// Whether any node but a root has position channels (then both readings are measured: on a
// root, the OFFSET shifts the original and the decoded pose alike).
inline bool has_position_channels(const Skeleton& sk) {
  for (const Joint& j : sk.joints)
    if (j.parent >= 0)
      for (ChannelType c : j.channels)
        if (static_cast<int>(c) < 3) return true;
  return false;
}

}  // namespace keyanim::test
