#pragma once
// ECO: a correlation-filter tracker built, in Aerie's own code, from the ideas that make the
// hand-crafted ECO-HC (Danelljan et al., "ECO: Efficient Convolution Operators for Tracking",
// CVPR 2017) and the UAV-oriented filters robust:
//
//  * features: FHOG (31) and grey level per cell, plus colour names (11) on colour footage;
//  * factorised convolution: each feature block is projected to a few channels by a matrix
//    learned (PCA) on the first frame (projection.hpp);
//  * a generative sample space: a Gaussian mixture of past samples trains the filter instead of a
//    running average (sample_space.hpp);
//  * sparse updates: the filter is retrained from the sample space every update_interval frames;
//  * continuous-domain detection: the response's Fourier series is maximised by Newton's method
//    to sub-cell precision (newton.hpp);
//  * background suppression: the filter is constrained to the target's support while trained on
//    every shift of a large window (BACF, Kiani Galoogahi et al. 2017; CSR-DCF's ADMM);
//  * aberrance repression (ARCF, Huang, Fu et al. 2019): the training label mixes the ideal
//    Gaussian with the previous response map aligned on its peak, which penalises sudden changes
//    of the response between frames;
//  * optionally ECO's own training (one joint filter, SRDCF's regulariser, conjugate gradient;
//    joint_filter.hpp) with AutoTrack's spatio-temporal regularisation (spatio_temporal.hpp);
//  * colour: Staple's foreground/background histogram likelihood merged with the response (as dcf);
//  * scale: DSST's scale filter;
//  * loss and re-detection: the state says lost once the response's peak or APCE has stayed far
//    below its running mean for a few frames, or once the box has stopped looking like the
//    target's conservative exemplars for a few frames (verifier.hpp: TLD's conservative model;
//    the flag only, never the track); while lost, the 8 neighbouring windows are searched
//    every frame and,
//    every global_interval frames, the whole image at a coarse resolution (the filter as a
//    spatial kernel over the image's feature map), the best candidates then verified at full
//    resolution.
//
// Deterministic (no randomness): the seed is unused.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "air/track/dcf/colour_histogram.hpp"
#include "air/track/dcf/filters.hpp"
#include "air/track/dcf/scale_filter.hpp"
#include "air/track/dcf/window.hpp"
#include "air/track/eco/sample_space.hpp"
#include "air/track/eco/spatio_temporal.hpp"
#include "air/track/eco/verifier.hpp"
#include "air/track/tracker.hpp"

