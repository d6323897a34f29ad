#include "air/stereo/sgbm_ctf/sgbm_ctf.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "air/stereo/cpu_time.hpp"

namespace aerie::stereo {
namespace {

SgmParams coarse_params(const SgbmCtfParams& p) {
  SgmParams c = p.sgm;
  // Half the range, rounded up to the SIMD step.
  c.num_disparities = std::max(16, (p.sgm.num_disparities / 2 + 15) / 16 * 16);
  return c;
}

// Fills the holes of a coarse disparity row with the smaller (farther) of the nearest valid
// values on either side: holes are mostly occlusions, which belong to the background.
void fill_row(float* d, int n) {
  int last = -1;
  for (int x = 0; x < n; ++x) {
    if (d[x] >= 0) {
      last = x;
      continue;
    }
    int next = x;
    while (next < n && d[next] < 0) ++next;
    float v;
    if (last < 0 && next >= n)
      v = 0.f;
    else if (last < 0)
      v = d[next];
    else if (next >= n)
      v = d[last];
    else
      v = std::min(d[last], d[next]);
    for (int k = x; k < next; ++k) d[k] = v;
    x = next - 1;
  }
}

}  // namespace

void SgbmCtfParams::validate(const std::string& what) const {
  sgm.validate(what + ".sgm");
  if (fine_window < 16 || fine_window % 16 != 0 || fine_window > sgm.num_disparities)
    throw std::invalid_argument(what + ".fine_window: a multiple of 16 in [16, num_disparities], got " +
                                std::to_string(fine_window));
}

CoarseToFineSgbm::CoarseToFineSgbm(const SgbmCtfParams& params)
    : params_(params), coarse_matcher_(coarse_params(params)), fine_matcher_(params.sgm) {
  params_.validate();
}

cv::Mat CoarseToFineSgbm::compute(const cv::Mat& left, const cv::Mat& right) {
  if (left.empty() || left.size() != right.size() || left.type() != CV_8UC1 || right.type() != CV_8UC1)
    throw std::invalid_argument("SGBM_F: left and right must be 8-bit gray images of the same size");
  timings_ = {};
  CpuStopwatch sw;
  const int W = params_.fine_window, D = params_.sgm.num_disparities;
  if (2 * W >= D) {
    // A window of half the range or more saves less than the coarse pass costs: plain SGM.
    cv::Mat disparity = fine_matcher_.compute(left, right);
    timings_.fine_ms = sw.ms();
    coarse_ = cv::Mat();
    coarse_density_ = 0;
    return disparity;
  }
  // Half resolution by area averaging (a 2x2 box, no aliasing of the census patterns). The
  // scale factors, not a target size, select OpenCV's exact 2x2 path for odd sizes too.
  cv::resize(left, left_half_, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
  cv::resize(right, right_half_, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
  timings_.pyramid_ms = sw.ms();

  sw.reset();
  coarse_ = coarse_matcher_.compute(left_half_, right_half_);
  timings_.coarse_ms = sw.ms();

  // Prior: each full-resolution pixel's window is centred on twice the coarse disparity. Where
  // the 3x3 coarse neighbourhood spans little, centre on its middle so that both sides of
  // a depth edge stay inside the window.
  sw.reset();
  coarse_density_ = static_cast<double>(cv::countNonZero(coarse_ >= 0)) / static_cast<double>(coarse_.total());
  cv::Mat filled = coarse_.clone();
  for (int y = 0; y < filled.rows; ++y) fill_row(filled.ptr<float>(y), filled.cols);
  cv::Mat lo, hi;
  cv::erode(filled, lo, cv::Mat());
  cv::dilate(filled, hi, cv::Mat());
  // The window start of each coarse pixel, then replicated over its 2x2 full-resolution block.
  coarse_start_.create(filled.size(), CV_16SC1);
  for (int cy = 0; cy < filled.rows; ++cy) {
    const float* c = filled.ptr<float>(cy);
    const float* l = lo.ptr<float>(cy);
    const float* h = hi.ptr<float>(cy);
    int16_t* o = coarse_start_.ptr<int16_t>(cy);
    for (int cx = 0; cx < filled.cols; ++cx) {
      const float span = 2.f * (h[cx] - l[cx]);
      const float centre = span <= W - 4 ? (h[cx] + l[cx]) : 2.f * c[cx];
      const int start = static_cast<int>(centre + 0.5f) - W / 2;  // rounded (centre >= 0)
      o[cx] = static_cast<int16_t>(std::clamp(start, 0, D - W));
    }
  }
  offsets_.create(left.size(), CV_16SC1);
  for (int y = 0; y < left.rows; ++y) {
    const int16_t* c = coarse_start_.ptr<int16_t>(std::min(y / 2, filled.rows - 1));
    int16_t* o = offsets_.ptr<int16_t>(y);
    for (int x = 0; x < left.cols; ++x) o[x] = c[std::min(x / 2, filled.cols - 1)];
  }
  timings_.prior_ms = sw.ms();

  sw.reset();
  cv::Mat disparity = fine_matcher_.compute(left, right, offsets_, W);
  timings_.fine_ms = sw.ms();
  return disparity;
}

}  // namespace aerie::stereo
