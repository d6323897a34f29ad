#include "air/track/eco/sample_space.hpp"

#include <limits>
#include <opencv2/core/hal/intrin.hpp>
#include <stdexcept>

namespace aerie::track {

// The spectra are of real signals (Hermitian: X[-k] = conj X[k]), so the columns right of the
// middle repeat those left of it: twice the left half, less the columns that are their own
// mirror (0 and, for an even width, W / 2). The brute-force reference of the Gram matrix's
// distances; inner() below sums the same columns.
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

// sum_k a[k] b[k] over n floats, with OpenCV's universal intrinsics (a row of interleaved
// complex values: re re + im im is the real part of a conj(b)).
static double dot(const float* a, const float* b, int n) {
  cv::v_float32 acc = cv::vx_setzero_f32();
  int k = 0;
  for (; k + cv::v_float32::nlanes <= n; k += cv::v_float32::nlanes) acc = cv::v_fma(cv::vx_load(a + k), cv::vx_load(b + k), acc);
  double sum = cv::v_reduce_sum(acc);
  for (; k < n; ++k) sum += double(a[k]) * b[k];
  return sum;
}

double SampleSpace::inner(const Sample& a, const Sample& b) {
  double total = 0;
  for (size_t c = 0; c < a.xf.size(); ++c) {
    const int w = a.xf[c].cols, half = w / 2 + 1;
    for (int r = 0; r < a.xf[c].rows; ++r) {
      const float* pa = a.xf[c].ptr<float>(r);
      const float* pb = b.xf[c].ptr<float>(r);
      double row = 2 * dot(pa, pb, 2 * half) - dot(pa, pb, 2);  // the mirrored half; column 0 is its own mirror
      if (w % 2 == 0 && w > 1) row -= dot(pa + w, pb + w, 2);  // ... and so is column W / 2
      total += row;
    }
  }
  return total;
}

SampleSpace::SampleSpace(int capacity, double learning_rate, double min_weight)
    : capacity_(capacity), learning_rate_(learning_rate), min_weight_(min_weight) {
  if (capacity < 1) throw std::invalid_argument("sample space: capacity must be >= 1");
  if (!(learning_rate > 0 && learning_rate <= 1)) throw std::invalid_argument("sample space: learning rate in (0, 1]");
  if (!(min_weight >= 0 && min_weight < 1)) throw std::invalid_argument("sample space: min_weight in [0, 1)");
  gram_ = cv::Mat(capacity, capacity, CV_64F, cv::Scalar(0));
}

double SampleSpace::gram(size_t i, size_t j) const {
  return gram_.at<double>(static_cast<int>(i), static_cast<int>(j));
}

double SampleSpace::distance(size_t i, size_t j) const {
  return i == j ? 0 : gram(i, i) + gram(j, j) - 2 * gram(i, j);
}

void SampleSpace::set_gram(size_t i, size_t j, double v) {
  gram_.at<double>(static_cast<int>(i), static_cast<int>(j)) = v;
  gram_.at<double>(static_cast<int>(j), static_cast<int>(i)) = v;
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
  // The Gram matrix of the components is kept up to date from the new sample's inner products
  // with them (ECO's implementation: a merged component's products are the same weighted mean
  // of its parents'), so each frame costs one inner product per component.
  const size_t n = components_.size();
  std::vector<double> p(n);
  for (size_t k = 0; k < n; ++k) p[k] = inner(s, components_[k]);
  const double ss = inner(s, s);
  auto take_slot = [&](size_t slot, double weight) {
    if (slot == components_.size()) {
      components_.push_back(copy(s));
      weights_.push_back(weight);
    } else {
      components_[slot] = copy(s);
      weights_[slot] = weight;
    }
    for (size_t k = 0; k < n; ++k)
      if (k != slot) set_gram(slot, k, p[k]);
    set_gram(slot, slot, ss);
  };
  if (n == 0) {
    take_slot(0, 1.0);
    return;
  }
  for (double& w : weights_) w *= 1 - learning_rate_;
  const double w_new = learning_rate_;

  size_t lightest = 0;
  for (size_t k = 1; k < n; ++k)
    if (weights_[k] < weights_[lightest]) lightest = k;
  if (n < static_cast<size_t>(capacity_)) {
    take_slot(n, w_new);
  } else if (weights_[lightest] < min_weight_) {
    take_slot(lightest, w_new);
  } else {
    // The new sample's nearest component, and the two nearest components.
    size_t nearest = 0;
    double d_new = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < n; ++k) {
      const double d = ss + gram(k, k) - 2 * p[k];
      if (d < d_new) d_new = d, nearest = k;
    }
    size_t a = 0, b = 1;
    double d_pair = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < n; ++i)
      for (size_t j = i + 1; j < n; ++j)
        if (distance(i, j) < d_pair) d_pair = distance(i, j), a = i, b = j;
    if (d_new < d_pair) {
      // m' = alpha m + beta s: <m', k> = alpha <m, k> + beta <s, k>.
      const double alpha = weights_[nearest] / (weights_[nearest] + w_new), beta = 1 - alpha;
      const double mm = gram(nearest, nearest);
      merge_into(nearest, s, w_new);
      for (size_t k = 0; k < n; ++k)
        if (k != nearest)
          set_gram(nearest, k, alpha * gram(nearest, k) + beta * p[k]);
      set_gram(nearest, nearest, alpha * alpha * mm + 2 * alpha * beta * p[nearest] + beta * beta * ss);
    } else {
      // a' = alpha a + beta b, then s takes b's slot.
      const double alpha = weights_[a] / (weights_[a] + weights_[b]), beta = 1 - alpha;
      const double aa = alpha * alpha * gram(a, a) + 2 * alpha * beta * gram(a, b) + beta * beta * gram(b, b);
      merge_into(a, components_[b], weights_[b]);
      for (size_t k = 0; k < n; ++k)
        if (k != a && k != b) set_gram(a, k, alpha * gram(a, k) + beta * gram(b, k));
      set_gram(a, a, aa);
      p[a] = alpha * p[a] + beta * p[b];  // <s, a'>
      take_slot(b, w_new);
    }
  }
  double sum = 0;
  for (double w : weights_) sum += w;
  for (double& w : weights_) w /= sum;
}

}  // namespace aerie::track
