#pragma once
// DSST's scale filter (Danelljan et al. 2014, sec. 3.2): a 1-D correlation filter along S
// FHOG samples of the target at sizes step^(S/2 - i) times the current one, each resized to
// about model_area pixels of the target's aspect ratio. With resize_once, the region of the
// largest sample is resized once to the model's resolution and every sample is taken from it
// by a sub-pixel warp (as fDSST takes its scale samples from one pyramid level, Danelljan et
// al., TPAMI 2017): one area resize a frame instead of S.
#include <opencv2/core.hpp>
#include <vector>

#include "air/track/dcf/filters.hpp"

namespace aerie::track {

struct ScaleFilterParams {
  int scales = 33;
  double step = 1.02;
  double sigma = 0.25;        // of the Gaussian label, x sqrt(scales)
  double lambda = 1e-2;
  double model_area = 1024;   // pixels of each resized sample
  int cell = 4;               // FHOG cell
  bool resize_once = false;   // the samples from one resized region (above) instead of S resizes
};

class ScaleFilter {
 public:
  ScaleFilter() = default;
  // target: the target's size at scale 1, image pixels.
  ScaleFilter(const ScaleFilterParams& p, cv::Size2d target);
  // Learns the samples around pos at size target * scale (rate 1: replaces the model).
  void learn(const cv::Mat& frame, cv::Point2d pos, double scale, double rate);
  // The factor, one of the S sample sizes, whose sample the filter scores highest. Its samples
  // are kept for a learn() on the same frame at the same position and scale (the scale did not
  // change): the same samples, not computed twice.
  double best_change(const cv::Mat& frame, cv::Point2d pos, double scale);
  int scales() const { return p_.scales; }

 private:
  cv::Mat features(const cv::Mat& frame, cv::Point2d pos, double scale) const;  // DFT along the scales
  struct Sampled {  // best_change's samples and where they were taken
    const uchar* frame = nullptr;
    cv::Point2d pos;
    double scale = 0;
    cv::Mat xsf;
  };

  ScaleFilterParams p_;
  cv::Size2d target_;
  cv::Size model_;
  std::vector<double> factors_;
  cv::Mat hann_;  // 1 x S
  cv::Mat yf_;
  LinearFilter filter_;
  Sampled last_;
};

}  // namespace aerie::track
