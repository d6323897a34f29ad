#include "air/track/dcf/scale_filter.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "air/track/dcf/fhog.hpp"
#include "air/track/dcf/window.hpp"

namespace aerie::track {

ScaleFilter::ScaleFilter(const ScaleFilterParams& p, cv::Size2d target) : p_(p), target_(target) {
  factors_.resize(p_.scales);
  for (int i = 0; i < p_.scales; ++i) factors_[i] = std::pow(p_.step, p_.scales / 2 - i);
  const double r = std::sqrt(p_.model_area / target_.area());
  model_ = {std::max(2 * p_.cell, cvRound(target_.width * r)), std::max(2 * p_.cell, cvRound(target_.height * r))};
  hann_ = cv::Mat(hann(p_.scales), true).reshape(1, 1);
  const double sigma = p_.sigma * std::sqrt(static_cast<double>(p_.scales));
  cv::Mat y(1, p_.scales, CV_32F);
  for (int i = 0; i < p_.scales; ++i) {
    const double d = i - p_.scales / 2;
    y.at<float>(i) = static_cast<float>(std::exp(-0.5 * d * d / (sigma * sigma)));
  }
  cv::dft(y, yf_, cv::DFT_ROWS | cv::DFT_COMPLEX_OUTPUT);
}

cv::Mat ScaleFilter::features(const cv::Mat& frame, cv::Point2d pos, double scale) const {
  cv::Mat region;  // with resize_once: the largest sample's region at the model's resolution
  if (p_.resize_once) {
    const cv::Size2d unit = target_ * scale;  // the sample of factor 1, image pixels
    const cv::Size size(cvCeil(model_.width * factors_.front()) + 2, cvCeil(model_.height * factors_.front()) + 2);
    region = subwindow(frame, pos, {size.width * unit.width / model_.width, size.height * unit.height / model_.height},
                       size);
  }
  cv::Mat xs;  // feature dimension x scales
  for (int i = 0; i < p_.scales; ++i) {
    cv::Mat patch;
    if (region.empty()) {
      patch = subwindow(frame, pos, target_ * (scale * factors_[i]), model_);
    } else {
      // Output pixel u samples the region at its centre + (u + 1/2 - model / 2) * factor - 1/2.
      const double f = factors_[i];
      const cv::Matx23d to_region(f, 0, region.cols / 2.0 - 0.5 + (0.5 - model_.width / 2.0) * f,  //
                                  0, f, region.rows / 2.0 - 0.5 + (0.5 - model_.height / 2.0) * f);
      cv::warpAffine(region, patch, to_region, model_, cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REPLICATE);
    }
    const std::vector<cv::Mat> h = fhog(patch, p_.cell);
    const int cells = static_cast<int>(h[0].total());
    if (xs.empty()) xs.create(cells * static_cast<int>(h.size()), p_.scales, CV_32F);
    const float w = hann_.at<float>(i);
    for (size_t c = 0; c < h.size(); ++c) {
      const float* src = h[c].ptr<float>();
      for (int k = 0; k < cells; ++k) xs.at<float>(static_cast<int>(c) * cells + k, i) = w * src[k];
    }
  }
  cv::Mat xsf;
  cv::dft(xs, xsf, cv::DFT_ROWS | cv::DFT_COMPLEX_OUTPUT);
  return xsf;
}

void ScaleFilter::learn(const cv::Mat& frame, cv::Point2d pos, double scale, double rate) {
  const bool same = last_.frame == frame.data && last_.pos == pos && last_.scale == scale && !last_.xsf.empty();
  filter_.learn(same ? last_.xsf : features(frame, pos, scale), yf_, rate);
  last_ = {};
}

double ScaleFilter::best_change(const cv::Mat& frame, cv::Point2d pos, double scale) {
  last_ = {frame.data, pos, scale, features(frame, pos, scale)};
  cv::Mat response;
  cv::dft(filter_.respond(last_.xsf, p_.lambda), response,
          cv::DFT_INVERSE | cv::DFT_REAL_OUTPUT | cv::DFT_SCALE | cv::DFT_ROWS);
  cv::Point best;
  cv::minMaxLoc(response, nullptr, nullptr, nullptr, &best);
  return factors_[best.x];
}

}  // namespace aerie::track
