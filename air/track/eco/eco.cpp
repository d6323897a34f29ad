#include "air/track/eco/eco.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <utility>

#include "air/track/dcf/cf_params.hpp"
#include "air/track/dcf/fhog.hpp"
#include "air/track/dcf/window.hpp"
#include "air/track/eco/colour_names.hpp"
#include "air/track/eco/joint_filter.hpp"
#include "air/track/eco/newton.hpp"
#include "air/track/eco/projection.hpp"

namespace aerie::track {
namespace {

using Complex = std::complex<float>;
constexpr int kHogBlock = kFhogChannels + 1;  // FHOG and the grey level
constexpr int kGaussNewtonCg = 15;             // conjugate-gradient steps per Gauss-Newton step (ECO-HC's)

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("eco: " + what);
}

// A frame whose three channels are equal (a grey sequence stored as BGR) has no colour.
bool has_colour(const cv::Mat& frame, const cv::Rect& roi) {
  if (frame.channels() != 3) return false;
  std::vector<cv::Mat> ch;
  cv::split(frame(roi), ch);
  return cv::norm(ch[0], ch[1], cv::NORM_INF) > 0 || cv::norm(ch[1], ch[2], cv::NORM_INF) > 0;
}

// spectrum * exp(-i 2 pi (k dx / W + l dy / H)): the signal moved by (dx, dy) cells, s(x - d).
cv::Mat shifted(const cv::Mat& spectrum, cv::Point2d d) {
  cv::Mat out(spectrum.size(), CV_32FC2);
  const int w = spectrum.cols, h = spectrum.rows;
  std::vector<Complex> ex(w);
  for (int k = 0; k < w; ++k) ex[k] = std::polar(1.f, static_cast<float>(-2 * CV_PI * circular(k, w) * d.x / w));
  for (int l = 0; l < h; ++l) {
    const Complex ey = std::polar(1.f, static_cast<float>(-2 * CV_PI * circular(l, h) * d.y / h));
    const Complex* s = spectrum.ptr<Complex>(l);
    Complex* o = out.ptr<Complex>(l);
    for (int k = 0; k < w; ++k) o[k] = s[k] * ex[k] * ey;
  }
  return out;
}

}  // namespace

void EcoParams::validate() const {
  validate_correlation_filter(*this, "eco");
  require(hog_dims >= 1 && hog_dims <= kHogBlock, "hog_dims must be in [1, 32]");
  require(cn_dims >= 0 && cn_dims <= kColourNames, "cn_dims must be in [0, 11]");
  require(samples >= 1, "samples must be >= 1");
  require(update_interval >= 1, "update_interval must be >= 1");
  require(aberrance >= 0 && std::isfinite(aberrance), "aberrance must be >= 0");
  require(reg_floor >= 0 && reg_edge >= reg_floor && std::isfinite(reg_edge),
          "reg_floor and reg_edge must satisfy 0 <= reg_floor <= reg_edge");
  require(cg_iterations >= 1 && init_cg_iterations >= 1, "cg_iterations and init_cg_iterations must be >= 1");
  require(projection_steps >= 0 && projection_reg >= 0 && std::isfinite(projection_reg),
          "projection_steps and projection_reg must be >= 0");
  for (const auto& [value, name] : {std::pair{temporal_reg, "temporal_reg"}, {variation_gain, "variation_gain"},
                                     {variation_reg, "variation_reg"}, {variation_limit, "variation_limit"}})
    require(value >= 0 && std::isfinite(value), std::string(name) + " must be finite and >= 0");
  require(newton_iterations >= 0, "newton_iterations must be >= 0");
  require(lost_confidence >= 0 && lost_confidence <= 1, "lost_confidence must be in [0, 1]");
  require(lost_after >= 1, "lost_after must be >= 1");
  require(verify_threshold >= 0 && verify_threshold <= 1, "verify_threshold must be in [0, 1]");
  require(verify_after >= 1, "verify_after must be >= 1");
  require(verify_exemplars >= 1 && verify_exemplars <= 100, "verify_exemplars must be in [1, 100]");
  require(verify_learn_confidence >= 0 && verify_learn_confidence <= 1, "verify_learn_confidence must be in [0, 1]");
  require(verify_learn_similarity >= -1 && verify_learn_similarity <= 1, "verify_learn_similarity must be in [-1, 1]");
  require(verify_interval >= 1, "verify_interval must be >= 1");
  require(global_interval >= 0, "global_interval must be >= 0");
  require(global_pixels >= 1024, "global_pixels must be >= 1024");
  require(global_candidates >= 1, "global_candidates must be >= 1");
}

