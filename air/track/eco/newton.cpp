#include "air/track/eco/newton.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

namespace aerie::track {

ResponseValue response_at(const cv::Mat& spectrum, cv::Point2d at) {
  const int w = spectrum.cols, h = spectrum.rows;
  // Per-axis phases exp(i w_k x) with w_k = 2 pi k_signed / W, computed once per axis.
  auto phases = [](int n, double t, std::vector<std::complex<double>>& e, std::vector<double>& f) {
    e.resize(n);
    f.resize(n);
    for (int k = 0; k < n; ++k) {
      f[k] = 2 * CV_PI * (k > n / 2 ? k - n : k) / n;
      e[k] = std::polar(1.0, f[k] * t);
    }
  };
  std::vector<std::complex<double>> ex, ey;
  std::vector<double> fx, fy;
  phases(w, at.x, ex, fx);
  phases(h, at.y, ey, fy);
  std::complex<double> s, sx, sy, sxx, sxy, syy;
  for (int l = 0; l < h; ++l) {
    const auto* row = spectrum.ptr<std::complex<float>>(l);
    std::complex<double> r0, r1, r2;  // sum over k of S e, S (i fx) e, S (-fx^2) e
    for (int k = 0; k < w; ++k) {
      const std::complex<double> v = std::complex<double>(row[k]) * ex[k];
      r0 += v;
      r1 += v * std::complex<double>(0, fx[k]);
      r2 -= v * (fx[k] * fx[k]);
    }
    const std::complex<double> e = ey[l], iy(0, fy[l]);
    s += r0 * e;
    sx += r1 * e;
    sy += r0 * e * iy;
    sxx += r2 * e;
    sxy += r1 * e * iy;
    syy -= r0 * e * (fy[l] * fy[l]);
  }
  const double n = static_cast<double>(w) * h;
  return {s.real() / n, sx.real() / n, sy.real() / n, sxx.real() / n, sxy.real() / n, syy.real() / n};
}

cv::Point2d newton_peak(const cv::Mat& spectrum, cv::Point2d start, int iterations) {
  cv::Point2d p = start;
  for (int it = 0; it < iterations; ++it) {
    const ResponseValue v = response_at(spectrum, p);
    const double det = v.dxx * v.dyy - v.dxy * v.dxy;
    if (!(v.dxx < 0 && det > 0)) break;  // not a maximum's neighbourhood: keep the point
    // step = -H^-1 grad
    const double sx = -(v.dyy * v.dx - v.dxy * v.dy) / det, sy = -(v.dxx * v.dy - v.dxy * v.dx) / det;
    p.x += std::clamp(sx, -1.0, 1.0);
    p.y += std::clamp(sy, -1.0, 1.0);
    if (std::abs(sx) < 1e-4 && std::abs(sy) < 1e-4) break;
  }
  return p;
}

}  // namespace aerie::track
