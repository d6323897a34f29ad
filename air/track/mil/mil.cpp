#include "air/track/mil/mil.hpp"

namespace aerie::track {

MilClassifier::MilClassifier(cv::Size template_size, const MilParams& params, const std::vector<int>& channels, Rng& rng)
    : features_(make_haar_features(template_size, params.features, params.min_rects, params.max_rects, channels, rng),
                template_size),
      boost_(sigma_floors(features_.base(), params.sigma_min), params.selected, params.learning_rate, params.log_floor) {}

void MilClassifier::score(const ChannelImages& ch, const SampleSet& samples, double scale, std::vector<float>& out) {
  // Only the K selected features are needed to evaluate H_K.
  evaluate_features(ch, features_.at(scale), boost_.selected(), samples, f_);
  boost_.classify(f_, out);
}

void MilClassifier::update(const ChannelImages& ch, const SampleSet& positives, const SampleSet& negatives,
                           double scale) {
  evaluate_features(ch, features_.at(scale), positives, f_pos_);
  evaluate_features(ch, features_.at(scale), negatives, f_neg_);
  boost_.update(f_pos_, f_neg_);
}


ClassifierFactory mil_classifier_factory(const MilParams& params) {
  if (params.features < 1 || params.selected < 1 || params.selected > params.features)
    throw std::invalid_argument("mil: need 1 <= selected <= features");
  return [params](cv::Size template_size, const std::vector<int>& channels, Rng& rng) -> std::unique_ptr<SampleClassifier> {
    return std::make_unique<MilClassifier>(template_size, params, channels, rng);
  };
}

}  // namespace aerie::track