EcoTracker::EcoTracker(EcoParams params, std::string name) : p_(params), name_(std::move(name)) { p_.validate(); }

cv::Mat EcoTracker::raw_features(const cv::Mat& image, cv::Size& cells) const {
  const std::vector<cv::Mat> hog = fhog(image, p_.cell);
  cells = hog[0].size();
  const cv::Mat whole = image(cv::Rect(0, 0, cells.width * p_.cell, cells.height * p_.cell));
  const int n = cells.area();
  cv::Mat raw(kHogBlock + (colour_ ? kColourNames : 0), n, CV_32F);
  for (int c = 0; c < kFhogChannels; ++c) hog[c].reshape(1, 1).copyTo(raw.row(c));
  cv::Mat grey;  // mean grey level per cell, centred
  cv::resize(to_gray(whole), grey, cells, 0, 0, cv::INTER_AREA);
  grey.convertTo(raw.row(kFhogChannels).reshape(1, cells.height), CV_32F, 1.0 / 255, -0.5);
  if (colour_) {
    cv::Mat mean_colour;  // the colour names of each cell's mean colour (one lookup per cell)
    cv::resize(whole, mean_colour, cells, 0, 0, cv::INTER_AREA);
    const std::vector<cv::Mat> cn = colour_names(mean_colour, 1);
    for (int c = 0; c < kColourNames; ++c) cn[c].reshape(1, 1).copyTo(raw.row(kHogBlock + c));
  }
  return raw;
}

std::vector<cv::Mat> EcoTracker::projected(const cv::Mat& raw, cv::Size cells) const {
  std::vector<cv::Mat> maps;
  auto add = [&](const cv::Mat& block, const cv::Mat& P) {
    const cv::Mat x = project(block, P);
    for (int c = 0; c < x.rows; ++c) maps.push_back(x.row(c).clone().reshape(1, cells.height));
  };
  add(raw.rowRange(0, kHogBlock), hog_projection_);
  if (colour_ && !cn_projection_.empty()) add(raw.rowRange(kHogBlock, raw.rows), cn_projection_);
  return maps;
}

std::vector<cv::Mat> EcoTracker::spectra(const std::vector<cv::Mat>& maps) const {
  std::vector<cv::Mat> xf(maps.size());
  for (size_t c = 0; c < maps.size(); ++c) cv::dft(maps[c].mul(fw_.hann), xf[c], cv::DFT_COMPLEX_OUTPUT);
  return xf;
}

