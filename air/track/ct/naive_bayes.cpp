#include "air/track/ct/naive_bayes.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "air/track/features/kernels.hpp"

namespace aerie::track {

Gaussian blend_ct(const Gaussian& old, const Gaussian& sample, double eta) {
  const double dm = static_cast<double>(old.mu) - sample.mu;
  const double var = eta * old.sigma * old.sigma + (1 - eta) * sample.sigma * sample.sigma + eta * (1 - eta) * dm * dm;
  return {static_cast<float>(eta * old.mu + (1 - eta) * sample.mu), static_cast<float>(std::sqrt(var))};
}

NaiveBayes::NaiveBayes(std::vector<float> sigma_floor, double eta, double log_floor)
    : eta_(eta), log_floor_(log_floor), sigma_floor_(std::move(sigma_floor)), pos_(sigma_floor_.size()),
      neg_(sigma_floor_.size()) {
  if (sigma_floor_.empty()) throw std::invalid_argument("naive Bayes: need at least one feature");
  if (!(eta >= 0 && eta < 1)) throw std::invalid_argument("naive Bayes: learning rate must be in [0, 1)");
  for (float f : sigma_floor_)
    if (!(f > 0)) throw std::invalid_argument("naive Bayes: sigma floors must be > 0");
}

void NaiveBayes::update(const cv::Mat& positives, const cv::Mat& negatives) {
  const int n = static_cast<int>(pos_.size());
  if (positives.rows != n || negatives.rows != n || positives.cols < 1 || negatives.cols < 1 ||
      positives.type() != CV_32F || negatives.type() != CV_32F)
    throw std::invalid_argument("naive Bayes update: expected " + std::to_string(n) +
                                " x samples CV_32F matrices with at least one sample each");
  auto apply = [&](std::vector<Gaussian>& model, const cv::Mat& m) {
    for (int i = 0; i < n; ++i) {
      const Gaussian g = sample_gaussian(m.ptr<float>(i), m.cols);
      model[i] = trained_ ? blend_ct(model[i], g, eta_) : g;
      model[i].sigma = std::max(model[i].sigma, sigma_floor_[i]);
    }
  };
  apply(pos_, positives);
  apply(neg_, negatives);
  trained_ = true;
}

void NaiveBayes::classify(const cv::Mat& features, std::vector<float>& scores) const {
  const int n = static_cast<int>(pos_.size());
  if (features.rows != n || features.type() != CV_32F)
    throw std::invalid_argument("naive Bayes classify: expected " + std::to_string(n) + " feature rows");
  scores.assign(features.cols, 0.0f);
  for (int i = 0; i < n; ++i)
    kernels::add_log_ratio(features.ptr<float>(i), features.cols, pos_[i].mu, pos_[i].sigma, neg_[i].mu, neg_[i].sigma,
                           static_cast<float>(log_floor_), scores.data());
}

}  // namespace aerie::track
