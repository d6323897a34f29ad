#pragma once
// Semi-global matching (Hirschmueller 2008) with census matching costs, 4 or 8 paths,
// uniqueness and left-right checks and subpixel refinement, over a per-pixel disparity
// window: pixel (x, y) searches [offsets(y, x), offsets(y, x) + window). With offsets = 0
// and window = num_disparities it is the classic full-range SGM; the coarse-to-fine
// SGBM_F (sgbm_ctf.hpp) restricts the window around the coarse result. OpenCV's
// StereoSGBM cannot take per-pixel ranges, hence this implementation (SIMD kernels in
// sgm_kernels.cpp).
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace aerie::stereo {

inline constexpr float kInvalidDisparity = -1.0f;

struct SgmParams {
  int num_disparities = 64;   // disparities 0 .. num_disparities-1; a multiple of 16
  int p1 = 8;                 // penalty of a disparity change of 1 between neighbours
  int p2 = 96;                // penalty of a larger change (P2 > P1)
  int census_width = 7;       // census window (odd sizes; width * height - 1 <= 64 bits)
  int census_height = 5;
  int paths = 4;              // 4 (horizontal + vertical) or 8 (+ diagonals)
  int uniqueness_percent = 10;  // a second minimum within this % of the best invalidates (0 = off)
  int lr_max_diff = 1;        // left-right consistency tolerance in pixels (< 0 = off)
  bool subpixel = true;       // parabola through the aggregated costs around the winner
  int speckle_window = 0;     // cv::filterSpeckles region size (0 = off)
  int speckle_range = 1;      // disparity step (px) that separates speckle regions

  // Throws std::invalid_argument naming the bad field.
  void validate(const std::string& what = "sgm") const;
};

struct SgmTimings {
  double census_ms = 0, cost_ms = 0, aggregate_ms = 0, select_ms = 0;
  double total() const { return census_ms + cost_ms + aggregate_ms + select_ms; }
};

class SemiGlobalMatcher {
 public:
  explicit SemiGlobalMatcher(const SgmParams& params = {});

  // Full range. left, right: rectified CV_8UC1 of the same size. Returns CV_32F left
  // disparities, kInvalidDisparity where unmatched or rejected.
  cv::Mat compute(const cv::Mat& left, const cv::Mat& right);
  // Restricted: offsets CV_16SC1 of the image size with 0 <= offset <= num_disparities - window,
  // window a multiple of 16.
  cv::Mat compute(const cv::Mat& left, const cv::Mat& right, const cv::Mat& offsets, int window);

  const SgmParams& params() const { return params_; }
  const SgmTimings& timings() const { return timings_; }
  // The SIMD instruction set the kernels run with here (e.g. "AVX2", "NEON").
  static const char* simd_target();

 private:
  SgmParams params_;
  SgmTimings timings_;
  std::vector<short> dx_, dy_;  // census neighbour offsets
  // Reused between calls (no allocation per frame once sizes settle).
  cv::Mat padded_, flipped_;
  std::vector<unsigned char> census_left_, census_right_, cost_;
  std::vector<unsigned short> sum_, scratch_, right_cost_;
  std::vector<short> right_disp_, zero_offsets_;
};

}  // namespace aerie::stereo
