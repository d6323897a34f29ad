#include "air/capture/output_format.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace aerie::capture {

OutputFormat::OutputFormat(const OutputOptions& options, cv::Size source_size) : opt_(options), source_(source_size) {
  if (source_.width <= 0 || source_.height <= 0) throw std::invalid_argument("output: the source has no image size");
  if ((opt_.width > 0) != (opt_.height > 0) || opt_.width < 0 || opt_.height < 0)
    throw std::invalid_argument("output: give both width and height (or neither)");
  if (!(opt_.downscale >= 1.0)) throw std::invalid_argument("output: downscale must be >= 1");
  if (opt_.width > 0) {
    size_ = {opt_.width, opt_.height};
  } else {
    size_ = {static_cast<int>(std::lround(source_.width / opt_.downscale)),
             static_cast<int>(std::lround(source_.height / opt_.downscale))};
  }
  if (size_.width < 8 || size_.height < 8) throw std::invalid_argument("output: image size below 8x8");
}

cv::Mat OutputFormat::convert(const cv::Mat& img) const {
  if (img.empty()) return img;
  cv::Mat out = img;
  if (out.size() != size_) {
    cv::Mat scaled;
    // INTER_AREA averages when shrinking (no aliasing); linear when enlarging.
    cv::resize(out, scaled, size_, 0, 0, size_.width < out.cols ? cv::INTER_AREA : cv::INTER_LINEAR);
    out = scaled;
  }
  if (!opt_.color && out.channels() == 3) {
    cv::Mat g;
    cv::cvtColor(out, g, cv::COLOR_BGR2GRAY);
    out = g;
  } else if (opt_.color && out.channels() == 1) {
    cv::Mat c;
    cv::cvtColor(out, c, cv::COLOR_GRAY2BGR);
    out = c;
  }
  return out;
}

void OutputFormat::apply(Frame& frame) const {
  if (frame.left.size() != source_)
    throw FrameError("frame " + std::to_string(frame.index) + " is " + std::to_string(frame.left.cols) + "x" +
                     std::to_string(frame.left.rows) + ", the source's size is " + std::to_string(source_.width) + "x" +
                     std::to_string(source_.height));
  frame.left = convert(frame.left);
  frame.right = convert(frame.right);
  if (frame.gt_box && resizes()) {
    auto& b = *frame.gt_box;
    const double ax = sx(), ay = sy();
    b.box = cv::Rect2d((b.box.x + 0.5) * ax - 0.5, (b.box.y + 0.5) * ay - 0.5, b.box.width * ax, b.box.height * ay);
    for (auto& c : b.corners) c = {(c.x + 0.5) * ax - 0.5, (c.y + 0.5) * ay - 0.5};
  }
}

camera::RectifiedStereo OutputFormat::apply(const camera::RectifiedStereo& in) const {
  camera::RectifiedStereo out = in;
  out.size = size_;
  out.fx = in.fx * sx();
  out.fy = in.fy * sy();
  out.cx = (in.cx + 0.5) * sx() - 0.5;
  out.cy = (in.cy + 0.5) * sy() - 0.5;
  return out;
}

}  // namespace aerie::capture
