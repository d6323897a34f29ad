#pragma once
// The tracker hot loops, vectorised with Highway (runtime dispatch: SSE4/AVX2/AVX-512 on
// x86, NEON on ARM). Plain functions over raw arrays; the callers give them meaning.
#include <cstddef>
#include <cstdint>

#include "air/track/features/rect_features.hpp"

namespace aerie::track::kernels {

// out[i] = sum_r weight_r * rectsum(x + i + rx_r, y + ry_r, w_r, h_r) for i in [0, count):
// one feature over one run of samples.
void feature_run(const IntegralImage& ii, const RectFeature& f, int x, int y, int count, float* out);

// acc[i] += max(log N(v[i]; mu1, sigma1), floor) - max(log N(v[i]; mu0, sigma0), floor):
// the log-ratio of one Gaussian naive Bayes / weak classifier term (eqs. 3.20, 3.28).
// The 1/sqrt(2 pi) factor cancels in the ratio and is left out of both logs.
void add_log_ratio(const float* v, size_t n, float mu1, float sigma1, float mu0, float sigma0, float log_floor,
                   float* acc);

// sum_j softplus(H[j] + h[j]) = -sum_j log(1 - sigmoid(H[j] + h[j])) over n entries: the
// negative log-probability that none of a bag's instances is positive (Algorithm 2, line 10).
double softplus_sum(const float* H, const float* h, size_t n);

}  // namespace aerie::track::kernels
