#pragma once
// Synthetic tracking sequences with exact ground truth: a textured target patch moved over a
// textured background by a known similarity (translation, rotation, scale) under a global
// illumination change.
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace aerie::track::test {

struct Motion {
  cv::Point2d centre;
  double scale = 1, theta = 0;   // relative to the initial target
  double gain = 1, bias = 0;     // illumination: I' = gain * I + bias
};

// Smooth random texture with values in [lo, hi].
inline cv::Mat texture(cv::Size size, uint64_t seed, double blur, int lo, int hi) {
  cv::Mat noise(size, CV_32F);
  cv::RNG(seed).fill(noise, cv::RNG::UNIFORM, 0, 1);
  cv::GaussianBlur(noise, noise, cv::Size(), blur);
  cv::normalize(noise, noise, lo, hi, cv::NORM_MINMAX);
  cv::Mat out;
  noise.convertTo(out, CV_8U);
  return out;
}

class Scene {
 public:
  // target_blur: scale of the target's texture (pixels; larger = coarser).
  Scene(cv::Size frame, cv::Size target, uint64_t seed = 1, double target_blur = 1.5)
      : background_(texture(frame, seed, 6, 40, 200)), target_(texture(target, seed + 1, target_blur, 0, 255)) {}

  cv::Size target_size() const { return target_.size(); }

  // The frame with the target at motion m (BGR).
  cv::Mat render(const Motion& m) const {
    cv::Mat frame = background_.clone();
    const cv::Point2d c0(target_.cols / 2.0, target_.rows / 2.0);
    cv::Mat A = cv::getRotationMatrix2D(c0, -m.theta * 180 / M_PI, m.scale);  // about the patch centre
    A.at<double>(0, 2) += m.centre.x - c0.x;
    A.at<double>(1, 2) += m.centre.y - c0.y;
    cv::Mat warped, mask;
    cv::warpAffine(target_, warped, A, frame.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
    cv::warpAffine(cv::Mat(target_.size(), CV_8U, cv::Scalar(255)), mask, A, frame.size(), cv::INTER_NEAREST);
    warped.copyTo(frame, mask);
    frame.convertTo(frame, CV_8U, m.gain, m.bias);
    cv::Mat bgr;
    cv::cvtColor(frame, bgr, cv::COLOR_GRAY2BGR);
    return bgr;
  }

  // Axis-aligned box of the unrotated target at motion m.
  cv::Rect2d box(const Motion& m) const {
    const double w = target_.cols * m.scale, h = target_.rows * m.scale;
    return {m.centre.x - w / 2, m.centre.y - h / 2, w, h};
  }

 private:
  cv::Mat background_, target_;
};

// The message with which a tracker built from the default parameters changed by `change` is
// refused, or "accepted".
template <typename TrackerType, typename Params, typename Change>
std::string rejection(Change change) {
  Params p;
  change(p);
  try {
    TrackerType t(p);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace aerie::track::test
