#pragma once
// ECO's compact generative sample space (Danelljan et al., CVPR 2017, sec. 3.2): the training
// set is a Gaussian mixture of at most `capacity` components, each the mean of the samples it
// absorbed, with a prior weight. A new sample gets weight `learning_rate` and the others are
// scaled by (1 - learning_rate). While there is room it takes a free slot; when full, a
// component whose weight fell below `min_weight` is replaced; otherwise, if the new sample is
// nearer to its closest component than the two closest components are to each other, it is
// merged into that component, else those two are merged (weighted means) and the new sample
// takes the freed slot. The weights are kept normalised to sum 1. The distances come from a
// Gram matrix of the components, updated from the new sample's inner products with them.
#include <opencv2/core.hpp>
#include <vector>

namespace aerie::track {

struct Sample {
  std::vector<cv::Mat> xf;  // one spectrum per feature channel (CV_32FC2), all of one size
  cv::Mat yf;               // its label spectrum (CV_32FC2)
};

class SampleSpace {
 public:
  SampleSpace(int capacity, double learning_rate, double min_weight);

  void add(const Sample& s);
  const std::vector<Sample>& components() const { return components_; }
  const std::vector<double>& weights() const { return weights_; }
  // Squared Euclidean distance of two samples' feature spectra (summed over channels), which
  // must be DFTs of real signals: computed directly (the reference for distance(i, j)).
  static double distance(const Sample& a, const Sample& b);
  // Real part of the inner product of the two samples' full spectra (summed over channels).
  static double inner(const Sample& a, const Sample& b);
  // Squared distance of components i and j as the Gram matrix holds it.
  double distance(size_t i, size_t j) const;

 private:
  void merge_into(size_t into, const Sample& s, double w);  // weighted mean, weight summed
  double gram(size_t i, size_t j) const;
  void set_gram(size_t i, size_t j, double v);               // entries (i, j) and (j, i)

  int capacity_;
  double learning_rate_, min_weight_;
  std::vector<Sample> components_;
  std::vector<double> weights_;
  cv::Mat gram_;  // capacity x capacity, CV_64F: Re <component i, component j>
};

}  // namespace aerie::track
