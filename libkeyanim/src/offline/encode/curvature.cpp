// He & Yung's CSS corner detector on one channel, step by step as in method.md section 5. The
// curve is (frame, value) scaled into a square box; after padding, index p of every array below
// is frame p - W.
#include "keyanim/offline/curvature.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>

namespace keyanim::offline {
namespace {

constexpr double kGaussianDieOff = 1e-4;  // kernel half-width: last tap above this
constexpr int kMaxHalfWidth = 30;
constexpr double kCollinear = 1e-8;       // |cross| below this: fit a chord, not a circle

std::vector<uint32_t> end_frames(size_t count) {
  if (count == 0) return {};
  if (count == 1) return {0};
  return {0, static_cast<uint32_t>(count - 1)};
}

// Half-width W: the largest w <= 30 whose tap exceeds the die-off (at least 1).
int half_width(double sigma) {
  int width = 1;
  for (int w = 1; w <= kMaxHalfWidth; ++w)
    if (std::exp(-double(w) * w / (2.0 * sigma * sigma)) > kGaussianDieOff) width = w;
  return width;
}

std::vector<double> gaussian(double sigma, int w) {
  std::vector<double> g(size_t(2 * w + 1));
  double sum = 0.0;
  for (int t = -w; t <= w; ++t) sum += g[size_t(t + w)] = std::exp(-double(t) * t / (2.0 * sigma * sigma));
  for (double& v : g) v /= sum;
  return g;
}

// The signal extended by w samples at each end by point reflection (2 y_0 - y_k).
std::vector<double> reflect_pad(const std::vector<double>& y, int w) {
  const size_t n = y.size(), uw = size_t(w);
  std::vector<double> p(n + 2 * uw);
  for (size_t i = 0; i < n; ++i) p[uw + i] = y[i];
  for (size_t k = 1; k <= uw; ++k) {
    p[uw - k] = 2.0 * y[0] - y[k];
    p[uw + n - 1 + k] = 2.0 * y[n - 1] - y[n - 1 - k];
  }
  return p;
}

// Convolution over the padded array. The kernel reaches w samples past the padding; there the
// padding is reflected once more, so that a straight end stays straight (a zero fill, as a plain
// convolution does, would bend the padded ends and plant false corners there).
std::vector<double> smooth(const std::vector<double>& p, const std::vector<double>& g, int w) {
  const ptrdiff_t n = ptrdiff_t(p.size());
  auto at = [&](ptrdiff_t i) {
    if (i < 0) return 2.0 * p[0] - p[size_t(-i)];
    if (i >= n) return 2.0 * p[size_t(n - 1)] - p[size_t(2 * (n - 1) - i)];
    return p[size_t(i)];
  };
  std::vector<double> out(p.size());
  for (ptrdiff_t i = 0; i < n; ++i) {
    double acc = 0.0;
    for (ptrdiff_t t = -w; t <= w; ++t) acc += g[size_t(t + w)] * at(i + t);
    out[size_t(i)] = acc;
  }
  return out;
}

// Central differences, one-sided at the two ends (n >= 2).
std::vector<double> derivative(const std::vector<double>& v) {
  const size_t n = v.size();
  std::vector<double> d(n);
  d[0] = v[1] - v[0];
  for (size_t i = 1; i + 1 < n; ++i) d[i] = (v[i + 1] - v[i - 1]) * 0.5;
  d[n - 1] = v[n - 1] - v[n - 2];
  return d;
}

struct Vec2 {
  double x, y;
};

// Tangent at the candidate c of the arm running from c to e (another index of the smoothed
// curve): the circle through c, the arm's midpoint and e, or the chord for short or straight arms.
Vec2 arm_tangent(const std::vector<double>& yy, size_t c, size_t e) {
  const size_t len = (c > e ? c - e : e - c) + 1;  // points in the arm, both ends included
  // Frames are x, so the smoothed x of index i is i (minus a constant that cancels here).
  auto pt = [&](size_t i) { return Vec2{double(i), yy[i]}; };
  const Vec2 p1 = pt(c), p3 = pt(e);
  const Vec2 chord{p3.x - p1.x, p3.y - p1.y};
  if (len <= 3) return chord;
  const size_t half = (len + 1) / 2 - 1;  // midpoint: 1-based ceil(len / 2) along the arm
  const Vec2 p2 = pt(c > e ? c - half : c + half);
  const Vec2 b{p2.x - p1.x, p2.y - p1.y};
  const double cross = b.x * chord.y - b.y * chord.x;
  if (std::abs(cross) < kCollinear) return chord;
  // Circumcentre relative to p1: the radius direction at p1.
  const double bb = b.x * b.x + b.y * b.y, cc = chord.x * chord.x + chord.y * chord.y;
  const Vec2 r{(chord.y * bb - b.y * cc) / (2.0 * cross), (b.x * cc - chord.x * bb) / (2.0 * cross)};
  // The tangent is perpendicular to the radius, on the side of the arm's midpoint.
  const double side = r.x * b.y - r.y * b.x;
  return side >= 0.0 ? Vec2{-r.y, r.x} : Vec2{r.y, -r.x};
}

double angle_deg(Vec2 a, Vec2 b) {
  const double na = std::hypot(a.x, a.y), nb = std::hypot(b.x, b.y);
  if (!(na > 0.0) || !(nb > 0.0)) return 180.0;  // a degenerate arm cannot make a corner
  const double c = std::clamp((a.x * b.x + a.y * b.y) / (na * nb), -1.0, 1.0);
  return std::acos(c) * 180.0 / std::numbers::pi;
}

// Indices of the curvature maxima that pass the adaptive threshold (steps 5 and 6).
std::vector<size_t> threshold_maxima(const std::vector<double>& k, double c) {
  const size_t n = k.size();
  // Alternating minima (even positions) and maxima (odd positions), starting with a minimum.
  std::vector<size_t> ext;
  int search = 1;
  for (size_t j = 0; j + 1 < n; ++j) {
    if ((k[j + 1] - k[j]) * search > 0.0) {
      ext.push_back(j);
      search = -search;
    }
  }
  if (ext.size() % 2 == 0) ext.push_back(n - 1);  // close the last maximum with a minimum
  std::vector<size_t> out;
  for (size_t j = 1; j + 1 < ext.size(); j += 2) {
    // Region of support: from the previous minimum to the next one.
    double sum = 0.0;
    for (size_t i = ext[j - 1]; i <= ext[j + 1]; ++i) sum += k[i];
    const double mean = sum / double(ext[j + 1] - ext[j - 1] + 1);
    if (!(k[ext[j]] < c * mean)) out.push_back(ext[j]);
  }
  return out;
}

}  // namespace

std::vector<uint32_t> curvature_keys(std::span<const double> signal, const CurvatureParams& params) {
  const size_t n = signal.size();
  std::vector<uint32_t> keys = end_frames(n);
  if (!(params.sigma > 0.0) || !std::isfinite(params.sigma) || !std::isfinite(params.c) ||
      !std::isfinite(params.t_angle))
    return keys;
  double lo = 0.0, hi = 0.0;
  for (size_t i = 0; i < n; ++i) {
    if (!std::isfinite(signal[i])) return keys;  // no meaningful curvature
    lo = i == 0 ? signal[i] : std::min(lo, signal[i]);
    hi = i == 0 ? signal[i] : std::max(hi, signal[i]);
  }
  const int w = half_width(params.sigma);
  if (n <= size_t(w) || !(hi > lo)) return keys;

  // 1. Square box: the value spans as many units as the frames do.
  std::vector<double> y(n);
  const double scale = double(n - 1) / (hi - lo);
  for (size_t i = 0; i < n; ++i) y[i] = (signal[i] - lo) * scale;

  // 2-3. Pad by point reflection, smooth. x = frame is a straight line, which the symmetric
  // normalised kernel and the reflection leave as it is: x' = 1 and x'' = 0 exactly.
  const std::vector<double> g = gaussian(params.sigma, w);
  const std::vector<double> yy = smooth(reflect_pad(y, w), g, w);

  // 4. Curvature |x' y'' - x'' y'| / (x'^2 + y'^2)^1.5 with x' = 1, x'' = 0.
  const std::vector<double> yu = derivative(yy);
  const std::vector<double> yuu = derivative(yu);
  std::vector<double> k(yy.size());
  for (size_t i = 0; i < k.size(); ++i) k[i] = std::abs(yuu[i]) / std::pow(1.0 + yu[i] * yu[i], 1.5);

  // 5-6. Maxima above C x the mean of their region.
  std::vector<size_t> cand = threshold_maxima(k, params.c);

  // 7. Angle test with the neighbouring survivors as the region of support, until stable.
  const size_t last = yy.size() - 1;
  std::vector<size_t> kept;
  for (bool changed = true; changed && !cand.empty();) {
    kept.clear();
    for (size_t j = 0; j < cand.size(); ++j) {
      const size_t prev = j == 0 ? 0 : cand[j - 1];
      const size_t next = j + 1 == cand.size() ? last : cand[j + 1];
      const double ang = angle_deg(arm_tangent(yy, cand[j], prev), arm_tangent(yy, cand[j], next));
      if (!(ang > params.t_angle)) kept.push_back(cand[j]);
    }
    changed = kept.size() != cand.size();
    cand.swap(kept);
  }

  // 8. Back to frames, dropping the padding.
  for (const size_t p : cand)
    if (p >= size_t(w) && p - size_t(w) < n) keys.push_back(static_cast<uint32_t>(p - size_t(w)));
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  return keys;
}

}  // namespace keyanim::offline