EcoTracker::Detection EcoTracker::detect(const cv::Mat& frame, cv::Point2d centre) const {
  Detection d;
  d.centre = centre;
  cv::Size cells;
  d.patch = subwindow(frame, centre, fw_.window * scale_, fw_.model);
  d.zf = spectra(projected(raw_features(d.patch, cells), cells));
  // Response spectrum sum_c G_c Z_c (the filters' convention: G = Y conj(X) / |X|^2).
  d.rf = cv::Mat(fw_.cells, CV_32FC2, cv::Scalar::all(0));
  float* out = d.rf.ptr<float>();  // interleaved re, im; g z in reals, as std::complex<float> computes it
  for (size_t c = 0; c < d.zf.size(); ++c) {
    const float* z = d.zf[c].ptr<float>();
    const float* g = filter_[c].ptr<float>();
    for (size_t k = 0; k < d.rf.total(); ++k) {
      out[2 * k] += g[2 * k] * z[2 * k] - g[2 * k + 1] * z[2 * k + 1];
      out[2 * k + 1] += g[2 * k] * z[2 * k + 1] + g[2 * k + 1] * z[2 * k];
    }
  }
  cv::dft(d.rf, d.response, cv::DFT_INVERSE | cv::DFT_REAL_OUTPUT | cv::DFT_SCALE);
  // Peak and average peak-to-correlation energy (APCE, Wang et al. 2017).
  double lo;
  cv::minMaxLoc(d.response, &lo, &d.peak);
  d.apce = (d.peak - lo) * (d.peak - lo) / std::max(1e-12, cv::mean((d.response - lo).mul(d.response - lo))[0]);
  if (p_.hist_weight > 0) colour_model_.merge(d.response, d.patch, target_in_model(), p_.cell, p_.hist_weight);
  cv::minMaxLoc(d.response, nullptr, nullptr, nullptr, &d.grid_peak);
  return d;
}

double EcoTracker::confidence_of(const Detection& d) const {
  return std::clamp(std::min(d.peak / mean_peak_, d.apce / mean_apce_), 0.0, 1.0);
}

double EcoTracker::colour_evidence(const Detection& d, cv::Point2d shift_cells) const {
  const cv::Size2d t = target_in_model();
  const cv::Point2d c(d.patch.cols / 2.0 + shift_cells.x * p_.cell, d.patch.rows / 2.0 + shift_cells.y * p_.cell);
  const cv::Rect box = cv::Rect(cvRound(c.x - t.width / 2), cvRound(c.y - t.height / 2), std::max(1, cvRound(t.width)),
                                std::max(1, cvRound(t.height))) &
                       cv::Rect(0, 0, d.patch.cols, d.patch.rows);
  return box.empty() ? 0.0 : cv::mean(colour_model_.likelihood(d.patch(box)))[0];
}

cv::Point2d EcoTracker::peak_offset(const Detection& d) const {
  const cv::Point2d grid(d.grid_peak);
  const cv::Point2d peak = newton_peak(d.rf, grid, p_.newton_iterations);
  const cv::Point2d moved = peak - grid;  // Newton's refinement: within a cell or two of the grid peak
  return {circular(d.grid_peak.x, fw_.cells.width) + moved.x, circular(d.grid_peak.y, fw_.cells.height) + moved.y};
}

void EcoTracker::add_sample(const Detection& d, cv::Point2d shift) {
  Sample s;
  for (const auto& z : d.zf) s.xf.push_back(shifted(z, -shift));  // ECO: the detection's sample, re-centred
  // ARCF: this frame's response (the filter before this update), aligned on its peak, scaled to
  // peak 1, mixed into the label: the new filter is kept from changing the response abruptly.
  const cv::Mat aligned = shifted(d.rf, -shift) / std::max(d.peak, 1e-12);
  s.yf = p_.aberrance > 0 ? (fw_.yf + p_.aberrance * aligned) / (1 + p_.aberrance) : fw_.yf;
  samples_.add(s);
}

cv::Mat EcoTracker::centred_response(const Detection& d, cv::Point2d shift) const {
  const cv::Point2d centre((fw_.cells.width - 1) / 2.0, (fw_.cells.height - 1) / 2.0);
  cv::Mat r;
  cv::dft(shifted(d.rf, centre - shift), r, cv::DFT_INVERSE | cv::DFT_REAL_OUTPUT | cv::DFT_SCALE);
  return r / std::max(d.peak, 1e-12);
}

