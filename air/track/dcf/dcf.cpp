#include "air/track/dcf/dcf.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "air/track/dcf/cf_params.hpp"
#include "air/track/dcf/fhog.hpp"
#include "air/track/dcf/window.hpp"

namespace aerie::track {
namespace {

using Complex = std::complex<float>;

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("dcf: " + what);
}

Complex* cptr(cv::Mat& m) { return m.ptr<Complex>(); }
const Complex* cptr(const cv::Mat& m) { return m.ptr<Complex>(); }

// Parabolic sub-cell refinement of a peak from its two circular neighbours.
double refine(float left, float centre, float right) {
  const double d = left - 2.0 * centre + right;
  return std::abs(d) < 1e-12 ? 0.0 : std::clamp(0.5 * (left - right) / d, -0.5, 0.5);
}

void blend(std::vector<cv::Mat>& model, const std::vector<cv::Mat>& sample, double rate) {
  model.resize(sample.size());
  for (size_t c = 0; c < sample.size(); ++c) track::blend(model[c], sample[c], rate);
}

}  // namespace

void DcfParams::validate() const {
  validate_correlation_filter(*this, "dcf");
  require(admm_mu > 0 && admm_beta >= 1 && admm_mu_max >= admm_mu, "bad ADMM settings");
}

cv::Mat masked_filter(const cv::Mat& xf, const cv::Mat& yf, const cv::Mat& mask, const DcfParams& p) {
  cv::Mat yx(xf.size(), CV_32FC2), sxx(xf.size(), CV_32F);
  const Complex* x = cptr(xf);
  const Complex* y = cptr(yf);
  for (size_t k = 0; k < xf.total(); ++k) {
    cptr(yx)[k] = y[k] * std::conj(x[k]);
    sxx.ptr<float>()[k] = std::norm(x[k]);
  }
  return masked_filter(yx, sxx, mask, p.admm());
}

namespace {
// Per-channel spectra as the rows of one matrix (LinearFilter's layout).
cv::Mat stack_rows(const std::vector<cv::Mat>& spectra) {
  cv::Mat out(static_cast<int>(spectra.size()), static_cast<int>(spectra[0].total()), CV_32FC2);
  for (size_t c = 0; c < spectra.size(); ++c) spectra[c].reshape(0, 1).copyTo(out.row(static_cast<int>(c)));
  return out;
}
}  // namespace

DcfTracker::DcfTracker(DcfParams params, std::string name) : p_(params), name_(std::move(name)) { p_.validate(); }

cv::Mat DcfTracker::window_patch(const cv::Mat& frame, cv::Point2d centre) const {
  return subwindow(frame, centre, fw_.window * scale_, fw_.model);
}

DcfTracker::Spectrum DcfTracker::translation_features(const cv::Mat& patch) const {
  std::vector<cv::Mat> channels = fhog(patch, p_.cell);
  cv::Mat gray;  // mean grey level per cell, centred
  cv::resize(to_gray(patch), gray, fw_.hann.size(), 0, 0, cv::INTER_AREA);
  gray.convertTo(gray, CV_32F, 1.0 / 255, -0.5);
  channels.push_back(gray);
  Spectrum xf(channels.size());
  for (size_t c = 0; c < channels.size(); ++c) cv::dft(channels[c].mul(fw_.hann), xf[c], cv::DFT_COMPLEX_OUTPUT);
  return xf;
}

// Every model learns the window at the current location and scale; the first frame
// initialises them.
void DcfTracker::learn(const cv::Mat& frame, bool first) {
  const cv::Mat patch = window_patch(frame, pos_);
  learn_translation(translation_features(patch), first ? 1.0 : p_.learning_rate);
  scale_filter_.learn(frame, pos_, scale_, first ? 1.0 : p_.scale_learning_rate);
  if (p_.hist_weight > 0)
    colour_.learn(patch, target_ * (fw_.model.width / fw_.window.width), first ? 1.0 : p_.hist_learning_rate);
}

void DcfTracker::learn_translation(const Spectrum& xf, double rate) {
  if (p_.spatial_mask) {
    Spectrum g(xf.size());
    for (size_t c = 0; c < xf.size(); ++c) g[c] = masked_filter(xf[c], fw_.yf, fw_.mask, p_);
    blend(filter_, g, rate);
    return;
  }
  linear_.learn(stack_rows(xf), fw_.yf.reshape(0, 1), rate);
}

void DcfTracker::init(const cv::Mat& frame, const cv::Rect2d& box) {
  validate_init(frame, box);
  frame_size_ = frame.size();
  pos_ = {box.x + box.width / 2, box.y + box.height / 2};
  target_ = box.size();
  scale_ = 1;
  frames_ = 0;
  unconfident_frames_ = 0;

  fw_ = filter_window(target_, p_.padding, p_.template_area, p_.cell, p_.mask_scale, p_.output_sigma);

  scale_filter_ = ScaleFilter(p_.scale_filter(), target_);
  colour_ = ColourHistogram(p_.hist_bins, p_.inner_padding);

  learn(frame, true);
  initialised_ = true;
}

