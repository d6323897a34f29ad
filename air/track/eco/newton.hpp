#pragma once
// The continuous-domain detection of C-COT and ECO (Danelljan et al., ECCV 2016 sec. 3.3;
// CVPR 2017): the response is the trigonometric polynomial of its DFT coefficients,
//   s(x, y) = 1 / (W H) sum_{k, l} S[l, k] exp(i 2 pi (k x / W + l y / H)),
// with signed frequencies, defined between the grid points; its maximum is refined from the
// best grid point by Newton's method on s's gradient and Hessian.
#include <opencv2/core.hpp>

namespace aerie::track {

// s and its derivatives at (x, y) (grid units) from the full DFT `spectrum` (CV_32FC2, H x W).
struct ResponseValue {
  double s = 0;
  double dx = 0, dy = 0, dxx = 0, dxy = 0, dyy = 0;
};
ResponseValue response_at(const cv::Mat& spectrum, cv::Point2d at);

// Newton's iterations from `start` (grid units, e.g. the best grid point). A step is taken only
// where the Hessian is negative definite and is limited to one grid unit per axis; stops early
// when the step is below 1e-4. Returns the maximum in grid units (may be outside [0, W)).
cv::Point2d newton_peak(const cv::Mat& spectrum, cv::Point2d start, int iterations);

}  // namespace aerie::track
