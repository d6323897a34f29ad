#pragma once
// DCF: a discriminative correlation filter tracker with scale adaptation and recovery of the
// target after occlusion or loss, which the thesis names as future work for its discriminative
// trackers (Conclusions), built from published methods:
//
//  * translation: a correlation filter per channel of FHOG + grey-level cells of a padded,
//    cosine-windowed window resized to a fixed area;
//  * colour: Staple's per-pixel foreground/background histogram likelihood (Bertinetto et al.
//    2016), averaged over the target box, merged with the filter response;
//  * scale: DSST's separate 1-D scale filter over S scales (Danelljan et al. 2014, sec. 3.2);
//  * spatial support: the filter is constrained to the target box (CSR-DCF, Lukezic et al. 2017),
//    so that a large window does not learn the background;
//  * occlusion: no learning while the filter's peak or APCE is well below its running mean;
//  * re-detection: after a few such frames the windows around the current one are searched.
//
// Deterministic (no randomness): the seed is unused.
#include <complex>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "air/track/dcf/colour_histogram.hpp"
#include "air/track/dcf/filters.hpp"
#include "air/track/dcf/scale_filter.hpp"
#include "air/track/dcf/window.hpp"
#include "air/track/tracker.hpp"

namespace aerie::track {

// Defaults: Staple's, DSST's and CSR-DCF's published settings except padding, template_area,
// mask_scale, scale_model_area, update_confidence and the re-detection's, chosen on the shared set
// (docs/results/track.md, with the neighbourhood measured around them).
struct DcfParams {
  // Translation filter.
  int cell = 4;                    // FHOG cell, pixels of the resized window
  double padding = 2.0;            // window = target + padding * (w + h) / 2 per side
  double template_area = 250 * 250;  // the window is resized to this many pixels
  double output_sigma = 1.0 / 16;  // Gaussian label sigma, x sqrt(target area) (in cells)
  double lambda = 1e-3;            // regularisation of the filter
  double learning_rate = 0.01;     // eta of the running filter
  // CSR-DCF's spatial constraint: the filter is zero outside the (scaled) target box (ADMM);
  // false: the unconstrained filter (running numerator and denominator).
  bool spatial_mask = true;
  double mask_scale = 1.1;         // the support is the target box times this
  int admm_iterations = 4;
  double admm_mu = 5, admm_beta = 3, admm_mu_max = 20;
  // Colour histogram model (Staple); weight 0 switches it off.
  double hist_weight = 0.3;        // merge: (1 - w) filter + w histogram
  int hist_bins = 32;              // per colour channel (grey frames: one channel)
  double hist_learning_rate = 0.04;
  double inner_padding = 0.2;      // foreground = target shrunk by this x (w + h) / 2
  // Scale filter (DSST).
  int scales = 33;
  double scale_step = 1.02;
  double scale_sigma = 0.25;       // x sqrt(scales)
  double scale_lambda = 1e-2;
  double scale_learning_rate = 0.025;
  double scale_model_area = 1024;  // scale samples are resized to this many pixels
  bool scale_resize_once = false;  // the samples from one resized region (ScaleFilterParams::resize_once)
  double min_scale = 0.2, max_scale = 5;  // relative to the initial box
  // Occlusion. Confidence = min(peak, APCE) of the filter relative to their running means:
  // below update_confidence the models are not updated and the state says lost.
  double update_confidence = 0.3;
  double confidence_rate = 0.05;   // weight of a new frame in the running means
  // Re-detection: after lost_frames frames below update_confidence in a row, the 8 windows
  // around the current one are searched too, and the best taken if it reaches found_confidence.
  bool redetection = true;
  int lost_frames = 3;
  double found_confidence = 0.7;

  void validate() const;  // throws std::invalid_argument naming the bad value
  AdmmSettings admm() const { return {lambda, admm_iterations, admm_mu, admm_beta, admm_mu_max}; }
  ScaleFilterParams scale_filter() const {
    return {scales, scale_step, scale_sigma, scale_lambda, scale_model_area, cell, scale_resize_once};
  }
};

// CSR-DCF's constrained filter of one channel (Lukezic et al. 2017, eqs. 6-8): the G
// (response IDFT(G Z)) minimising |X G - Y|^2 + lambda / 2 |g|^2 over filters g = IDFT(G) that
// are zero outside `mask`, by the augmented Lagrangian (ADMM: admm_iterations steps, penalty
// admm_mu growing by admm_beta per step up to admm_mu_max). xf, yf: CV_32FC2 full DFTs of the
// (windowed) feature channel and the label; mask: CV_32F of 0/1, same size.
cv::Mat masked_filter(const cv::Mat& xf, const cv::Mat& yf, const cv::Mat& mask, const DcfParams& p);

class DcfTracker : public Tracker {
 public:
  explicit DcfTracker(DcfParams params, std::string name = "dcf");
  std::string name() const override { return name_; }
  void init(const cv::Mat& frame, const cv::Rect2d& box) override;
  TrackState update(const cv::Mat& frame) override;

 private:
  using Spectrum = std::vector<cv::Mat>;  // CV_32FC2 per feature channel
  struct Detection {
    cv::Point2d centre;    // of the window, image pixels
    cv::Mat response;      // per cell shift: filter, merged with the colour likelihood
    double peak = 0, apce = 0;  // of the filter's response alone
  };

  Detection detect(const cv::Mat& frame, cv::Point2d centre) const;
  cv::Point2d peak_location(const Detection& d) const;
  cv::Mat window_patch(const cv::Mat& frame, cv::Point2d centre) const;  // at scale_, resized
  Spectrum translation_features(const cv::Mat& patch) const;
  void learn_translation(const Spectrum& xf, double rate);
  void learn(const cv::Mat& frame, bool first);

  DcfParams p_;
  std::string name_;
  cv::Size frame_size_;
  bool initialised_ = false;

  cv::Point2d pos_;
  cv::Size2d target_;    // initial target size, image pixels
  double scale_ = 1;     // current size / initial size
  FilterWindow fw_;      // window at scale 1, model size, taper, support (mask), label spectrum
  LinearFilter linear_;  // !spatial_mask: the unconstrained filter
  Spectrum filter_;      // spatial_mask: G_c per channel, running

  ScaleFilter scale_filter_;

  ColourHistogram colour_;
  double mean_peak_ = 0, mean_apce_ = 0;
  int frames_ = 0;
  int unconfident_frames_ = 0;  // in a row
};

}  // namespace aerie::track
