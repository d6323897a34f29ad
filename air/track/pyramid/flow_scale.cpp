#include "air/track/pyramid/flow_scale.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/video/tracking.hpp>
#include <vector>

namespace aerie::track {
namespace {
double median(std::vector<double> v) {
  const size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  return v[m];
}
}  // namespace

FlowScale flow_scale(const cv::Mat& prev, const cv::Mat& next, const cv::Rect2d& box, int grid) {
  FlowScale out;
  // Work on a crop around the box: the points move by tens of pixels at most.
  const double margin = 40 + 0.5 * std::max(box.width, box.height);
  const cv::Rect roi = cv::Rect(cv::Point(static_cast<int>(box.x - margin), static_cast<int>(box.y - margin)),
                                cv::Point(static_cast<int>(box.x + box.width + margin),
                                          static_cast<int>(box.y + box.height + margin))) &
                       cv::Rect(0, 0, prev.cols, prev.rows);
  if (roi.width < 16 || roi.height < 16) return out;
  std::vector<cv::Point2f> p0, p1, pb;
  for (int j = 0; j < grid; ++j)
    for (int i = 0; i < grid; ++i) {
      const cv::Point2f p(static_cast<float>(box.x + box.width * (0.2 + 0.6 * (i + 0.5) / grid) - roi.x),
                          static_cast<float>(box.y + box.height * (0.2 + 0.6 * (j + 0.5) / grid) - roi.y));
      if (p.x >= 0 && p.y >= 0 && p.x < roi.width && p.y < roi.height) p0.push_back(p);
    }
  if (p0.size() < 8) return out;
  std::vector<uchar> st1, st2;
  std::vector<float> err;
  const cv::Mat a = prev(roi), b = next(roi);
  const cv::TermCriteria term(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 10, 0.03);
  cv::calcOpticalFlowPyrLK(a, b, p0, p1, st1, err, cv::Size(9, 9), 3, term);
  cv::calcOpticalFlowPyrLK(b, a, p1, pb, st2, err, cv::Size(9, 9), 3, term);
  std::vector<int> idx;
  std::vector<double> fb;
  for (size_t k = 0; k < p0.size(); ++k)
    if (st1[k] && st2[k]) {
      idx.push_back(static_cast<int>(k));
      fb.push_back(std::hypot(pb[k].x - p0[k].x, pb[k].y - p0[k].y));
    }
  if (idx.size() < 8) return out;
  const double fb_med = median(fb);
  std::vector<int> keep;
  for (size_t k = 0; k < idx.size(); ++k)
    if (fb[k] <= fb_med && fb[k] < 2.0) keep.push_back(idx[k]);
  if (keep.size() < 6) return out;
  std::vector<double> ratios, dx, dy;
  for (size_t i = 0; i < keep.size(); ++i) {
    dx.push_back(p1[keep[i]].x - p0[keep[i]].x);
    dy.push_back(p1[keep[i]].y - p0[keep[i]].y);
    for (size_t j = i + 1; j < keep.size(); ++j) {
      const double d0 = cv::norm(p0[keep[i]] - p0[keep[j]]);
      if (d0 > 1e-3) ratios.push_back(cv::norm(p1[keep[i]] - p1[keep[j]]) / d0);
    }
  }
  out.ok = true;
  out.ratio = median(ratios);
  out.shift = {median(dx), median(dy)};
  out.points = static_cast<int>(keep.size());
  return out;
}

}  // namespace aerie::track
