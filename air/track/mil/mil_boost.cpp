#include "air/track/mil/mil_boost.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

#include "air/track/features/kernels.hpp"

namespace aerie::track {
namespace {
constexpr size_t kPad = 16;  // SIMD row padding (covers 512-bit vectors of floats)
// Padding instances have h = -1e4: sigmoid(H + h) = 0, so they add nothing to a bag.
constexpr float kNoInstance = -1e4f;
size_t padded(int n) { return (static_cast<size_t>(n) + kPad - 1) / kPad * kPad; }
}  // namespace

Gaussian blend_mil(const Gaussian& old, const float* f, int n, double eta) {
  double s = 0;
  for (int i = 0; i < n; ++i) s += f[i];
  const double mu = eta * old.mu + (1 - eta) * (s / n);
  double s2 = 0;
  for (int i = 0; i < n; ++i) s2 += (f[i] - mu) * (f[i] - mu);
  return {static_cast<float>(mu), static_cast<float>(eta * old.sigma + (1 - eta) * std::sqrt(s2 / n))};
}

double bag_log_likelihood(double softplus_pos, double softplus_neg) {
  // log(1 - exp(-S)) = log(-expm1(-S)), finite as long as S > 0
  return std::log(-std::expm1(-std::max(softplus_pos, 1e-30))) - softplus_neg;
}

MilBoost::MilBoost(std::vector<float> sigma_floor, int selected, double eta, double log_floor)
    : pool_(static_cast<int>(sigma_floor.size())), k_(selected), eta_(eta), log_floor_(log_floor),
      sigma_floor_(std::move(sigma_floor)), pos_(pool_), neg_(pool_) {
  const int pool = pool_;
  if (pool < 1 || selected < 1 || selected > pool)
    throw std::invalid_argument("MILBoost: need 1 <= selected (" + std::to_string(selected) + ") <= pool (" +
                                std::to_string(pool) + ")");
  if (!(eta >= 0 && eta < 1)) throw std::invalid_argument("MILBoost: learning rate must be in [0, 1)");
  for (float f : sigma_floor_)
    if (!(f > 0)) throw std::invalid_argument("MILBoost: sigma floors must be > 0");
}

float MilBoost::weak(int m, float f) const {
  float h = 0;
  kernels::add_log_ratio(&f, 1, pos_[m].mu, pos_[m].sigma, neg_[m].mu, neg_[m].sigma, static_cast<float>(log_floor_), &h);
  return h;
}

void MilBoost::update(const cv::Mat& positives, const cv::Mat& negatives) {
  if (positives.rows != pool_ || negatives.rows != pool_ || positives.cols < 1 || negatives.cols < 1 ||
      positives.type() != CV_32F || negatives.type() != CV_32F)
    throw std::invalid_argument("MILBoost update: expected " + std::to_string(pool_) +
                                " x instances CV_32F matrices with at least one instance each");
  const bool first = !trained();
  auto apply = [&](std::vector<Gaussian>& model, const cv::Mat& m) {
    for (int i = 0; i < pool_; ++i) {
      model[i] = first ? sample_gaussian(m.ptr<float>(i), m.cols) : blend_mil(model[i], m.ptr<float>(i), m.cols, eta_);
      model[i].sigma = std::max(model[i].sigma, sigma_floor_[i]);
    }
  };
  apply(pos_, positives);
  apply(neg_, negatives);
  select(positives, negatives);
}

void MilBoost::select(const cv::Mat& positives, const cv::Mat& negatives) {
  const size_t np = padded(positives.cols), nn = padded(negatives.cols);
  h_pos_.assign(pool_ * np, kNoInstance);
  h_neg_.assign(pool_ * nn, kNoInstance);
  const float floor = static_cast<float>(log_floor_);
  for (int m = 0; m < pool_; ++m) {
    float* hp = &h_pos_[m * np];
    float* hn = &h_neg_[m * nn];
    std::fill(hp, hp + positives.cols, 0.0f);
    std::fill(hn, hn + negatives.cols, 0.0f);
    kernels::add_log_ratio(positives.ptr<float>(m), positives.cols, pos_[m].mu, pos_[m].sigma, neg_[m].mu,
                           neg_[m].sigma, floor, hp);
    kernels::add_log_ratio(negatives.ptr<float>(m), negatives.cols, pos_[m].mu, pos_[m].sigma, neg_[m].mu,
                           neg_[m].sigma, floor, hn);
  }
  H_pos_.assign(np, 0.0f);
  H_neg_.assign(nn, 0.0f);
  selected_.clear();
  std::vector<char> taken(pool_, 0);
  for (int k = 0; k < k_; ++k) {
    int best = -1;
    double best_l = -std::numeric_limits<double>::infinity();
    for (int m = 0; m < pool_; ++m) {
      if (taken[m]) continue;
      const double l = bag_log_likelihood(kernels::softplus_sum(H_pos_.data(), &h_pos_[m * np], np),
                                          kernels::softplus_sum(H_neg_.data(), &h_neg_[m * nn], nn));
      if (l > best_l || best < 0) {
        best_l = l;
        best = m;
      }
    }
    taken[best] = 1;
    selected_.push_back(best);
    for (int j = 0; j < positives.cols; ++j) H_pos_[j] += h_pos_[best * np + j];
    for (int j = 0; j < negatives.cols; ++j) H_neg_[j] += h_neg_[best * nn + j];
  }
}

void MilBoost::classify(const cv::Mat& selected_features, std::vector<float>& scores) const {
  if (selected_features.rows != static_cast<int>(selected_.size()) || selected_features.type() != CV_32F)
    throw std::invalid_argument("MILBoost classify: expected one row per selected weak classifier");
  scores.assign(selected_features.cols, 0.0f);
  const float floor = static_cast<float>(log_floor_);
  for (size_t k = 0; k < selected_.size(); ++k) {
    const int m = selected_[k];
    kernels::add_log_ratio(selected_features.ptr<float>(static_cast<int>(k)), selected_features.cols, pos_[m].mu,
                           pos_[m].sigma, neg_[m].mu, neg_[m].sigma, floor, scores.data());
  }
}

}  // namespace aerie::track
