#include "air/track/features/integral.hpp"

#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace aerie::track {

void IntegralImage::compute(const cv::Mat& gray, cv::Point origin) {
  if (gray.empty() || gray.type() != CV_8UC1) throw std::invalid_argument("IntegralImage: need a non-empty 8-bit gray image");
  origin_ = origin;
  const cv::Size need(gray.cols + 1 + kPadColumns, gray.rows + 1);
  if (buffer_.rows < need.height || buffer_.cols != need.width) buffer_.create(need, CV_32S);
  sum_ = buffer_(cv::Rect(0, 0, gray.cols + 1, gray.rows + 1));
  cv::integral(gray, sum_, CV_32S);  // sum_ has the right size and type: filled in place
  if (sum_.data != buffer_.data) throw std::logic_error("IntegralImage: cv::integral reallocated its output");
}

}  // namespace aerie::track
