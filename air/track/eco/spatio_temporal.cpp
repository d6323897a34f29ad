#include "air/track/eco/spatio_temporal.hpp"

#include <cmath>
#include <stdexcept>

namespace aerie::track {
namespace {

// The target's box of cells around the grid's centre, clipped to the grid.
cv::Rect target_box(cv::Size cells, cv::Size2d target_cells) {
  const double cx = (cells.width - 1) / 2.0, cy = (cells.height - 1) / 2.0;
  const cv::Point tl(static_cast<int>(std::ceil(cx - target_cells.width / 2)),
                     static_cast<int>(std::ceil(cy - target_cells.height / 2)));
  const cv::Point br(static_cast<int>(std::floor(cx + target_cells.width / 2)) + 1,
                     static_cast<int>(std::floor(cy + target_cells.height / 2)) + 1);
  return cv::Rect(tl, br) & cv::Rect(cv::Point(0, 0), cells);
}

}  // namespace

ResponseVariation response_variation(const cv::Mat& previous, const cv::Mat& current, cv::Size2d target_cells) {
  if (previous.size() != current.size() || previous.type() != CV_32F || current.type() != CV_32F)
    throw std::invalid_argument("response variation: the two responses are not CV_32F maps of one size");
  if (!(target_cells.width > 0 && target_cells.height > 0))
    throw std::invalid_argument("response variation: the target must have a positive size");
  ResponseVariation v;
  v.local = cv::abs(current - previous);
  const cv::Rect box = target_box(current.size(), target_cells);
  if (!box.empty()) {
    const cv::Mat inside = v.local(box);
    v.global = std::sqrt(inside.dot(inside) / static_cast<double>(box.area()));
  }
  return v;
}

double temporal_weight(double theta0, double nu, double global) { return theta0 / (1 + std::log1p(nu * global)); }

cv::Mat varied_regulariser(const cv::Mat& w2, const ResponseVariation& variation, cv::Size2d target_cells,
                           double delta) {
  if (variation.local.size() != w2.size() || w2.type() != CV_32F)
    throw std::invalid_argument("varied regulariser: the variation and the regulariser are not of one grid");
  cv::Mat w;
  cv::sqrt(w2, w);
  const cv::Rect box = target_box(w2.size(), target_cells);
  cv::Mat added;
  cv::log(variation.local(box) + 1, added);
  w(box) += delta * added;
  return w.mul(w);
}

}  // namespace aerie::track
