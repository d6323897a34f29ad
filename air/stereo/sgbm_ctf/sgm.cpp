#include "air/stereo/sgbm_ctf/sgm.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "air/stereo/sgbm_ctf/sgm_kernels.hpp"
#include "air/stereo/cpu_time.hpp"

namespace aerie::stereo {
namespace {


int census_bits(const SgmParams& p) { return p.census_width * p.census_height - 1; }

}  // namespace

void SgmParams::validate(const std::string& what) const {
  auto fail = [&](const std::string& field, const std::string& expected) {
    throw std::invalid_argument(what + "." + field + ": " + expected);
  };
  if (num_disparities < kernels::kWindowStep || num_disparities % kernels::kWindowStep != 0)
    fail("num_disparities", "a positive multiple of 16 (got " + std::to_string(num_disparities) + ")");
  if (num_disparities > 1024) fail("num_disparities", "at most 1024");
  if (p1 <= 0 || p2 <= p1 || p2 > 2000) fail("p1/p2", "0 < P1 < P2 <= 2000");
  if (census_width < 3 || census_height < 3 || census_width % 2 == 0 || census_height % 2 == 0)
    fail("census_width/census_height", "odd sizes >= 3");
  if (census_bits(*this) > 64) fail("census_width/census_height", "at most 65 pixels (64 bits)");
  if (paths != 4 && paths != 8) fail("paths", "4 or 8");
  if (uniqueness_percent < 0 || uniqueness_percent >= 100) fail("uniqueness_percent", "0..99");
  if (speckle_window < 0 || speckle_range < 0) fail("speckle_window/speckle_range", ">= 0");
}

SemiGlobalMatcher::SemiGlobalMatcher(const SgmParams& params) : params_(params) {
  params_.validate();
  const int rx = params_.census_width / 2, ry = params_.census_height / 2;
  for (int dy = -ry; dy <= ry; ++dy)
    for (int dx = -rx; dx <= rx; ++dx)
      if (dx != 0 || dy != 0) {
        dx_.push_back(static_cast<short>(dx));
        dy_.push_back(static_cast<short>(dy));
      }
}

const char* SemiGlobalMatcher::simd_target() { return kernels::target_name(); }

cv::Mat SemiGlobalMatcher::compute(const cv::Mat& left, const cv::Mat& right) {
  zero_offsets_.assign(static_cast<size_t>(left.total()), 0);
  const cv::Mat offsets(left.size(), CV_16SC1, zero_offsets_.data());
  return compute(left, right, offsets, params_.num_disparities);
}

cv::Mat SemiGlobalMatcher::compute(const cv::Mat& left, const cv::Mat& right, const cv::Mat& offsets_in, int window) {
  if (left.empty() || left.type() != CV_8UC1 || right.type() != CV_8UC1 || left.size() != right.size())
    throw std::invalid_argument("SGM: left and right must be 8-bit gray images of the same size");
  if (offsets_in.type() != CV_16SC1 || offsets_in.size() != left.size())
    throw std::invalid_argument("SGM: offsets must be CV_16SC1 of the image size");
  const int D = params_.num_disparities;
  if (window < kernels::kWindowStep || window % kernels::kWindowStep != 0 || window > D)
    throw std::invalid_argument("SGM: window must be a multiple of 16 in [16, num_disparities], got " +
                                std::to_string(window));
  const cv::Mat offsets = offsets_in.isContinuous() ? offsets_in : offsets_in.clone();
  {
    double lo, hi;
    cv::minMaxLoc(offsets, &lo, &hi);
    if (lo < 0 || hi > D - window) throw std::invalid_argument("SGM: offsets outside [0, num_disparities - window]");
  }
  const int width = left.cols, height = left.rows;
  const int nbits = census_bits(params_), nplanes = (nbits + 7) / 8;
  const int rx = params_.census_width / 2, ry = params_.census_height / 2;
  const size_t npix = static_cast<size_t>(width) * height;
  timings_ = {};

  // 1. Census transform of both images into planes of 8 bits (row y, plane p, pixel x). The
  //    right image is mirrored (census of the flipped image with mirrored neighbours) so that
  //    the costs of consecutive disparities are contiguous; its D + 32 bytes of margin stand
  //    for the pixels left of the right image.
  CpuStopwatch sw;
  const ptrdiff_t cstep = width + D + 2 * kernels::kWindowStep;
  // (No clearing between calls: the margins are only read for costs the kernel masks.)
  census_left_.resize(static_cast<size_t>(cstep) * height * nplanes);
  census_right_.resize(census_left_.size());
  for (int side = 0; side < 2; ++side) {
    if (side) {
      cv::flip(right, flipped_, 1);
      for (auto& dx : dx_) dx = static_cast<short>(-dx);
    }
    cv::copyMakeBorder(side ? flipped_ : left, padded_, ry, ry, rx, rx, cv::BORDER_REPLICATE);
    kernels::CensusArgs ca{padded_.ptr<uint8_t>(ry) + rx, static_cast<ptrdiff_t>(padded_.step), width, height,
                           dx_.data(), dy_.data(), nbits, (side ? census_right_ : census_left_).data(), cstep};
    kernels::census(ca);
    if (side)
      for (auto& dx : dx_) dx = static_cast<short>(-dx);
  }
  timings_.census_ms = sw.ms();

  // 2. Matching costs: Hamming distance of the census strings over each pixel's window.
  sw.reset();
  cost_.resize(npix * window);
  for (int y = 0; y < height; ++y) {
    const size_t row = static_cast<size_t>(y) * nplanes * cstep;
    kernels::CostRowArgs cr{census_left_.data() + row, census_right_.data() + row, cstep, nplanes, nbits, width, window,
                            offsets.ptr<int16_t>(y), cost_.data() + static_cast<size_t>(y) * width * window};
    kernels::cost_row(cr);
  }
  timings_.cost_ms = sw.ms();

  // 3. Aggregation along 4 or 8 paths: one forward and one backward sweep.
  sw.reset();
  sum_.resize(npix * window);
  scratch_.resize(kernels::pass_scratch_size(width, window, params_.paths));
  for (bool forward : {true, false}) {
    kernels::PassArgs pa{cost_.data(), offsets.ptr<int16_t>(), sum_.data(), width, height, window, forward,
                         params_.paths, static_cast<uint16_t>(params_.p1), static_cast<uint16_t>(params_.p2),
                         scratch_.data()};
    kernels::aggregate_pass(pa);
  }
  timings_.aggregate_ms = sw.ms();

  // 4. Winner takes all with uniqueness, subpixel and the left-right check.
  sw.reset();
  cv::Mat disparity(height, width, CV_32FC1);
  const int rpad = D + kernels::kWindowStep;
  right_cost_.resize(static_cast<size_t>(rpad) + width);
  right_disp_.resize(right_cost_.size());
  for (int y = 0; y < height; ++y) {
    std::fill(right_cost_.begin(), right_cost_.end(), uint16_t{0xFFFF});
    std::fill(right_disp_.begin(), right_disp_.end(), -1);
    float* drow = disparity.ptr<float>(y);
    const int16_t* orow = offsets.ptr<int16_t>(y);
    kernels::SelectRowArgs sa{sum_.data() + static_cast<size_t>(y) * width * window, orow, width, window,
                              params_.uniqueness_percent, drow, params_.subpixel, right_cost_.data() + rpad,
                              right_disp_.data() + rpad,
                              static_cast<uint16_t>(params_.paths * (nbits + params_.p2))};
    kernels::select_row(sa);
    if (params_.lr_max_diff >= 0) {
      const int16_t* rdisp = right_disp_.data() + rpad;
      for (int x = 0; x < width; ++x) {
        if (drow[x] < 0) continue;
        const int d = static_cast<int>(drow[x] + 0.5f);  // rounded (disparities are >= 0)
        const int xr = x - d;
        if (xr < 0 || rdisp[xr] < 0 || std::abs(rdisp[xr] - d) > params_.lr_max_diff) drow[x] = kInvalidDisparity;
      }
    }
  }
  if (params_.speckle_window > 0) {
    cv::Mat d16;
    disparity.convertTo(d16, CV_16S, 16.0);
    cv::filterSpeckles(d16, -16, params_.speckle_window, 16 * params_.speckle_range);
    for (int y = 0; y < height; ++y) {
      const int16_t* s = d16.ptr<int16_t>(y);
      float* dr = disparity.ptr<float>(y);
      for (int x = 0; x < width; ++x)
        if (s[x] < 0) dr[x] = kInvalidDisparity;
    }
  }
  timings_.select_ms = sw.ms();
  return disparity;
}

}  // namespace aerie::stereo