// The filter from the whole sample space: per channel sum_m pi_m Y_m conj(X_m) and
// sum_m pi_m |X_m|^2, then CSR-DCF's constrained solution.
void EcoTracker::train() {
  const auto& comps = samples_.components();
  const auto& w = samples_.weights();
  if (p_.joint_filter) {
    // AutoTrack's regularisation from this frame's response variation (none on the first frame).
    cv::Mat w2 = regulariser_;
    TemporalPrior prior;
    if (frames_ > 0 && p_.variation_reg > 0 && !variation_.local.empty())
      w2 = varied_regulariser(regulariser_, variation_, target_cells(), p_.variation_reg * std::sqrt(energy_));  // w x sqrt(energy)
    if (frames_ > 0 && p_.temporal_reg > 0) {
      prior.theta = temporal_weight(p_.temporal_reg, p_.variation_gain, variation_.global) * energy_;
      for (const auto& g : filter_) prior.reference.push_back(g.clone());  // the filter moves in place
    }
    train_joint_filter(comps, w, w2, frames_ == 0 ? p_.init_cg_iterations : p_.cg_iterations, filter_, prior);
    since_training_ = 0;
    return;
  }
  const size_t channels = comps[0].xf.size(), n = static_cast<size_t>(fw_.cells.area());
  filter_.resize(channels);
  const AdmmSettings admm{p_.lambda, p_.admm_iterations, 5, 3, 20};
  for (size_t c = 0; c < channels; ++c) {
    cv::Mat yx(fw_.cells, CV_32FC2, cv::Scalar::all(0)), sxx(fw_.cells, CV_32F, cv::Scalar(0));
    float* a = yx.ptr<float>();  // interleaved re, im
    float* e = sxx.ptr<float>();
    for (size_t m = 0; m < comps.size(); ++m) {
      const float* x = comps[m].xf[c].ptr<float>();
      const float* y = comps[m].yf.ptr<float>();
      const float wm = static_cast<float>(w[m]);
      // (wm y) conj(x) and wm |x|^2 written out in reals (the operations of std::complex<float>,
      // in its order), so that the compiler vectorises the loop.
      for (size_t k = 0; k < n; ++k) {
        const float tr = wm * y[2 * k], ti = wm * y[2 * k + 1], xr = x[2 * k], xi = x[2 * k + 1];
        a[2 * k] += tr * xr - ti * -xi;
        a[2 * k + 1] += tr * -xi + ti * xr;
        e[k] += wm * (xr * xr + xi * xi);
      }
    }
    filter_[c] = masked_filter(yx, sxx, fw_.mask, admm);
  }
  since_training_ = 0;
}

cv::Mat EcoTracker::verifier_patch(const cv::Mat& window_patch, cv::Point2d offset, double model_per_px) const {
  const cv::Point2d centre = cv::Point2d(window_patch.cols / 2.0, window_patch.rows / 2.0) + offset * model_per_px;
  const cv::Size2d box = target_ * (scale_ * model_per_px * AppearanceVerifier::kGrowth);
  const int n = AppearanceVerifier::kPatch;
  return to_gray(subwindow(window_patch, centre, box, {n, n}));
}

