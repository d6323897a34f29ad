#pragma once
// A one-dimensional Gaussian class conditional, as used by the naive Bayes classifier of CT
// (eq. 3.21) and the weak classifiers of MIL (eq. 3.29).
namespace aerie::track {

struct Gaussian {
  float mu = 0;
  float sigma = 1;
};

// Mean and (population) standard deviation of n values.
Gaussian sample_gaussian(const float* v, int n);

}  // namespace aerie::track
