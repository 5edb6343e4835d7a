// Euler angles of a quaternion node's rotation (spec/FORMAT.md Appendix B): what Clip::sample
// gives as its rotation channels' values, and what a converter writes frame after frame.
#include "keyanim/rotation.h"

#include <cmath>
#include <numbers>

namespace keyanim {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

// The angle moved by whole turns to lie within 180 degrees of `near`.
double turned_near(double angle, double near) noexcept {
  return angle + 360.0 * std::round((near - angle) / 360.0);
}

}  // namespace

void euler_from_quaternion(const double (&q)[4], const uint8_t (&axes)[3], double (&deg)[3]) noexcept {
  const double x = q[0], y = q[1], z = q[2], w = q[3];
  const double m[3][3] = {{1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)},
                          {2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)},
                          {2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)}};
  // R = R_i(a) R_j(b) R_k(c): with s = +1 for a cyclic order (XYZ, YZX, ZXY) and -1 otherwise,
  // m[i][k] = s sin b, m[j][k] = -s sin a cos b, m[k][k] = cos a cos b, m[i][i], m[i][j] = cos b
  // (cos c, -s sin c).
  const int i = axes[0], j = axes[1], k = axes[2];
  const double s = j == (i + 1) % 3 ? 1.0 : -1.0;
  const double a = std::atan2(-s * m[j][k], m[k][k]);
  const double b = std::atan2(s * m[i][k], std::hypot(m[i][i], m[i][j]));
  // c from what is left once a is undone: row j of R_i(-a) R = R_j(b) R_k(c) is (s sin c, cos c)
  // at columns i and j, so that c fits the a found even where a and c are ill-defined (b near
  // +-90, where only their sum or difference is): the three angles recompose R.
  const double ca = std::cos(a), sa = std::sin(a);
  const double n_ji = ca * m[j][i] + s * sa * m[k][i], n_jj = ca * m[j][j] + s * sa * m[k][j];
  deg[0] = a * kDegPerRad;
  deg[1] = b * kDegPerRad;
  deg[2] = std::atan2(s * n_ji, n_jj) * kDegPerRad;
}

void nearest_euler(const double (&previous)[3], double (&deg)[3]) noexcept {
  const double other[3] = {deg[0] + 180.0, 180.0 - deg[1], deg[2] + 180.0};
  double a[3], b[3], cost_a = 0.0, cost_b = 0.0;
  for (int k = 0; k < 3; ++k) {
    a[k] = turned_near(deg[k], previous[k]), b[k] = turned_near(other[k], previous[k]);
    cost_a += std::fabs(a[k] - previous[k]), cost_b += std::fabs(b[k] - previous[k]);
  }
  for (int k = 0; k < 3; ++k) deg[k] = cost_b < cost_a ? b[k] : a[k];
}

}  // namespace keyanim
