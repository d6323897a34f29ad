#include "air/track/tracker.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace aerie::track {

std::array<cv::Point2d, 4> TrackState::corners() const {
  const cv::Size2d s = size();
  const double c = std::cos(pose.theta), n = std::sin(pose.theta);
  const double hx = s.width / 2, hy = s.height / 2;
  std::array<cv::Point2d, 4> out;
  const double dx[4] = {-hx, hx, hx, -hx}, dy[4] = {-hy, -hy, hy, hy};
  for (int i = 0; i < 4; ++i) out[i] = {pose.x + c * dx[i] - n * dy[i], pose.y + n * dx[i] + c * dy[i]};
  return out;
}

cv::Rect2d TrackState::box() const {
  const cv::Size2d s = size();
  return {pose.x - s.width / 2, pose.y - s.height / 2, s.width, s.height};
}

int TrackState::samples_evaluated() const {
  int n = 0;
  for (const auto& l : levels) n += l.evaluated;
  return n;
}

void validate_init(const cv::Mat& frame, const cv::Rect2d& box) {
  if (frame.empty()) throw std::invalid_argument("tracker init: empty frame");
  if (frame.depth() != CV_8U || (frame.channels() != 1 && frame.channels() != 3))
    throw std::invalid_argument("tracker init: frame must be 8-bit gray or BGR");
  for (double v : {box.x, box.y, box.width, box.height})
    if (!std::isfinite(v)) throw std::invalid_argument("tracker init: box is not finite");
  if (box.width < 4 || box.height < 4)
    throw std::invalid_argument("tracker init: box " + std::to_string(box.width) + "x" + std::to_string(box.height) +
                                " is empty or smaller than 4x4 pixels");
  if (box.x < 0 || box.y < 0 || box.x + box.width > frame.cols || box.y + box.height > frame.rows)
    throw std::invalid_argument("tracker init: box (" + std::to_string(box.x) + ", " + std::to_string(box.y) + ", " +
                                std::to_string(box.width) + ", " + std::to_string(box.height) +
                                ") is not inside the " + std::to_string(frame.cols) + "x" +
                                std::to_string(frame.rows) + " image");
}

void validate_update(const std::string& tracker, const cv::Mat& frame, cv::Size init_size) {
  if (frame.empty()) throw std::invalid_argument(tracker + ": empty frame");
  if (frame.size() != init_size)
    throw std::invalid_argument(tracker + ": frame is " + std::to_string(frame.cols) + "x" + std::to_string(frame.rows) +
                                ", the tracker was initialised on " + std::to_string(init_size.width) + "x" +
                                std::to_string(init_size.height));
  if (frame.depth() != CV_8U || (frame.channels() != 1 && frame.channels() != 3))
    throw std::invalid_argument(tracker + ": frame must be 8-bit gray or BGR");
}

cv::Mat to_gray(const cv::Mat& frame) {
  if (frame.channels() == 1) return frame;
  cv::Mat g;
  cv::cvtColor(frame, g, cv::COLOR_BGR2GRAY);
  return g;
}

}  // namespace aerie::track
