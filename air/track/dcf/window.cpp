#include "air/track/dcf/window.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace aerie::track {

cv::Mat subwindow(const cv::Mat& image, cv::Point2d centre, cv::Size2d size, cv::Size out) {
  const cv::Rect r(cvFloor(centre.x - size.width / 2), cvFloor(centre.y - size.height / 2),
                   std::max(1, cvRound(size.width)), std::max(1, cvRound(size.height)));
  const cv::Rect inside = r & cv::Rect(0, 0, image.cols, image.rows);
  cv::Mat patch;
  if (inside.empty()) {  // wholly outside: the nearest border pixel everywhere
    const cv::Point p(std::clamp(r.x, 0, image.cols - 1), std::clamp(r.y, 0, image.rows - 1));
    cv::copyMakeBorder(image(cv::Rect(p, cv::Size(1, 1))), patch, 0, r.height - 1, 0, r.width - 1,
                       cv::BORDER_REPLICATE);
  } else if (inside == r) {
    patch = image(r);
  } else {
    cv::copyMakeBorder(image(inside), patch, inside.y - r.y, r.br().y - inside.br().y, inside.x - r.x,
                       r.br().x - inside.br().x, cv::BORDER_REPLICATE);
  }
  cv::Mat resized;
  cv::resize(patch, resized, out, 0, 0, out.area() < patch.size().area() ? cv::INTER_AREA : cv::INTER_LINEAR);
  return resized;
}

std::vector<float> hann(int n) {
  std::vector<float> w(n, 1.f);
  if (n > 1)
    for (int i = 0; i < n; ++i) w[i] = 0.5f * (1 - std::cos(2 * CV_PI * i / (n - 1)));
  return w;
}

}  // namespace aerie::track
