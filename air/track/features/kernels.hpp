#pragma once
// The tracker hot loops, vectorised with Highway (runtime dispatch: SSE4/AVX2/AVX-512 on
// x86, NEON on ARM). Plain functions over raw arrays; the callers give them meaning.
#include <cstddef>
#include <cstdint>

#include "air/track/features/rect_features.hpp"

namespace aerie::track::kernels {

// Lanes of slack every output row of features_run needs past its last sample.
constexpr size_t kOutputPad = 16;

// For each feature k: out[k * stride + i] = sum_r weight_r * rectsum(run.x + i + rx_r, run.y + ry_r,
// w_r, h_r) over the channel of the feature, i in [0, run.count). Vector stores may write up to
// kOutputPad - 1 entries past run.count (later runs overwrite them; the last run's land in the padding).
void features_run(const ChannelImages& ch, const RectFeature* const* features, size_t nf, const SampleRun& run,
                  float* out, size_t stride);

// acc[i] += max(log N(v[i]; mu1, sigma1), floor) - max(log N(v[i]; mu0, sigma0), floor):
// the log-ratio of one Gaussian naive Bayes / weak classifier term (eqs. 3.20, 3.28).
// The 1/sqrt(2 pi) factor cancels in the ratio and is left out of both logs.
void add_log_ratio(const float* v, size_t n, float mu1, float sigma1, float mu0, float sigma0, float log_floor,
                   float* acc);

// For every weak classifier m in [0, M): S[m] = sum_j softplus(H[j] + h[j * stride + m]) over the
// n instances j of a bag, softplus(z) = -log(1 - sigmoid(z)): the negative log-probability that
// none of the instances is positive (Algorithm 2, lines 8-10). M must be a multiple of 16.
void softplus_sums(const float* H, const float* h, size_t n, size_t M, size_t stride, double* S);

// Name of the instruction set these kernels dispatch to on this machine (e.g. "AVX2", "NEON").
const char* target_name();

}  // namespace aerie::track::kernels