void EcoTracker::init(const cv::Mat& frame, const cv::Rect2d& box) {
  validate_init(frame, box);
  frame_size_ = frame.size();
  pos_ = {box.x + box.width / 2, box.y + box.height / 2};
  target_ = box.size();
  scale_ = 1;
  frames_ = since_training_ = unconfident_frames_ = doubtful_frames_ = 0;
  const cv::Rect inside = cv::Rect(box) & cv::Rect(0, 0, frame.cols, frame.rows);
  colour_ = p_.cn_dims > 0 && has_colour(frame, inside.empty() ? cv::Rect(0, 0, frame.cols, frame.rows) : inside);

  fw_ = filter_window(target_, p_.padding, p_.template_area, p_.cell, p_.mask_scale, p_.output_sigma);
  filter_.clear();

  // Factorised convolution: each block's projection from the first window's cells (PCA).
  cv::Size cells;
  const cv::Mat window_patch = subwindow(frame, pos_, fw_.window, fw_.model);
  const cv::Mat raw = raw_features(window_patch, cells);
  hog_projection_ = pca_projection(raw.rowRange(0, kHogBlock), p_.hog_dims);
  cn_projection_ = colour_ ? pca_projection(raw.rowRange(kHogBlock, raw.rows), p_.cn_dims) : cv::Mat();
  Sample first{spectra(projected(raw, cells)), fw_.yf};
  last_response_ = cv::Mat();
  variation_ = {};
  if (p_.joint_filter) {  // SRDCF's regulariser, relative to this first sample's energy
    energy_ = std::max(mean_energy({first}, {1.0}), 1e-30);
    regulariser_ = spatial_regulariser(fw_.cells, target_cells(), p_.reg_floor, p_.reg_edge) * energy_;
  }
  if (p_.joint_filter && p_.projection_steps > 0) {
    // ECO's Gauss-Newton from the PCA: the projections learned with the filter on this window.
    std::vector<cv::Mat> raw_maps;
    for (int d = 0; d < raw.rows; ++d) raw_maps.push_back(raw.row(d).reshape(1, cells.height));
    std::vector<ProjectionBlock> blocks{{0, hog_projection_}};
    if (colour_) blocks.push_back({kHogBlock, cn_projection_});
    learn_projection(spectra(raw_maps), fw_.yf, regulariser_, p_.projection_reg, p_.projection_steps, kGaussNewtonCg,
                     blocks, filter_);
    hog_projection_ = blocks[0].P;
    if (colour_) cn_projection_ = blocks[1].P;
    first.xf = spectra(projected(raw, cells));  // the first sample in the learned projection
  }

  // ECO's minimum weight: a sample older than twice the capacity at the learning rate.
  samples_ = SampleSpace(p_.samples, p_.learning_rate,
                         p_.learning_rate * std::pow(1 - p_.learning_rate, 2.0 * p_.samples));
  samples_.add(first);
  train();
  scale_filter_ = ScaleFilter(p_.scale_filter(), target_);
  scale_filter_.learn(frame, pos_, scale_, 1.0);
  colour_model_ = ColourHistogram(p_.hist_bins, p_.inner_padding);
  if (p_.hist_weight > 0) colour_model_.learn(window_patch, target_in_model(), 1.0);
  // The verifier's first exemplar: the box given.
  verifier_ = AppearanceVerifier(p_.verify_exemplars);
  similarity_ = 1;
  unverified_frames_ = last_exemplar_ = 0;
  if (p_.verify_threshold > 0) verifier_.add(verifier_patch(window_patch, {0, 0}, fw_.model.width / fw_.window.width));
  initialised_ = true;
}

