#pragma once
// The naive Bayes classifier of compressive tracking (eqs. 3.20-3.22, Zhang et al. 2012):
// each compressed feature v_i has Gaussian class conditionals N(mu_i^1, sigma_i^1) (target)
// and N(mu_i^0, sigma_i^0) (background), uniform prior, updated online with learning rate eta.
#include <opencv2/core.hpp>
#include <vector>

#include "air/track/features/gaussian.hpp"

namespace aerie::track {

// eq. 3.22: mu <- eta mu + (1 - eta) mu_new,
// sigma <- sqrt(eta sigma^2 + (1 - eta) sigma_new^2 + eta (1 - eta) (mu - mu_new)^2) (old mu).
Gaussian blend_ct(const Gaussian& old, const Gaussian& sample, double eta);

class NaiveBayes {
 public:
  // One entry of sigma_floor per feature (feature units); eta in [0, 1); log_floor floors
  // each class log-density (the reference implementation's log(p + 1e-30)).
  NaiveBayes(std::vector<float> sigma_floor, double eta, double log_floor);

  // Rows = features, columns = samples. The first update sets the parameters from the
  // samples (there is nothing to blend with yet); later ones apply eq. 3.22.
  void update(const cv::Mat& positives, const cv::Mat& negatives);
  // H(v) of eq. 3.20 for each column.
  void classify(const cv::Mat& features, std::vector<float>& scores) const;

  bool trained() const { return trained_; }
  const std::vector<Gaussian>& positive() const { return pos_; }
  const std::vector<Gaussian>& negative() const { return neg_; }

 private:
  double eta_, log_floor_;
  std::vector<float> sigma_floor_;
  bool trained_ = false;
  std::vector<Gaussian> pos_, neg_;
};

}  // namespace aerie::track
