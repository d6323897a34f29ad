#pragma once
// The scalar FHOG of air/track/dcf/fhog.cpp as it was before its vectorisation (commit
// 8dc0e90), kept verbatim as the reference the vectorised fhog() is compared with
// (test_dcf.cpp, within 1e-5) and timed against (bench/track/micro_fhog.cpp).
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "air/track/dcf/fhog.hpp"

namespace aerie::track::reference {
namespace detail {

inline constexpr int kSigned = 18, kUnsigned = 9;
inline constexpr float kTruncate = 0.2f;

// Gradient magnitude and signed orientation (radians in [0, 2 pi)) with [-1 0 1] differences;
// for colour, the channel of largest magnitude.
inline void gradient(const cv::Mat& image, cv::Mat& mag, cv::Mat& ang) {
  std::vector<cv::Mat> planes;
  cv::split(image, planes);
  for (size_t c = 0; c < planes.size(); ++c) {
    cv::Mat f, dx, dy, m, a;
    planes[c].convertTo(f, CV_32F);
    cv::Sobel(f, dx, CV_32F, 1, 0, 1, 1.0, 0.0, cv::BORDER_REPLICATE);
    cv::Sobel(f, dy, CV_32F, 0, 1, 1, 1.0, 0.0, cv::BORDER_REPLICATE);
    cv::cartToPolar(dx, dy, m, a);
    if (c == 0) {
      mag = m;
      ang = a;
    } else {
      const cv::Mat stronger = m > mag;
      m.copyTo(mag, stronger);
      a.copyTo(ang, stronger);
    }
  }
}

}  // namespace detail

inline std::vector<cv::Mat> fhog_reference(const cv::Mat& image, int cell) {
  if (image.empty()) throw std::invalid_argument("fhog: empty image");
  if (cell < 1) throw std::invalid_argument("fhog: cell size must be >= 1");
  const int ny = image.rows / cell, nx = image.cols / cell;
  if (nx < 1 || ny < 1) throw std::invalid_argument("fhog: image smaller than one cell");

  cv::Mat mag, ang;
  detail::gradient(image, mag, ang);

  // Orientation histograms, each pixel voting bilinearly into the 4 nearest cell centres and
  // linearly into the 2 nearest of 18 signed orientation bins.
  using detail::kSigned, detail::kUnsigned, detail::kTruncate;
  std::vector<float> hist(static_cast<size_t>(nx) * ny * kSigned, 0.f);
  const float inv_cell = 1.f / cell, bins_per_rad = kSigned / float(2 * CV_PI);
  for (int y = 0; y < ny * cell; ++y) {
    const float* m = mag.ptr<float>(y);
    const float* a = ang.ptr<float>(y);
    const float yc = (y + 0.5f) * inv_cell - 0.5f;
    const int y0 = static_cast<int>(std::floor(yc));
    const float wy1 = yc - y0, wy0 = 1 - wy1;
    for (int x = 0; x < nx * cell; ++x) {
      const float xc = (x + 0.5f) * inv_cell - 0.5f;
      const int x0 = static_cast<int>(std::floor(xc));
      const float wx1 = xc - x0, wx0 = 1 - wx1;
      const float o = a[x] * bins_per_rad;
      int o0 = static_cast<int>(o);
      const float wo1 = o - o0, wo0 = 1 - wo1;
      o0 %= kSigned;
      const int o1 = (o0 + 1) % kSigned;
      const float cy[2] = {wy0 * m[x], wy1 * m[x]};
      const float cx[2] = {wx0, wx1};
      for (int j = 0; j < 2; ++j) {
        const int yy = y0 + j;
        if (yy < 0 || yy >= ny) continue;
        for (int i = 0; i < 2; ++i) {
          const int xx = x0 + i;
          if (xx < 0 || xx >= nx) continue;
          float* h = &hist[(static_cast<size_t>(yy) * nx + xx) * kSigned];
          const float w = cy[j] * cx[i];
          h[o0] += w * wo0;
          h[o1] += w * wo1;
        }
      }
    }
  }

  // Energy of each cell's contrast-insensitive histogram, for the block norms.
  std::vector<float> energy(static_cast<size_t>(nx) * ny);
  for (size_t c = 0; c < energy.size(); ++c) {
    const float* h = &hist[c * kSigned];
    float e = 0;
    for (int o = 0; o < kUnsigned; ++o) e += (h[o] + h[o + kUnsigned]) * (h[o] + h[o + kUnsigned]);
    energy[c] = e;
  }
  auto energy_at = [&](int y, int x) {
    return energy[static_cast<size_t>(std::clamp(y, 0, ny - 1)) * nx + std::clamp(x, 0, nx - 1)];
  };

  std::vector<cv::Mat> out(kFhogChannels);
  for (auto& m : out) m.create(ny, nx, CV_32F);
  for (int y = 0; y < ny; ++y) {
    for (int x = 0; x < nx; ++x) {
      // The four 2x2 blocks that contain this cell (replicated at the border).
      float norm[4];
      int k = 0;
      for (int dy : {-1, 1})
        for (int dx : {-1, 1}) {
          const float e = energy_at(y, x) + energy_at(y + dy, x) + energy_at(y, x + dx) + energy_at(y + dy, x + dx);
          norm[k++] = 1.f / std::sqrt(e + 1e-4f);
        }
      const float* h = &hist[(static_cast<size_t>(y) * nx + x) * kSigned];
      float texture[4] = {0, 0, 0, 0};
      for (int o = 0; o < kSigned; ++o) {
        float sum = 0;
        for (int b = 0; b < 4; ++b) {
          const float v = std::min(h[o] * norm[b], kTruncate);
          sum += v;
          texture[b] += v;
        }
        out[o].at<float>(y, x) = 0.5f * sum;
      }
      for (int o = 0; o < kUnsigned; ++o) {
        float sum = 0;
        for (int b = 0; b < 4; ++b) sum += std::min((h[o] + h[o + kUnsigned]) * norm[b], kTruncate);
        out[kSigned + o].at<float>(y, x) = 0.5f * sum;
      }
      for (int b = 0; b < 4; ++b) out[kSigned + kUnsigned + b].at<float>(y, x) = 0.2357f * texture[b];
    }
  }
  return out;
}

}  // namespace aerie::track::reference