bool EcoTracker::search_whole_image(const cv::Mat& frame, Detection& best, double& confidence) const {
  // The frame at the filter's resolution (model pixels per image pixel), reduced to at most
  // global_pixels pixels: the coarse level.
  const double r = fw_.model.width / (fw_.window.width * scale_);
  const double q = std::min(1.0, std::sqrt(p_.global_pixels / (frame.total() * r * r)));
  const cv::Size size(cvRound(frame.cols * r * q), cvRound(frame.rows * r * q));
  if (size.width < 4 * p_.cell || size.height < 4 * p_.cell) return false;
  cv::Mat coarse;
  cv::resize(frame, coarse, size, 0, 0, r * q < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
  cv::Size cells;
  const std::vector<cv::Mat> maps = projected(raw_features(coarse, cells), cells);

  // The filter as a spatial kernel around the window's centre cell c0: a target at cell p of the
  // map scores sum_u g(c0 + u) F(p - u) (the window's circular convolution), resized by q.
  const cv::Point c0(fw_.cells.width / 2, fw_.cells.height / 2);
  const int rx = std::min(fw_.cells.width / 2, static_cast<int>(std::ceil(target_.width * scale_ * r / p_.cell / 2)) + 1);
  const int ry = std::min(fw_.cells.height / 2, static_cast<int>(std::ceil(target_.height * scale_ * r / p_.cell / 2)) + 1);
  cv::Mat score(cells, CV_32F, cv::Scalar(0));
  for (size_t c = 0; c < maps.size(); ++c) {
    cv::Mat g;
    cv::dft(filter_[c], g, cv::DFT_INVERSE | cv::DFT_REAL_OUTPUT | cv::DFT_SCALE);
    cv::Mat k(2 * ry + 1, 2 * rx + 1, CV_32F);
    for (int v = -ry; v <= ry; ++v)  // flipped for filter2D's correlation: k(v) = g(c0 - v)
      for (int u = -rx; u <= rx; ++u)
        k.at<float>(v + ry, u + rx) =
            g.at<float>((c0.y - v + fw_.cells.height) % fw_.cells.height, (c0.x - u + fw_.cells.width) % fw_.cells.width);
    if (q < 1) cv::resize(k, k, cv::Size(std::max(1, cvRound(k.cols * q)), std::max(1, cvRound(k.rows * q))), 0, 0,
                          cv::INTER_AREA);
    cv::Mat s;
    cv::filter2D(maps[c], s, CV_32F, k, cv::Point(-1, -1), 0, cv::BORDER_CONSTANT);
    score += s;
  }
  // The best few local maxima, each verified by a full-resolution detection there.
  bool found = false;
  const int suppress = std::max(1, cvRound(std::max(rx, ry) * q));
  for (int i = 0; i < p_.global_candidates; ++i) {
    cv::Point at;
    double v;
    cv::minMaxLoc(score, nullptr, &v, nullptr, &at);
    if (!std::isfinite(v) || v <= -1e30) break;
    cv::rectangle(score, cv::Rect(at.x - suppress, at.y - suppress, 2 * suppress + 1, 2 * suppress + 1),
                  cv::Scalar(-1e31), cv::FILLED);
    // Verified where the full-resolution response of a window there peaks (a second window
    // centred on that peak: the coarse position is a few pixels off).
    auto clamped = [&](cv::Point2d c) {
      return cv::Point2d(std::clamp(c.x, 0.0, frame.cols - 1.0), std::clamp(c.y, 0.0, frame.rows - 1.0));
    };
    const cv::Point2d c((at.x + 0.5) * p_.cell / (r * q), (at.y + 0.5) * p_.cell / (r * q));
    Detection d = detect(frame, clamped(c));
    d = detect(frame, clamped(d.centre + peak_offset(d) * (p_.cell / r)));
    const double conf = confidence_of(d);
    found = take_if_better(std::move(d), conf, p_.found_confidence, best, confidence) || found;
  }
  return found;
}

TrackState EcoTracker::update(const cv::Mat& frame) {
  if (!initialised_) throw std::invalid_argument(name_ + ": update() before init()");
  validate_update(name_, frame, frame_size_);

  Detection d = detect(frame, pos_);
  if (++frames_ == 1) {
    mean_peak_ = d.peak;
    mean_apce_ = d.apce;
  }
  double confidence = confidence_of(d);

  // Re-detection while lost, within a budget of 5 window detections per frame: half of the 8
  // neighbouring windows (3/4 of a window apart) in turn, the 4 sides and then the 4 corners;
  // every global_interval frames also the whole image (about 6 more).
  bool redetected = false;
  int windows = 1;
  if (p_.redetection && unconfident_frames_ >= p_.lost_frames) {
    const std::vector<cv::Point2d> around = neighbour_windows(pos_, fw_.window * scale_, frame.size());
    const bool corners = (unconfident_frames_ - p_.lost_frames) % 2 == 1;
    for (size_t k = 0; k < around.size(); ++k) {
      const bool corner = k == 0 || k == 2 || k == 5 || k == 7;  // neighbour_windows' row-major order
      if (corner != corners) continue;
      Detection candidate = detect(frame, around[k]);
      ++windows;
      const double conf = confidence_of(candidate);
      redetected = take_if_better(std::move(candidate), conf, p_.found_confidence, d, confidence) || redetected;
    }
    if (p_.global_interval > 0 && (unconfident_frames_ - p_.lost_frames) % p_.global_interval == 0) {
      windows += p_.global_candidates;
      redetected = search_whole_image(frame, d, confidence) || redetected;
    }
  }
  const bool confident = confidence >= p_.update_confidence;
  unconfident_frames_ = confident ? 0 : unconfident_frames_ + 1;

  const cv::Point2d shift = peak_offset(d);
  const double model_per_px = fw_.model.width / (fw_.window.width * scale_);  // of d's patch
  const double px_per_cell = p_.cell * fw_.window.width * scale_ / fw_.model.width;
  pos_.x = std::clamp(d.centre.x + shift.x * px_per_cell, 0.0, frame.cols - 1.0);
  pos_.y = std::clamp(d.centre.y + shift.y * px_per_cell, 0.0, frame.rows - 1.0);
  bool abnormal = false;  // AutoTrack: a response that changed this much is a failure, not learned from
  if (p_.joint_filter && spatio_temporal()) {
    const cv::Mat centred = centred_response(d, shift);
    variation_ = last_response_.empty() ? ResponseVariation{}
                                        : response_variation(last_response_, centred, target_cells());
    last_response_ = centred;
    abnormal = p_.variation_limit > 0 && variation_.global > p_.variation_limit;
  }
  if (confident) {
    // The running means of the reliability follow confident frames only, so that a long loss
    // does not lower the bar it is measured against.
    mean_peak_ += p_.confidence_rate * (d.peak - mean_peak_);
    mean_apce_ += p_.confidence_rate * (d.apce - mean_apce_);
    scale_ = std::clamp(scale_ * scale_filter_.best_change(frame, pos_, scale_), p_.min_scale, p_.max_scale);
    if (!abnormal) {
      add_sample(d, shift);
      if (++since_training_ >= p_.update_interval) train();
    }
    scale_filter_.learn(frame, pos_, scale_, p_.scale_learning_rate);
    if (p_.hist_weight > 0)
      colour_model_.learn(subwindow(frame, pos_, fw_.window * scale_, fw_.model), target_in_model(), p_.hist_learning_rate);
  }

  TrackState s;
  s.pose = {pos_.x, pos_.y, scale_, 0.0};
  s.initial_size = target_;
  // The filter's reliability and the colour model's evidence fail apart: a target turned or
  // blurred lowers the first and keeps its colours, a box on background loses both
  // (docs/results/track.md, "The LOST flag").
  s.confidence = p_.colour_evidence && p_.hist_weight > 0 ? confidence * colour_evidence(d, shift) : confidence;
  doubtful_frames_ = s.confidence < p_.lost_confidence ? doubtful_frames_ + 1 : 0;
  s.lost = doubtful_frames_ >= p_.lost_after;
  if (p_.verify_threshold > 0) {
    // The conservative verifier: does the box still look like the target? It learns only on
    // very confident frames that also pass it, so a box sliding onto what the filter has come to
    // match does not teach it (TLD's conservative model, Kalal et al. 2012).
    const cv::Mat patch = verifier_patch(d.patch, pos_ - d.centre, model_per_px);
    similarity_ = verifier_.similarity(patch);
    unverified_frames_ = similarity_ < p_.verify_threshold ? unverified_frames_ + 1 : 0;
    s.lost = s.lost || unverified_frames_ >= p_.verify_after;
    if (confidence >= p_.verify_learn_confidence && similarity_ >= p_.verify_learn_similarity &&
        frames_ - last_exemplar_ >= p_.verify_interval) {
      verifier_.add(patch);
      last_exemplar_ = frames_;
    }
  }
  s.redetected = redetected;
  LevelStats level;
  level.evaluated = static_cast<int>(d.response.total()) * windows + (confident ? p_.scales : 0);
  level.search_radius = static_cast<float>(std::min(fw_.window.width, fw_.window.height) * scale_ / 2);
  s.levels.push_back(std::move(level));
  return s;
}

}  // namespace aerie::track
