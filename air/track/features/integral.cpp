#include "air/track/features/integral.hpp"

#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace aerie::track {

IntegralImage::IntegralImage(const cv::Mat& gray, cv::Point origin) : origin_(origin) {
  if (gray.empty() || gray.type() != CV_8UC1) throw std::invalid_argument("IntegralImage: need a non-empty 8-bit gray image");
  cv::integral(gray, sum_, CV_32S);
}

}  // namespace aerie::track
