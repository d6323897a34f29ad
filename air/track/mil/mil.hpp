#pragma once
// Online multiple-instance learning tracking (Babenko et al. 2011; thesis 3.3.1): Haar-like
// features, Gaussian weak classifiers and online MILBoost. As a classifier of the
// multi-resolution framework it gives MIL (one level) and AM3 (thesis 3.3.1, Fig. 3.34).
#include <cmath>

#include "air/track/features/rect_features.hpp"
#include "air/track/mil/mil_boost.hpp"
#include "air/track/pyramid/discriminative.hpp"

namespace aerie::track {

struct MilParams {
  int features = 250;    // M: weak classifier pool (one Haar-like feature each)
  int selected = 50;     // K: weak classifiers chosen by MILBoost
  int min_rects = 2;     // rectangles per Haar-like feature
  int max_rects = 4;
  double learning_rate = 0.85;  // eta of eq. 3.30 (weight of the old model)
  double sigma_min = 2.0;       // floor of every sigma, grey levels (x feature_gain)
  double log_floor = std::log(1e-30);
};

class MilClassifier : public SampleClassifier {
 public:
  MilClassifier(cv::Size template_size, const MilParams& params, const std::vector<int>& channels, Rng& rng);

  cv::Size footprint(double scale) const override { return features_.footprint(scale); }
  void score(const ChannelImages& ch, const SampleSet& samples, double scale, std::vector<float>& out) override;
  void update(const ChannelImages& ch, const SampleSet& positives, const SampleSet& negatives, double scale) override;
  int terms() const override { return static_cast<int>(boost_.selected().size()); }
  std::unique_ptr<SampleClassifier> clone() const override { return std::make_unique<MilClassifier>(*this); }

  const MilBoost& boost() const { return boost_; }

 private:
  mutable ScaledFeatures features_;
  MilBoost boost_;
  cv::Mat f_, f_pos_, f_neg_;
};

ClassifierFactory mil_classifier_factory(const MilParams& params);

}  // namespace aerie::track