namespace aerie::track {

struct EcoParams {
  // Window and filter (as dcf).
  int cell = 4;                      // FHOG and colour-names cell, pixels of the resized window
  double padding = 2.0;              // window = target + padding * (w + h) / 2 per side
  double template_area = 200 * 200;  // the window is resized to about this many pixels
  double output_sigma = 1.0 / 16;    // Gaussian label sigma, x sqrt(target area) (in cells)
  double lambda = 1e-3;              // filter regularisation
  double mask_scale = 1.1;           // the filter's support is the target box times this
  int admm_iterations = 4;
  // ECO's joint training instead (joint_filter.hpp): one filter over all channels, SRDCF's
  // spatial regulariser in place of the mask (w^2 times the first sample's mean energy: reg_floor
  // at the centre, reg_edge on the target's border), conjugate gradient warm-started from the
  // last filter (init_cg_iterations on the first frame, cg_iterations at each training).
  bool joint_filter = false;
  double reg_floor = 1e-5;
  double reg_edge = 0.1;
  int cg_iterations = 5;
  int init_cg_iterations = 50;
  // With the joint filter, ECO's learned projection: projection_steps Gauss-Newton steps on the
  // first frame from the PCA (0: the PCA is kept), its regularisation relative (joint_filter.hpp).
  int projection_steps = 0;
  double projection_reg = 1e-3;
  // With the joint filter, AutoTrack's automatic spatio-temporal regularisation
  // (spatio_temporal.hpp), from the change of the response between frames: a temporal prior
  // theta ||G - G_last||^2 with theta = temporal_reg / (1 + log(1 + variation_gain ||Pi||)) x the
  // first sample's mean energy (0: none); variation_reg x log(1 + Pi) added to SRDCF's w on the
  // target's cells (0: none); no sample learned from a frame whose ||Pi|| exceeds
  // variation_limit (0: no limit).
  double temporal_reg = 0;
  double variation_gain = 1;
  double variation_reg = 0;
  double variation_limit = 0;
  // Factorised convolution: channels after projection.
  int hog_dims = 10;                 // of FHOG + grey (32)
  int cn_dims = 3;                   // of the colour names (11), colour footage only
  // Sample space and sparse updates (ECO-HC: 30 components, learning rate 0.009, N_s = 6).
  int samples = 30;
  double learning_rate = 0.01;
  int update_interval = 3;           // frames between filter trainings
  // ARCF: the label is (y + aberrance * M_prev) / (1 + aberrance); 0 switches it off.
  double aberrance = 0.3;
  int newton_iterations = 5;
  // Staple's colour histogram merged with the response (weight 0 switches it off).
  double hist_weight = 0.3;
  int hist_bins = 32;
  double hist_learning_rate = 0.04;
  double inner_padding = 0.2;
  // Scale filter (DSST).
  int scales = 33;
  double scale_step = 1.02;
  double scale_sigma = 0.25;
  double scale_lambda = 1e-2;
  double scale_learning_rate = 0.025;
  double scale_model_area = 1024;
  bool scale_resize_once = true;  // the samples from one resized region (ScaleFilterParams::resize_once)
  double min_scale = 0.2, max_scale = 5;
  // Loss. The filter's reliability = min(peak, APCE) relative to their running means; below
  // update_confidence nothing is learned. The confidence the state reports is that reliability
  // times, with colour_evidence (and the colour model on), the colour model's evidence that the
  // box holds the target: the mean of P(foreground | colour) over the box. The state says lost
  // once the confidence has stayed below lost_confidence for lost_after frames in a row (the
  // LOST flag, measured as a detector in docs/results/track.md), until it is above again.
  double update_confidence = 0.3;
  double confidence_rate = 0.05;
  bool colour_evidence = true;
  double lost_confidence = 0.08;  // chosen on simulated exits (bench/track/lost_rule.py)
  int lost_after = 2;
  // Appearance verifier (verifier.hpp; TLD's conservative model, Kalal et al. 2012): the state
  // also says lost once the similarity (largest normalised cross-correlation of the box's grey
  // 16x16 patch with the exemplars) has stayed below verify_threshold for verify_after frames in
  // a row; 0 switches it off. Exemplars: the first frame's box, then the box of a frame whose
  // confidence reaches verify_learn_confidence and whose similarity reaches
  // verify_learn_similarity, at most one every verify_interval frames, verify_exemplars at most
  // (the first kept, the oldest of the others replaced). It changes the LOST flag only.
  double verify_threshold = 0;  // off: chosen on simulated exits (bench/track/lost_rule.py); 0.4 was before 2026-11-27
  int verify_after = 5;
  int verify_exemplars = 8;
  double verify_learn_confidence = 0.9;
  double verify_learn_similarity = 0.7;
  int verify_interval = 10;
  // Re-detection: after lost_frames unconfident frames in a row, the 8 windows around the current
  // one every frame, and every global_interval frames the whole image at a resolution of at most
  // global_pixels pixels; a candidate is taken when its confidence reaches found_confidence.
  bool redetection = true;
  int lost_frames = 3;
  double found_confidence = 0.7;
  int global_interval = 5;           // 0: no whole-image search
  double global_pixels = 320 * 240;
  int global_candidates = 3;         // peaks of the coarse response verified at full resolution

