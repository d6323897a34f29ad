#pragma once
// The checks of the settings DCF and ECO share (their parameter structs name them alike).
#include <cmath>
#include <stdexcept>
#include <string>

namespace aerie::track {

// Throws std::invalid_argument("<tracker>: <what>") for the first bad shared setting.
template <typename P>
void validate_correlation_filter(const P& p, const std::string& tracker) {
  auto require = [&](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(tracker + ": " + what);
  };
  require(p.cell >= 1, "cell must be >= 1");
  require(p.padding >= 0 && std::isfinite(p.padding), "padding must be >= 0");
  require(p.template_area >= 16.0 * p.cell * p.cell, "template_area must hold at least 4x4 cells");
  require(p.output_sigma > 0 && p.lambda > 0 && p.scale_lambda > 0 && p.scale_sigma > 0,
          "sigmas and lambdas must be > 0");
  for (double r : {p.learning_rate, p.hist_learning_rate, p.scale_learning_rate, p.confidence_rate})
    require(r > 0 && r <= 1, "learning rates must be in (0, 1]");
  require(p.mask_scale > 0, "mask_scale must be > 0");
  require(p.admm_iterations >= 0, "admm_iterations must be >= 0");
  require(p.hist_weight >= 0 && p.hist_weight <= 1, "hist_weight must be in [0, 1]");
  require(p.hist_bins >= 2 && p.hist_bins <= 256 && (p.hist_bins & (p.hist_bins - 1)) == 0,
          "hist_bins must be a power of two in [2, 256]");
  require(p.inner_padding >= 0 && p.inner_padding < 1, "inner_padding must be in [0, 1)");
  require(p.scales >= 1 && p.scale_step > 1 && p.scale_model_area >= 4.0 * p.cell * p.cell * 4,
          "bad scale filter settings");
  require(p.min_scale > 0 && p.max_scale >= p.min_scale, "need 0 < min_scale <= max_scale");
  require(p.update_confidence >= 0 && p.update_confidence <= 1 && p.found_confidence >= 0 && p.found_confidence <= 1,
          "update_confidence and found_confidence must be in [0, 1]");
  require(p.lost_frames >= 1, "lost_frames must be >= 1");
}

// Re-detection's acceptance: a candidate replaces the current detection when its confidence
// reaches `found` and beats the current one.
template <typename Detection>
bool take_if_better(Detection&& candidate, double candidate_confidence, double found, Detection& current,
                    double& confidence) {
  if (candidate_confidence < found || candidate_confidence <= confidence) return false;
  current = std::move(candidate);
  confidence = candidate_confidence;
  return true;
}

}  // namespace aerie::track
