#include "air/track/mil/mil_boost.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

#include "air/track/features/kernels.hpp"

namespace aerie::track {
namespace {
constexpr size_t kPad = 16;  // the likelihood kernel works on 16 weak classifiers at a time
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
  // Weak classifier outputs h_m(S_ij), instance-major (row j holds every m) so that the
  // likelihoods of all M candidates are computed together, 16 lanes at a time.
  const size_t mp = padded(pool_);
  const int np = positives.cols, nn = negatives.cols;
  h_pos_.assign(np * mp, 0.0f);
  h_neg_.assign(nn * mp, 0.0f);
  const float floor = static_cast<float>(log_floor_);
  std::vector<float> row(std::max(np, nn));
  auto fill = [&](const cv::Mat& f, int n, std::vector<float>& h, int m) {
    std::fill(row.begin(), row.begin() + n, 0.0f);
    kernels::add_log_ratio(f.ptr<float>(m), n, pos_[m].mu, pos_[m].sigma, neg_[m].mu, neg_[m].sigma, floor, row.data());
    for (int j = 0; j < n; ++j) h[j * mp + m] = row[j];
  };
  for (int m = 0; m < pool_; ++m) {
    fill(positives, np, h_pos_, m);
    fill(negatives, nn, h_neg_, m);
  }
  H_pos_.assign(np, 0.0f);
  H_neg_.assign(nn, 0.0f);
  std::vector<double> s_pos(mp), s_neg(mp);
  selected_.clear();
  std::vector<char> taken(pool_, 0);
  for (int k = 0; k < k_; ++k) {  // Algorithm 2, lines 3-17
    kernels::softplus_sums(H_pos_.data(), h_pos_.data(), np, mp, mp, s_pos.data());
    kernels::softplus_sums(H_neg_.data(), h_neg_.data(), nn, mp, mp, s_neg.data());
    int best = -1;
    double best_l = -std::numeric_limits<double>::infinity();
    for (int m = 0; m < pool_; ++m) {
      if (taken[m]) continue;
      const double l = bag_log_likelihood(s_pos[m], s_neg[m]);
      if (l > best_l || best < 0) {
        best_l = l;
        best = m;
      }
    }
    taken[best] = 1;
    selected_.push_back(best);
    for (int j = 0; j < np; ++j) H_pos_[j] += h_pos_[j * mp + best];
    for (int j = 0; j < nn; ++j) H_neg_[j] += h_neg_[j * mp + best];
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
