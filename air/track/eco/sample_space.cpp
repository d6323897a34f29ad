#include "air/track/eco/sample_space.hpp"

#include <limits>
#include <stdexcept>

namespace aerie::track {

SampleSpace::SampleSpace(int capacity, double learning_rate, double min_weight)
    : capacity_(capacity), learning_rate_(learning_rate), min_weight_(min_weight) {
  if (capacity < 1) throw std::invalid_argument("sample space: capacity must be >= 1");
  if (!(learning_rate > 0 && learning_rate <= 1)) throw std::invalid_argument("sample space: learning rate in (0, 1]");
  if (!(min_weight >= 0 && min_weight < 1)) throw std::invalid_argument("sample space: min_weight in [0, 1)");
  distance_ = cv::Mat(capacity, capacity, CV_64F, cv::Scalar(0));
}

// The spectra are of real signals (Hermitian: X[-k] = conj X[k]), so the columns right of the
// middle repeat those left of it: twice the left half, less the columns that are their own
// mirror (0 and, for an even width, W / 2).
double SampleSpace::distance(const Sample& a, const Sample& b) {
  double d = 0;
  for (size_t c = 0; c < a.xf.size(); ++c) {
    const int w = a.xf[c].cols, half = w / 2 + 1;
    auto cols = [&](int from, int to) {
      return cv::norm(a.xf[c].colRange(from, to), b.xf[c].colRange(from, to), cv::NORM_L2SQR);
    };
    d += 2 * cols(0, half) - cols(0, 1) - (w % 2 == 0 && w > 1 ? cols(w / 2, w / 2 + 1) : 0.0);
  }
  return d;
}

void SampleSpace::update_distances(size_t k) {
  for (size_t j = 0; j < components_.size(); ++j) {
    const double d = j == k ? 0 : distance(components_[k], components_[j]);
    distance_.at<double>(static_cast<int>(k), static_cast<int>(j)) = d;
    distance_.at<double>(static_cast<int>(j), static_cast<int>(k)) = d;
  }
}

void SampleSpace::merge_into(size_t into, const Sample& s, double w) {
  Sample& m = components_[into];
  const double wm = weights_[into], total = wm + w;
  for (size_t c = 0; c < m.xf.size(); ++c) cv::addWeighted(m.xf[c], wm / total, s.xf[c], w / total, 0, m.xf[c]);
  cv::addWeighted(m.yf, wm / total, s.yf, w / total, 0, m.yf);
  weights_[into] = total;
}

void SampleSpace::add(const Sample& s) {
  auto copy = [](const Sample& in) {
    Sample out{{}, in.yf.clone()};
    for (const auto& x : in.xf) out.xf.push_back(x.clone());
    return out;
  };
  if (components_.empty()) {
    components_.push_back(copy(s));
    weights_.push_back(1.0);
    return;
  }
  for (double& w : weights_) w *= 1 - learning_rate_;
  const double w_new = learning_rate_;

  size_t slot = components_.size();
  if (components_.size() < static_cast<size_t>(capacity_)) {
    components_.push_back(copy(s));
    weights_.push_back(w_new);
  } else {
    size_t lightest = 0;
    for (size_t k = 1; k < weights_.size(); ++k)
      if (weights_[k] < weights_[lightest]) lightest = k;
    if (weights_[lightest] < min_weight_) {
      slot = lightest;
      components_[slot] = copy(s);
      weights_[slot] = w_new;
    } else {
      // The new sample's nearest component, and the two nearest components.
      size_t nearest = 0;
      double d_new = std::numeric_limits<double>::infinity();
      for (size_t k = 0; k < components_.size(); ++k) {
        const double d = distance(s, components_[k]);
        if (d < d_new) d_new = d, nearest = k;
      }
      size_t a = 0, b = 1;
      double d_pair = std::numeric_limits<double>::infinity();
      for (size_t i = 0; i < components_.size(); ++i)
        for (size_t j = i + 1; j < components_.size(); ++j)
          if (distance_.at<double>(static_cast<int>(i), static_cast<int>(j)) < d_pair)
            d_pair = distance_.at<double>(static_cast<int>(i), static_cast<int>(j)), a = i, b = j;
      if (d_new < d_pair) {
        merge_into(nearest, s, w_new);
        slot = nearest;
      } else {
        merge_into(a, components_[b], weights_[b]);
        update_distances(a);
        slot = b;
        components_[slot] = copy(s);
        weights_[slot] = w_new;
      }
    }
  }
  update_distances(slot);
  double sum = 0;
  for (double w : weights_) sum += w;
  for (double& w : weights_) w /= sum;
}

}  // namespace aerie::track
