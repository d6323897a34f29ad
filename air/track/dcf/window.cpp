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

FilterWindow filter_window(cv::Size2d target, double padding, double template_area, int cell, double mask_scale,
                           double output_sigma) {
  FilterWindow w;
  const double pad = padding * (target.width + target.height) / 2;
  const cv::Size2d window(target.width + pad, target.height + pad);
  const double r = std::sqrt(template_area / window.area());
  w.cells = {cv::getOptimalDFTSize(std::max(4, cvRound(window.width * r / cell))),
             cv::getOptimalDFTSize(std::max(4, cvRound(window.height * r / cell)))};
  w.model = w.cells * cell;
  w.window = {w.model.width / r, w.model.height / r};
  cv::createHanningWindow(w.hann, w.cells, CV_32F);
  w.mask = cv::Mat::zeros(w.cells, CV_32F);
  const double support_px = mask_scale * r / cell;
  const cv::Size support(std::min(w.cells.width, static_cast<int>(std::ceil(target.width * support_px))),
                         std::min(w.cells.height, static_cast<int>(std::ceil(target.height * support_px))));
  w.mask(cv::Rect((w.cells.width - support.width) / 2, (w.cells.height - support.height) / 2, support.width,
                  support.height))
      .setTo(1);
  const double sigma = std::sqrt(target.area()) * r / cell * output_sigma;
  cv::Mat y(w.cells, CV_32F);
  for (int i = 0; i < w.cells.height; ++i)
    for (int j = 0; j < w.cells.width; ++j) {
      const double di = circular(i, w.cells.height), dj = circular(j, w.cells.width);
      y.at<float>(i, j) = static_cast<float>(std::exp(-0.5 * (di * di + dj * dj) / (sigma * sigma)));
    }
  cv::dft(y, w.yf, cv::DFT_COMPLEX_OUTPUT);
  return w;
}

std::vector<cv::Point2d> neighbour_windows(cv::Point2d pos, cv::Size2d window, cv::Size image) {
  std::vector<cv::Point2d> out;
  const cv::Size2d step = window * 0.75;
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j)
      if (i != 0 || j != 0)
        out.emplace_back(std::clamp(pos.x + j * step.width, 0.0, image.width - 1.0),
                         std::clamp(pos.y + i * step.height, 0.0, image.height - 1.0));
  return out;
}

}  // namespace aerie::track
