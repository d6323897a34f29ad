#pragma once
// SGBM_F: coarse-to-fine semi-global matching (Hermann & Klette 2012; thesis ch. 4,
// "Disparity/Depth Map Estimation"). A prior disparity map is computed on the
// half-resolution pair over half the disparity range; at full resolution every pixel
// then searches only a window of `fine_window` disparities centred on twice the
// upsampled prior. The saving over full-range SGM follows eq. 4.3,
// gamma = 1 - t_C / t_S ~= eta (D - 9) / D - 1/8, with our fixed window in place of 9.
// When the window is half the range or more (small D) the coarse pass cannot pay for
// itself and plain full-range SGM runs instead.
#include <opencv2/core.hpp>

#include "air/stereo/sgbm_ctf/sgm.hpp"

namespace aerie::stereo {

struct SgbmCtfParams {
  SgmParams sgm;         // num_disparities is the full-resolution range D
  int fine_window = 16;  // disparities searched per pixel at full resolution (multiple of 16)
  void validate(const std::string& what = "sgbm_ctf") const;
};

struct SgbmCtfTimings {
  double pyramid_ms = 0, coarse_ms = 0, prior_ms = 0, fine_ms = 0;
  double total() const { return pyramid_ms + coarse_ms + prior_ms + fine_ms; }
};

class CoarseToFineSgbm {
 public:
  explicit CoarseToFineSgbm(const SgbmCtfParams& params = {});

  // Rectified CV_8UC1 pair of the same size -> CV_32F disparity (kInvalidDisparity holes).
  cv::Mat compute(const cv::Mat& left, const cv::Mat& right);

  const SgbmCtfParams& params() const { return params_; }
  const SgbmCtfTimings& timings() const { return timings_; }
  // Stage timings of the two SGM passes of the last call (census, costs, aggregation, selection).
  const SgmTimings& coarse_sgm_timings() const { return coarse_matcher_.timings(); }
  const SgmTimings& fine_sgm_timings() const { return fine_matcher_.timings(); }
  const cv::Mat& coarse_disparity() const { return coarse_; }  // half resolution, half range
  // Density eta of the coarse prior (valid fraction) of the last call (eq. 4.4).
  double coarse_density() const { return coarse_density_; }

  // Thesis eq. 4.3: the predicted saving of SGBM_F over full-range SGBM.
  static double predicted_saving(double density, int max_disparity) {
    return density * (max_disparity - 9.0) / max_disparity - 1.0 / 8.0;
  }

 private:
  SgbmCtfParams params_;
  SemiGlobalMatcher coarse_matcher_, fine_matcher_;
  SgbmCtfTimings timings_;
  cv::Mat left_half_, right_half_, coarse_, coarse_start_, offsets_;
  double coarse_density_ = 0;
};

}  // namespace aerie::stereo