DcfTracker::Detection DcfTracker::detect(const cv::Mat& frame, cv::Point2d centre) const {
  // Translation response: IDFT(sum_c G_c Z_c) (spatial_mask) or IDFT(sum_c conj(A_c) Z_c / (B + lambda)).
  const cv::Mat patch = window_patch(frame, centre);
  const Spectrum zf = translation_features(patch);
  cv::Mat rf;
  if (p_.spatial_mask) {  // sum_c G_c Z_c
    rf = cv::Mat(zf[0].size(), CV_32FC2, cv::Scalar::all(0));
    Complex* out = cptr(rf);
    for (size_t c = 0; c < zf.size(); ++c) {
      const Complex* z = cptr(zf[c]);
      const Complex* g = cptr(filter_[c]);
      for (size_t k = 0; k < rf.total(); ++k) out[k] += g[k] * z[k];
    }
  } else {
    rf = linear_.respond(stack_rows(zf), p_.lambda).reshape(0, zf[0].rows);
  }
  Detection d;
  d.centre = centre;
  cv::dft(rf, d.response, cv::DFT_INVERSE | cv::DFT_REAL_OUTPUT | cv::DFT_SCALE);

  // Reliability of the filter alone: its peak and the average peak-to-correlation energy
  // (APCE, Wang et al. 2017) = (max - min)^2 / mean((F - min)^2).
  double cf_min;
  cv::minMaxLoc(d.response, &cf_min, &d.peak);
  d.apce = (d.peak - cf_min) * (d.peak - cf_min) /
           std::max(1e-12, cv::mean((d.response - cf_min).mul(d.response - cf_min))[0]);

  // Staple: merge with the mean colour likelihood of a target-sized box at each shift.
  if (p_.hist_weight > 0)
    colour_.merge(d.response, patch, target_ * (fw_.model.width / fw_.window.width), p_.cell, p_.hist_weight);
  return d;
}

// The merged response's peak, refined to sub-cell precision, in image pixels.
cv::Point2d DcfTracker::peak_location(const Detection& d) const {
  const cv::Size cells = d.response.size();
  cv::Point at;
  cv::minMaxLoc(d.response, nullptr, nullptr, nullptr, &at);
  auto value = [&](int i, int j) {
    return d.response.at<float>((i + cells.height) % cells.height, (j + cells.width) % cells.width);
  };
  const double dy =
      circular(at.y, cells.height) + refine(value(at.y - 1, at.x), value(at.y, at.x), value(at.y + 1, at.x));
  const double dx =
      circular(at.x, cells.width) + refine(value(at.y, at.x - 1), value(at.y, at.x), value(at.y, at.x + 1));
  const double px_per_cell = p_.cell * fw_.window.width * scale_ / fw_.model.width;
  return d.centre + cv::Point2d(dx, dy) * px_per_cell;
}

TrackState DcfTracker::update(const cv::Mat& frame) {
  if (!initialised_) throw std::invalid_argument(name_ + ": update() before init()");
  validate_update(name_, frame, frame_size_);

  // Confidence (LMCF's criterion): the filter's peak and APCE relative to their running means;
  // below update_confidence (occlusion, loss) nothing is learned.
  Detection d = detect(frame, pos_);
  ++frames_;
  if (frames_ == 1) {
    mean_peak_ = d.peak;
    mean_apce_ = d.apce;
  }
  auto confidence_of = [&](const Detection& c) {
    return std::clamp(std::min(c.peak / mean_peak_, c.apce / mean_apce_), 0.0, 1.0);
  };
  double confidence = confidence_of(d);

  // Re-detection: after lost_frames unconfident frames, the windows around the current one
  // (3/4 of a window apart) are searched too; the best is taken if it reaches found_confidence.
  bool redetected = false;
  int windows = 1;
  if (p_.redetection && unconfident_frames_ >= p_.lost_frames) {
    for (const cv::Point2d& c : neighbour_windows(pos_, fw_.window * scale_, frame.size())) {
      Detection candidate = detect(frame, c);
      ++windows;
      const double conf = confidence_of(candidate);
      redetected = take_if_better(std::move(candidate), conf, p_.found_confidence, d, confidence) || redetected;
    }
  }
  mean_peak_ += p_.confidence_rate * (d.peak - mean_peak_);
  mean_apce_ += p_.confidence_rate * (d.apce - mean_apce_);
  const bool confident = confidence >= p_.update_confidence;
  unconfident_frames_ = confident ? 0 : unconfident_frames_ + 1;

  const cv::Point2d at = peak_location(d);
  pos_.x = std::clamp(at.x, 0.0, frame.cols - 1.0);
  pos_.y = std::clamp(at.y, 0.0, frame.rows - 1.0);
  scale_ = std::clamp(scale_ * scale_filter_.best_change(frame, pos_, scale_), p_.min_scale, p_.max_scale);
  if (confident) learn(frame, false);

  TrackState s;
  s.pose = {pos_.x, pos_.y, scale_, 0.0};
  s.initial_size = target_;
  s.confidence = confidence;
  s.lost = !confident;
  s.redetected = redetected;
  LevelStats level;
  level.evaluated = static_cast<int>(d.response.total()) * windows + p_.scales;
  level.search_radius = static_cast<float>(std::min(fw_.window.width, fw_.window.height) * scale_ / 2);
  s.levels.push_back(std::move(level));
  return s;
}

}  // namespace aerie::track