  void validate() const;  // throws std::invalid_argument naming the bad value
  ScaleFilterParams scale_filter() const {
    return {scales, scale_step, scale_sigma, scale_lambda, scale_model_area, cell, scale_resize_once};
  }
};

class EcoTracker : public Tracker {
 public:
  explicit EcoTracker(EcoParams params, std::string name = "eco");
  std::string name() const override { return name_; }
  void init(const cv::Mat& frame, const cv::Rect2d& box) override;
  TrackState update(const cv::Mat& frame) override;
  // The verifier's similarity of the last box (1 before the first update and while it is switched off).
  double similarity() const { return similarity_; }

 private:
  struct Detection {
    cv::Point2d centre;          // of the window, image pixels
    std::vector<cv::Mat> zf;     // projected, windowed feature spectra
    cv::Mat patch;               // the window resized to the model
    cv::Mat rf, response;        // the filter's response spectrum; its IDFT merged with the colour likelihood
    double peak = 0, apce = 0;   // of the filter's response alone
    cv::Point grid_peak;         // best cell of the merged response
  };

  // Raw features of an image (window patch or whole frame): one row per channel (FHOG + grey
  // [+ colour names]), one column per cell; cells: the grid size.
  cv::Mat raw_features(const cv::Mat& image, cv::Size& cells) const;
  std::vector<cv::Mat> projected(const cv::Mat& raw, cv::Size cells) const;  // C maps of `cells`
  std::vector<cv::Mat> spectra(const std::vector<cv::Mat>& maps) const;      // windowed DFTs
  Detection detect(const cv::Mat& frame, cv::Point2d centre) const;
  double confidence_of(const Detection& d) const;
  // Mean P(foreground | colour) over the target's box in d's patch, moved by the sub-cell shift.
  double colour_evidence(const Detection& d, cv::Point2d shift_cells) const;
  cv::Point2d peak_offset(const Detection& d) const;  // sub-cell peak as a shift in cells
  bool search_whole_image(const cv::Mat& frame, Detection& best, double& confidence) const;
  void add_sample(const Detection& d, cv::Point2d shift_cells);
  // The filter's response of d, its peak moved to the grid's centre, scaled to peak 1.
  cv::Mat centred_response(const Detection& d, cv::Point2d shift_cells) const;
  bool spatio_temporal() const { return p_.temporal_reg > 0 || p_.variation_reg > 0 || p_.variation_limit > 0; }
  cv::Size2d target_in_model() const { return target_ * (fw_.model.width / fw_.window.width); }
  cv::Size2d target_cells() const { return target_in_model() * (1.0 / p_.cell); }
  void train();
  // The verifier's patch of the box centred `offset` image pixels from the centre of a window
  // patch (a detection's, already resized to the model: cheap whatever the target's size).
  cv::Mat verifier_patch(const cv::Mat& window_patch, cv::Point2d offset, double model_per_px) const;

  EcoParams p_;
  std::string name_;
  cv::Size frame_size_;
  bool initialised_ = false;
  bool colour_ = false;         // colour names in use (a colour init frame)

  cv::Point2d pos_;
  cv::Size2d target_;           // initial target size, image pixels
  double scale_ = 1;
  FilterWindow fw_;             // window, model size, cells, taper, support, label
  cv::Mat regulariser_;         // w^2 of the joint filter, x energy_
  double energy_ = 1;           // the first sample's mean energy
  cv::Mat last_response_;       // centred_response of the last frame (AutoTrack)
  ResponseVariation variation_; // from it to this frame's
  cv::Mat hog_projection_, cn_projection_;  // D x C per block

  SampleSpace samples_{1, 1, 0};
  std::vector<cv::Mat> filter_;  // G_c per projected channel
  ScaleFilter scale_filter_;
  ColourHistogram colour_model_;

  double mean_peak_ = 0, mean_apce_ = 0;
  int frames_ = 0, since_training_ = 0, unconfident_frames_ = 0, doubtful_frames_ = 0;

  AppearanceVerifier verifier_;
  double similarity_ = 1;
  int unverified_frames_ = 0, last_exemplar_ = 0;
};

}  // namespace aerie::track
