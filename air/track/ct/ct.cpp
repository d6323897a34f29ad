#include "air/track/ct/ct.hpp"

#include <stdexcept>

namespace aerie::track {

CtClassifier::CtClassifier(cv::Size template_size, const CtParams& params, Rng& rng)
    : features_(make_compressive_features(template_size, params.features, params.min_rects, params.max_rects, rng),
                template_size),
      bayes_(params.features, params.learning_rate, params.sigma_min, params.log_floor) {}

void CtClassifier::score(const IntegralImage& ii, const SampleSet& samples, double scale, std::vector<float>& out) {
  evaluate_features(ii, features_.at(scale), samples, v_);
  bayes_.classify(v_, out);
}

void CtClassifier::update(const IntegralImage& ii, const SampleSet& positives, const SampleSet& negatives,
                          double scale) {
  evaluate_features(ii, features_.at(scale), positives, v_pos_);
  evaluate_features(ii, features_.at(scale), negatives, v_neg_);
  bayes_.update(v_pos_, v_neg_);
}

double CtClassifier::confidence(float score) const { return 1.0 / (1.0 + std::exp(-score / terms())); }

ClassifierFactory ct_classifier_factory(const CtParams& params) {
  if (params.features < 1) throw std::invalid_argument("ct: features must be >= 1");
  return [params](cv::Size template_size, Rng& rng) -> std::unique_ptr<SampleClassifier> {
    return std::make_unique<CtClassifier>(template_size, params, rng);
  };
}

}  // namespace aerie::track
