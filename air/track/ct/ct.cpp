#include "air/track/ct/ct.hpp"

#include <stdexcept>

namespace aerie::track {

CtClassifier::CtClassifier(cv::Size template_size, const CtParams& params, const std::vector<int>& channels, Rng& rng)
    : features_(make_compressive_features(template_size, params.features, params.min_rects, params.max_rects, channels, rng),
                template_size),
      bayes_(sigma_floors(features_.base(), params.sigma_min), params.learning_rate, params.log_floor) {}

void CtClassifier::score(const ChannelImages& ch, const SampleSet& samples, double scale, std::vector<float>& out) {
  evaluate_features(ch, features_.at(scale), samples, v_);
  bayes_.classify(v_, out);
}

void CtClassifier::update(const ChannelImages& ch, const SampleSet& positives, const SampleSet& negatives,
                          double scale) {
  evaluate_features(ch, features_.at(scale), positives, v_pos_);
  evaluate_features(ch, features_.at(scale), negatives, v_neg_);
  bayes_.update(v_pos_, v_neg_);
}


ClassifierFactory ct_classifier_factory(const CtParams& params) {
  if (params.features < 1) throw std::invalid_argument("ct: features must be >= 1");
  return [params](cv::Size template_size, const std::vector<int>& channels, Rng& rng) -> std::unique_ptr<SampleClassifier> {
    return std::make_unique<CtClassifier>(template_size, params, channels, rng);
  };
}

}  // namespace aerie::track
