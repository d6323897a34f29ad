#include "air/track/mil/mil.hpp"

namespace aerie::track {

MilClassifier::MilClassifier(cv::Size template_size, const MilParams& params, Rng& rng)
    : features_(make_haar_features(template_size, params.features, params.min_rects, params.max_rects, rng),
                template_size),
      boost_(params.features, params.selected, params.learning_rate, params.sigma_min, params.log_floor) {}

void MilClassifier::score(const IntegralImage& ii, const SampleSet& samples, double scale, std::vector<float>& out) {
  // Only the K selected features are needed to evaluate H_K.
  evaluate_features(ii, features_.at(scale), boost_.selected(), samples, f_);
  boost_.classify(f_, out);
}

void MilClassifier::update(const IntegralImage& ii, const SampleSet& positives, const SampleSet& negatives,
                           double scale) {
  evaluate_features(ii, features_.at(scale), positives, f_pos_);
  evaluate_features(ii, features_.at(scale), negatives, f_neg_);
  boost_.update(f_pos_, f_neg_);
}

double MilClassifier::confidence(float score) const { return 1.0 / (1.0 + std::exp(-score / std::max(1, terms()))); }

ClassifierFactory mil_classifier_factory(const MilParams& params) {
  if (params.features < 1 || params.selected < 1 || params.selected > params.features)
    throw std::invalid_argument("mil: need 1 <= selected <= features");
  return [params](cv::Size template_size, Rng& rng) -> std::unique_ptr<SampleClassifier> {
    return std::make_unique<MilClassifier>(template_size, params, rng);
  };
}

}  // namespace aerie::track
