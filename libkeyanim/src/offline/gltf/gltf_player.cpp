// A glTF player's arithmetic (gltf_player.h), in binary64 as three.js computes it.
#include "gltf_player.h"

#include <algorithm>
#include <cmath>

namespace keyanim::offline::gltf {
namespace {

void quat_lerp(QuatLerp lerp, const float* a, const float* b_in, double u, double* out) noexcept {
  double b[4] = {b_in[0], b_in[1], b_in[2], b_in[3]};
  double dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
  if (dot < 0.0) {  // the short way (the export aligns hemispheres, so this is for safety)
    for (double& v : b) v = -v;
    dot = -dot;
  }
  const bool slerp = lerp == QuatLerp::slerp ? dot < 1.0 : lerp == QuatLerp::threejs && dot < 0.9995;
  double s0 = 1.0 - u, s1 = u;
  if (slerp) {
    const double theta = std::acos(dot);
    const double sn = std::sin(theta);
    if (sn > 0.0) {
      s0 = std::sin(s0 * theta) / sn;
      s1 = std::sin(s1 * theta) / sn;
    }
  }
  for (int i = 0; i < 4; ++i) out[i] = a[i] * s0 + b[i] * s1;
  if (!slerp) {
    const double f = 1.0 / std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2] + out[3] * out[3]);
    for (int i = 0; i < 4; ++i) out[i] *= f;
  }
}

}  // namespace

void eval_segment(Interp interp, int components, QuatLerp lerp, const float* v0, const float* out0, const float* in1,
                  const float* v1, double t0, double t1, double t, double* out) noexcept {
  const double td = t1 - t0;
  const double u = (t - t0) / td;
  if (interp == Interp::linear) {
    if (components == 4) return quat_lerp(lerp, v0, v1, u, out);
    for (int i = 0; i < components; ++i) out[i] = v0[i] * (1.0 - u) + v1[i] * u;
    return;
  }
  // glTF 2.0 appendix C: (2u^3 - 3u^2 + 1) v0 + td (u^3 - 2u^2 + u) b0 + (-2u^3 + 3u^2) v1 + td (u^3 - u^2) a1.
  const double uu = u * u, uuu = uu * u;
  const double s2 = -2.0 * uuu + 3.0 * uu;
  const double s3 = uuu - uu;
  const double s0 = 1.0 - s2;
  const double s1 = s3 - uu + u;
  for (int i = 0; i < components; ++i) out[i] = s0 * v0[i] + s1 * (out0[i] * td) + s2 * v1[i] + s3 * (in1[i] * td);
  if (components == 4) {
    const double len = std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2] + out[3] * out[3]);
    for (int i = 0; i < 4; ++i) out[i] /= len;
  }
}

void eval_sampler(const Sampler& s, double t, QuatLerp lerp, double* out) noexcept {
  const size_t n = s.times.size();
  const int k = s.components;
  const bool cubic = s.interp == Interp::cubic;
  // Key i's in-tangent, value and out-tangent (cubic), or its value.
  auto at = [&](size_t i, int part) { return s.values.data() + (cubic ? (3 * i + size_t(part)) * k : i * k); };
  size_t clamp = SIZE_MAX;
  if (n == 1 || t <= s.times[0]) clamp = 0;
  else if (t >= s.times[n - 1]) clamp = n - 1;
  if (clamp != SIZE_MAX) {
    const float* v = at(clamp, 1);
    for (int i = 0; i < k; ++i) out[i] = v[i];
    return;
  }
  const size_t i = size_t(std::upper_bound(s.times.begin(), s.times.end(), t) - s.times.begin()) - 1;
  eval_segment(s.interp, k, lerp, at(i, 1), at(i, 2), at(i + 1, 0), at(i + 1, 1), s.times[i], s.times[i + 1], t, out);
}

Mat3 quat_matrix(const double* q) noexcept {
  const double x = q[0], y = q[1], z = q[2], w = q[3];
  const double x2 = x + x, y2 = y + y, z2 = z + z;
  const double xx = x * x2, xy = x * y2, xz = x * z2, yy = y * y2, yz = y * z2, zz = z * z2;
  const double wx = w * x2, wy = w * y2, wz = w * z2;
  return {1 - (yy + zz), xy - wz, xz + wy,
          xy + wz, 1 - (xx + zz), yz - wx,
          xz - wy, yz + wx, 1 - (xx + yy)};
}

void play_pose(const Model& model, double t, QuatLerp lerp, std::vector<Vec3>& positions, std::vector<Mat3>& rotations) {
  const size_t n = model.skeleton.joints.size();
  positions.resize(n);
  rotations.resize(n);
  for (size_t j = 0; j < n; ++j) {
    const Joint& joint = model.skeleton.joints[j];
    const NodeAnimation& anim = model.nodes[j];
    Vec3 tr = joint.offset;
    if (anim.translation) eval_sampler(*anim.translation, t, lerp, tr.data());
    double q[4] = {0, 0, 0, 1};
    if (anim.rotation) eval_sampler(*anim.rotation, t, lerp, q);
    const Mat3 local = quat_matrix(q);
    const bool root = joint.parent < 0 || size_t(joint.parent) >= j;
    if (root) {
      positions[j] = tr;
      rotations[j] = local;
      continue;
    }
    const Vec3& pp = positions[size_t(joint.parent)];
    const Mat3& m = rotations[size_t(joint.parent)];
    positions[j] = {pp[0] + m[0] * tr[0] + m[1] * tr[1] + m[2] * tr[2],
                    pp[1] + m[3] * tr[0] + m[4] * tr[1] + m[5] * tr[2],
                    pp[2] + m[6] * tr[0] + m[7] * tr[1] + m[8] * tr[2]};
    Mat3& r = rotations[j];
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 3; ++col)
        r[row * 3 + col] = m[row * 3] * local[col] + m[row * 3 + 1] * local[3 + col] + m[row * 3 + 2] * local[6 + col];
  }
}

}  // namespace keyanim::offline::gltf
