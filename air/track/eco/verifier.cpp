#include "air/track/eco/verifier.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace aerie::track {
namespace {

constexpr double kFlat = 1e-6;  // a placement whose norm (grey levels / 255) is below this has no texture

cv::Mat as_float(const cv::Mat& patch) {
  if (patch.size() != cv::Size(AppearanceVerifier::kPatch, AppearanceVerifier::kPatch) || patch.channels() != 1)
    throw std::invalid_argument("AppearanceVerifier: the patch must be one channel of kPatch x kPatch");
  cv::Mat f;
  patch.convertTo(f, CV_32F, patch.depth() == CV_8U ? 1.0 / 255 : 1.0);
  return f;
}

}  // namespace

AppearanceVerifier::AppearanceVerifier(int capacity) : capacity_(capacity) {
  if (capacity < 1) throw std::invalid_argument("AppearanceVerifier: capacity must be >= 1");
}

double AppearanceVerifier::similarity(const cv::Mat& patch) const {
  if (exemplars_.empty()) return 0;
  const cv::Mat f = as_float(patch);
  cv::Mat sum, sqsum;  // the placements' means and norms from integral images
  cv::integral(f, sum, sqsum, CV_64F, CV_64F);
  constexpr double n = kSize * kSize;
  double best = -1;
  for (int dy = 0; dy <= 2 * kMargin; ++dy)
    for (int dx = 0; dx <= 2 * kMargin; ++dx) {
      auto box = [&](const cv::Mat& s) {
        return s.at<double>(dy + kSize, dx + kSize) - s.at<double>(dy, dx + kSize) - s.at<double>(dy + kSize, dx) +
               s.at<double>(dy, dx);
      };
      const double s = box(sum), norm = std::sqrt(std::max(0.0, box(sqsum) - s * s / n));
      if (norm < kFlat) {
        best = std::max(best, 0.0);
        continue;
      }
      for (const cv::Mat& e : exemplars_) {
        // The exemplar has zero mean, so its product with the placement minus its mean is its
        // product with the placement.
        double dot = 0;
        for (int y = 0; y < kSize; ++y) {
          const float* a = e.ptr<float>(y);
          const float* b = f.ptr<float>(y + dy) + dx;
          float row = 0;
          for (int x = 0; x < kSize; ++x) row += a[x] * b[x];
          dot += row;
        }
        best = std::max(best, dot / norm);
      }
    }
  return std::clamp(best, -1.0, 1.0);
}

void AppearanceVerifier::add(const cv::Mat& patch) {
  cv::Mat e = as_float(patch)(cv::Rect(kMargin, kMargin, kSize, kSize)).clone();
  e -= cv::mean(e)[0];
  const double norm = cv::norm(e);
  if (norm < kFlat) return;
  e /= norm;
  if (exemplars_.size() < static_cast<size_t>(capacity_)) {
    exemplars_.push_back(std::move(e));
    return;
  }
  if (capacity_ == 1) return;  // the first is kept
  exemplars_[next_] = std::move(e);
  next_ = next_ + 1 < exemplars_.size() ? next_ + 1 : 1;
}

}  // namespace aerie::track
