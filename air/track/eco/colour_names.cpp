#include "air/track/eco/colour_names.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace aerie::track {
namespace {

constexpr int kLevels = 32, kStep = 256 / kLevels;
constexpr float kSigma = 30.f;  // CIELAB units: about the distance between neighbouring focal colours

// CIELAB (L in [0, 100]) of BGR colours in [0, 255].
std::vector<cv::Vec3f> to_lab(const std::vector<cv::Vec3f>& bgr) {
  cv::Mat in(static_cast<int>(bgr.size()), 1, CV_32FC3), lab;
  for (size_t i = 0; i < bgr.size(); ++i) in.at<cv::Vec3f>(static_cast<int>(i)) = bgr[i] / 255.f;
  cv::cvtColor(in, lab, cv::COLOR_BGR2Lab);
  return std::vector<cv::Vec3f>(lab.begin<cv::Vec3f>(), lab.end<cv::Vec3f>());
}

const std::vector<cv::Vec3f>& focal_lab() {
  static const std::vector<cv::Vec3f> lab = [] {
    std::vector<cv::Vec3f> bgr;
    for (const auto& c : focal_colours()) bgr.emplace_back(c[0], c[1], c[2]);
    return to_lab(bgr);
  }();
  return lab;
}

std::array<float, kColourNames> probabilities(const cv::Vec3f& lab) {
  std::array<float, kColourNames> p{};
  double sum = 0, nearest = INFINITY;
  std::array<double, kColourNames> d2{};
  for (int n = 0; n < kColourNames; ++n) {
    const cv::Vec3f d = lab - focal_lab()[n];
    d2[n] = d.dot(d);
    nearest = std::min(nearest, d2[n]);
  }
  for (int n = 0; n < kColourNames; ++n) sum += std::exp(-(d2[n] - nearest) / (2.0 * kSigma * kSigma));
  for (int n = 0; n < kColourNames; ++n)
    p[n] = static_cast<float>(std::exp(-(d2[n] - nearest) / (2.0 * kSigma * kSigma)) / sum);
  return p;
}

// The table, indexed (B / 8) * 1024 + (G / 8) * 32 + R / 8, of the bins' centre colours.
const std::vector<float>& table() {
  static const std::vector<float> t = [] {
    std::vector<cv::Vec3f> centres;
    centres.reserve(kLevels * kLevels * kLevels);
    for (int b = 0; b < kLevels; ++b)
      for (int g = 0; g < kLevels; ++g)
        for (int r = 0; r < kLevels; ++r)
          centres.emplace_back(b * kStep + kStep / 2.f, g * kStep + kStep / 2.f, r * kStep + kStep / 2.f);
    const auto lab = to_lab(centres);
    std::vector<float> out(lab.size() * kColourNames);
    for (size_t i = 0; i < lab.size(); ++i) {
      const auto p = probabilities(lab[i]);
      std::copy(p.begin(), p.end(), out.begin() + static_cast<std::ptrdiff_t>(i * kColourNames));
    }
    return out;
  }();
  return t;
}

int bin(const cv::Vec3b& c) { return ((c[0] / kStep) * kLevels + c[1] / kStep) * kLevels + c[2] / kStep; }

}  // namespace

const std::array<cv::Vec3b, kColourNames>& focal_colours() {
  // Approximate sRGB renderings of the focal Munsell chips of the 11 terms (Berlin & Kay 1969;
  // Sturges & Whitfield 1995), in OpenCV's B, G, R order.
  static const std::array<cv::Vec3b, kColourNames> c = {{
      {0, 0, 0},        // black
      {170, 70, 0},     // blue
      {35, 70, 115},    // brown
      {128, 128, 128},  // grey
      {60, 140, 20},    // green
      {30, 130, 245},   // orange
      {190, 165, 245},  // pink
      {140, 40, 110},   // purple
      {35, 25, 200},    // red
      {255, 255, 255},  // white
      {30, 225, 250},   // yellow
  }};
  return c;
}

std::array<float, kColourNames> colour_name_model(const cv::Vec3f& bgr) { return probabilities(to_lab({bgr})[0]); }

const float* colour_name_probabilities(const cv::Vec3b& bgr) { return &table()[bin(bgr) * kColourNames]; }

std::vector<cv::Mat> colour_names(const cv::Mat& bgr, int cell) {
  if (bgr.type() != CV_8UC3) throw std::invalid_argument("colour_names: expected an 8-bit BGR image");
  if (cell < 1) throw std::invalid_argument("colour_names: cell size must be >= 1");
  const int ny = bgr.rows / cell, nx = bgr.cols / cell;
  if (nx < 1 || ny < 1) throw std::invalid_argument("colour_names: image smaller than one cell");
  const float* t = table().data();
  std::vector<float> sum(static_cast<size_t>(nx) * kColourNames);
  std::vector<cv::Mat> out(kColourNames);
  for (auto& m : out) m.create(ny, nx, CV_32F);
  const float inv = 1.f / static_cast<float>(cell * cell);
  for (int cy = 0; cy < ny; ++cy) {
    std::fill(sum.begin(), sum.end(), 0.f);
    for (int y = cy * cell; y < (cy + 1) * cell; ++y) {
      const cv::Vec3b* p = bgr.ptr<cv::Vec3b>(y);
      for (int x = 0; x < nx * cell; ++x) {
        const float* e = t + bin(p[x]) * kColourNames;
        float* s = &sum[static_cast<size_t>(x / cell) * kColourNames];
        for (int n = 0; n < kColourNames; ++n) s[n] += e[n];
      }
    }
    for (int n = 0; n < kColourNames; ++n) {
      float* o = out[n].ptr<float>(cy);
      for (int cx = 0; cx < nx; ++cx) o[cx] = sum[static_cast<size_t>(cx) * kColourNames + n] * inv;
    }
  }
  return out;
}

}  // namespace aerie::track
