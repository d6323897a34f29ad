#pragma once
// Compressive tracking (Zhang et al. 2012; thesis 3.2.1): compressive features (eq. 3.19)
// classified by online Gaussian naive Bayes (eqs. 3.20-3.22). As a classifier of the
// multi-resolution framework it gives CT (one level) and AMCMR-CT (thesis 3.2.2).
#include <cmath>

#include "air/track/ct/naive_bayes.hpp"
#include "air/track/features/rect_features.hpp"
#include "air/track/pyramid/discriminative.hpp"

namespace aerie::track {

struct CtParams {
  int features = 100;    // n: dimension of the compressed vector v (rows of R; Zhang et al. use 50)
  int min_rects = 2;     // non-zero entries per row of R
  int max_rects = 4;
  double learning_rate = 0.85;  // eta of eq. 3.22 (weight of the old model)
  double sigma_min = 2.0;       // floor of every sigma, grey levels (x feature_gain)
  double log_floor = std::log(1e-30);  // floor of each class log-density
};

class CtClassifier : public SampleClassifier {
 public:
  CtClassifier(cv::Size template_size, const CtParams& params, const std::vector<int>& channels, Rng& rng);

  cv::Size footprint(double scale) const override { return features_.footprint(scale); }
  void score(const ChannelImages& ch, const SampleSet& samples, double scale, std::vector<float>& out) override;
  void update(const ChannelImages& ch, const SampleSet& positives, const SampleSet& negatives, double scale) override;
  int terms() const override { return static_cast<int>(features_.base().size()); }
  std::unique_ptr<SampleClassifier> clone() const override { return std::make_unique<CtClassifier>(*this); }

  const NaiveBayes& bayes() const { return bayes_; }

 private:
  mutable ScaledFeatures features_;
  NaiveBayes bayes_;
  cv::Mat v_, v_pos_, v_neg_;  // feature buffers
};

ClassifierFactory ct_classifier_factory(const CtParams& params);

}  // namespace aerie::track
