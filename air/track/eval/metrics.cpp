#include "air/track/eval/metrics.hpp"

#include <cmath>
#include <stdexcept>

#include "air/track/eval/sequence.hpp"

namespace aerie::track::eval {

double iou(const cv::Rect2d& a, const cv::Rect2d& b) {
  const double w = std::min(a.x + a.width, b.x + b.width) - std::max(a.x, b.x);
  const double h = std::min(a.y + a.height, b.y + b.height) - std::max(a.y, b.y);
  if (w <= 0 || h <= 0) return 0;
  const double inter = w * h;
  return inter / (a.area() + b.area() - inter);
}

double centre_error(const cv::Rect2d& a, const cv::Rect2d& b) {
  return std::hypot(a.x + a.width / 2 - b.x - b.width / 2, a.y + a.height / 2 - b.y - b.height / 2);
}

std::vector<double> success_thresholds() {
  std::vector<double> t;
  for (int i = 0; i <= 20; ++i) t.push_back(i * 0.05);
  return t;
}

std::vector<double> precision_thresholds() {
  std::vector<double> t;
  for (int i = 0; i <= 50; ++i) t.push_back(i);
  return t;
}

Score score(const std::vector<cv::Rect2d>& predicted, const std::vector<cv::Rect2d>& groundtruth) {
  if (predicted.size() != groundtruth.size())
    throw std::invalid_argument("score: " + std::to_string(predicted.size()) + " predicted boxes for " +
                                std::to_string(groundtruth.size()) + " ground-truth boxes");
  const auto st = success_thresholds(), pt = precision_thresholds();
  Score s;
  s.success.assign(st.size(), 0);
  s.precision.assign(pt.size(), 0);
  double cle_sum = 0;
  for (size_t i = 0; i < groundtruth.size(); ++i) {
    if (!is_valid_box(groundtruth[i])) continue;
    ++s.frames;
    const bool ok = is_valid_box(predicted[i]);
    const double o = ok ? iou(predicted[i], groundtruth[i]) : 0;
    // A missing prediction counts as infinitely far away.
    const double e = ok ? centre_error(predicted[i], groundtruth[i]) : INFINITY;
    for (size_t k = 0; k < st.size(); ++k) s.success[k] += o > st[k];
    for (size_t k = 0; k < pt.size(); ++k) s.precision[k] += e <= pt[k];
    cle_sum += ok ? e : std::hypot(groundtruth[i].width, groundtruth[i].height);
  }
  if (s.frames == 0) return s;
  for (auto& v : s.success) v /= s.frames;
  for (auto& v : s.precision) v /= s.frames;
  for (double v : s.success) s.auc += v;
  s.auc /= static_cast<double>(s.success.size());
  s.precision20 = s.precision[20];
  s.mean_centre_error = cle_sum / s.frames;
  return s;
}

Figures figures(const Score& s) { return {s.auc, s.precision20, s.mean_centre_error}; }

Figures mean(const std::vector<Figures>& per_sequence) {
  if (per_sequence.empty()) return {NAN, NAN, NAN};
  Figures m;
  for (const auto& f : per_sequence) {
    m.auc += f.auc;
    m.precision20 += f.precision20;
    m.mean_centre_error += f.mean_centre_error;
  }
  const double n = static_cast<double>(per_sequence.size());
  return {m.auc / n, m.precision20 / n, m.mean_centre_error / n};
}

}  // namespace aerie::track::eval
