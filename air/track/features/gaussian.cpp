#include "air/track/features/gaussian.hpp"

#include <cmath>

namespace aerie::track {

Gaussian sample_gaussian(const float* v, int n) {
  double s = 0, s2 = 0;
  for (int i = 0; i < n; ++i) s += v[i];
  const double mu = s / n;
  for (int i = 0; i < n; ++i) s2 += (v[i] - mu) * (v[i] - mu);
  return {static_cast<float>(mu), static_cast<float>(std::sqrt(s2 / n))};
}

}  // namespace aerie::track
