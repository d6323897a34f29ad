#include "air/track/dcf/colour_histogram.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "air/track/dcf/filters.hpp"
#include "air/track/dcf/window.hpp"

namespace aerie::track {
namespace {

// Index of the colour histogram bin of each pixel.
cv::Mat bin_index(const cv::Mat& patch, int bins) {
  const int shift = static_cast<int>(std::round(std::log2(256.0 / bins)));
  cv::Mat idx(patch.size(), CV_32S);
  for (int y = 0; y < patch.rows; ++y) {
    int* o = idx.ptr<int>(y);
    if (patch.channels() == 1) {
      const uchar* p = patch.ptr<uchar>(y);
      for (int x = 0; x < patch.cols; ++x) o[x] = p[x] >> shift;
    } else {
      const cv::Vec3b* p = patch.ptr<cv::Vec3b>(y);
      for (int x = 0; x < patch.cols; ++x)
        o[x] = ((p[x][2] >> shift) * bins + (p[x][1] >> shift)) * bins + (p[x][0] >> shift);
    }
  }
  return idx;
}

}  // namespace

cv::Mat ColourHistogram::likelihood(const cv::Mat& patch) const {
  const cv::Mat idx = bin_index(patch, bins_);
  cv::Mat out(patch.size(), CV_32F);
  const float* fg = fg_.ptr<float>();
  const float* bg = bg_.ptr<float>();
  for (int y = 0; y < patch.rows; ++y) {
    const int* i = idx.ptr<int>(y);
    float* o = out.ptr<float>(y);
    for (int x = 0; x < patch.cols; ++x) {
      const float f = fg[i[x]], b = bg[i[x]];
      o[x] = f + b > 0 ? f / (f + b) : 0.f;
    }
  }
  return out;
}

void ColourHistogram::learn(const cv::Mat& patch, cv::Size2d target, double rate) {
  const cv::Mat idx = bin_index(patch, bins_);
  const double shrink = inner_padding_ * (target.width + target.height) / 2;
  const cv::Point2d c(patch.cols / 2.0, patch.rows / 2.0);
  auto rect = [&](cv::Size2d s) {
    return cv::Rect(cvRound(c.x - s.width / 2), cvRound(c.y - s.height / 2), std::max(1, cvRound(s.width)),
                    std::max(1, cvRound(s.height))) &
           cv::Rect(0, 0, patch.cols, patch.rows);
  };
  const cv::Rect fg_rect = rect({std::max(1.0, target.width - shrink), std::max(1.0, target.height - shrink)});
  const cv::Rect target_rect = rect(target);
  const int n = patch.channels() == 1 ? bins_ : bins_ * bins_ * bins_;
  cv::Mat fg = cv::Mat::zeros(1, n, CV_32F), bg = cv::Mat::zeros(1, n, CV_32F);
  float nf = 0, nb = 0;
  for (int y = 0; y < patch.rows; ++y) {
    const int* i = idx.ptr<int>(y);
    for (int x = 0; x < patch.cols; ++x) {
      if (fg_rect.contains({x, y})) {
        fg.at<float>(i[x]) += 1;
        ++nf;
      } else if (!target_rect.contains({x, y})) {
        bg.at<float>(i[x]) += 1;
        ++nb;
      }
    }
  }
  if (nf > 0) fg /= nf;
  if (nb > 0) bg /= nb;
  blend(fg_, fg, rate);
  blend(bg_, bg, rate);
}

void ColourHistogram::merge(cv::Mat& response, const cv::Mat& patch, cv::Size2d target, int cell,
                            double weight) const {
  cv::Mat box;
  cv::boxFilter(likelihood(patch), box, CV_32F,
                cv::Size(std::max(1, cvRound(target.width)), std::max(1, cvRound(target.height))), cv::Point(-1, -1),
                true, cv::BORDER_CONSTANT);
  const float w = static_cast<float>(weight);
  for (int i = 0; i < response.rows; ++i)
    for (int j = 0; j < response.cols; ++j) {
      const int py = std::clamp(patch.rows / 2 + circular(i, response.rows) * cell, 0, patch.rows - 1);
      const int px = std::clamp(patch.cols / 2 + circular(j, response.cols) * cell, 0, patch.cols - 1);
      float& v = response.at<float>(i, j);
      v = (1 - w) * v + w * box.at<float>(py, px);
    }
}

}  // namespace aerie::track
