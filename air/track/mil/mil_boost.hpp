#pragma once
// Online MILBoost (Babenko et al. 2011; thesis 3.3.1, Algorithm 2): a pool of M Gaussian
// weak classifiers h_m (eqs. 3.28-3.30), updated online from a positive and a negative bag,
// of which K are chosen greedily by the bag log-likelihood; the strong classifier is
// H_K = sum_k h_k (eq. 3.27).
#include <cmath>
#include <opencv2/core.hpp>
#include <vector>

#include "air/track/features/gaussian.hpp"

namespace aerie::track {

// eq. 3.30: mu <- eta mu + (1 - eta) mean; sigma <- eta sigma + (1 - eta) sqrt(mean((f - mu)^2))
// with the updated mu inside the square root.
Gaussian blend_mil(const Gaussian& old, const float* f, int n, double eta);

// log(sigmoid-bag) helpers of Algorithm 2 (lines 8-11), from S = sum_j softplus(H_ij + h(S_ij)):
// log p_1 = log(1 - prod_j (1 - p_1j)) = log(1 - exp(-S_pos)) and log(1 - p_0) = -S_neg.
double bag_log_likelihood(double softplus_pos, double softplus_neg);

class MilBoost {
 public:
  // M = sigma_floor.size() weak classifiers (one sigma floor each, feature units), K of them
  // selected; eta the learning rate of eq. 3.30.
  MilBoost(std::vector<float> sigma_floor, int selected, double eta, double log_floor);

  // Rows = the M pool features, columns = instances of the positive bag / the negatives.
  // Updates every weak classifier (Algorithm 2, line 1; the first update initialises) and
  // reselects the K weak classifiers (lines 2-17).
  void update(const cv::Mat& positives, const cv::Mat& negatives);
  // H_K of eq. 3.27 for each column of `selected_features` (rows = the selected features in
  // the order of selected()).
  void classify(const cv::Mat& selected_features, std::vector<float>& scores) const;

  const std::vector<int>& selected() const { return selected_; }
  const std::vector<Gaussian>& positive() const { return pos_; }
  const std::vector<Gaussian>& negative() const { return neg_; }
  bool trained() const { return !selected_.empty(); }
  // h_m(f) of eq. 3.28 for weak classifier m (for tests and inspection).
  float weak(int m, float f) const;

 private:
  void select(const cv::Mat& positives, const cv::Mat& negatives);

  int pool_, k_;
  double eta_, log_floor_;
  std::vector<float> sigma_floor_;
  std::vector<Gaussian> pos_, neg_;
  std::vector<int> selected_;
  // Scratch: weak outputs h_m(S_ij) (instance-major, rows padded to a multiple of 16) and H_ij.
  std::vector<float> h_pos_, h_neg_, H_pos_, H_neg_;
};

}  // namespace aerie::track
