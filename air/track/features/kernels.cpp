// Highway kernels, compiled once per SIMD target and dispatched at run time.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "air/track/features/kernels.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

#include <cmath>

#include "air/track/features/kernels.hpp"

HWY_BEFORE_NAMESPACE();
namespace aerie::track::kernels::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

void FeatureRun(const IntegralImage& ii, const RectFeature& f, int x, int y, int count, float* out) {
  const hn::ScalableTag<float> df;
  const hn::RebindToSigned<decltype(df)> di;
  const int N = static_cast<int>(hn::Lanes(df));
  const int32_t* top[RectFeature::kMaxRects];
  const int32_t* bottom[RectFeature::kMaxRects];
  for (int r = 0; r < f.count; ++r) {
    top[r] = ii.row(y + f.rects[r].y) + x + f.rects[r].x;
    bottom[r] = ii.row(y + f.rects[r].y + f.rects[r].h) + x + f.rects[r].x;
  }
  int i = 0;
  for (; i + N <= count; i += N) {
    auto acc = hn::Zero(df);
    for (int r = 0; r < f.count; ++r) {
      const int w = f.rects[r].w;
      // rectangle sum = D - B - C + A over N consecutive sample positions (exact in int32)
      const auto s = hn::Sub(hn::Add(hn::LoadU(di, bottom[r] + i + w), hn::LoadU(di, top[r] + i)),
                             hn::Add(hn::LoadU(di, bottom[r] + i), hn::LoadU(di, top[r] + i + w)));
      acc = hn::MulAdd(hn::ConvertTo(df, s), hn::Set(df, f.rects[r].weight), acc);
    }
    hn::StoreU(acc, df, out + i);
  }
  for (; i < count; ++i) {
    float acc = 0;
    for (int r = 0; r < f.count; ++r) {
      const int w = f.rects[r].w;
      acc += f.rects[r].weight * static_cast<float>(bottom[r][i + w] - bottom[r][i] - top[r][i + w] + top[r][i]);
    }
    out[i] = acc;
  }
}

void AddLogRatio(const float* v, size_t n, float mu1, float sigma1, float mu0, float sigma0, float log_floor,
                 float* acc) {
  const hn::ScalableTag<float> d;
  const size_t N = hn::Lanes(d);
  // log N(v; mu, sigma) + log sqrt(2 pi) = -(v - mu)^2 / (2 sigma^2) - log sigma
  const float a1 = -0.5f / (sigma1 * sigma1), a0 = -0.5f / (sigma0 * sigma0);
  const float c1 = -std::log(sigma1), c0 = -std::log(sigma0);
  const auto va1 = hn::Set(d, a1), va0 = hn::Set(d, a0), vc1 = hn::Set(d, c1), vc0 = hn::Set(d, c0);
  const auto vm1 = hn::Set(d, mu1), vm0 = hn::Set(d, mu0), vf = hn::Set(d, log_floor);
  size_t i = 0;
  for (; i + N <= n; i += N) {
    const auto x = hn::LoadU(d, v + i);
    const auto e1 = hn::Sub(x, vm1), e0 = hn::Sub(x, vm0);
    const auto l1 = hn::Max(hn::MulAdd(hn::Mul(e1, e1), va1, vc1), vf);
    const auto l0 = hn::Max(hn::MulAdd(hn::Mul(e0, e0), va0, vc0), vf);
    hn::StoreU(hn::Add(hn::LoadU(d, acc + i), hn::Sub(l1, l0)), d, acc + i);
  }
  for (; i < n; ++i) {
    const float e1 = v[i] - mu1, e0 = v[i] - mu0;
    acc[i] += std::max(e1 * e1 * a1 + c1, log_floor) - std::max(e0 * e0 * a0 + c0, log_floor);
  }
}

double SoftplusSum(const float* H, const float* h, size_t n) {
  // softplus(z) = max(z, 0) + log(1 + exp(-|z|)); the second terms are multiplied per lane
  // (each factor is in [1, 2]) and turned into one log per 32 steps, so the loop needs one
  // exp per entry and no log.
  const hn::ScalableTag<float> d;
  const size_t N = hn::Lanes(d);
  const auto one = hn::Set(d, 1.0f), zero = hn::Zero(d);
  auto linear = zero, product = one;
  double logs = 0;
  size_t i = 0, steps = 0;
  for (; i + N <= n; i += N) {
    const auto z = hn::Add(hn::LoadU(d, H + i), hn::LoadU(d, h + i));
    linear = hn::Add(linear, hn::Max(z, zero));
    product = hn::Mul(product, hn::Add(one, hn::Exp(d, hn::Neg(hn::Abs(z)))));
    if (++steps == 32) {
      logs += hn::GetLane(hn::SumOfLanes(d, hn::Log(d, product)));
      product = one;
      steps = 0;
    }
  }
  double sum = logs + hn::GetLane(hn::SumOfLanes(d, hn::Add(linear, hn::Log(d, product))));
  for (; i < n; ++i) {
    const double z = static_cast<double>(H[i]) + h[i];
    sum += std::max(z, 0.0) + std::log1p(std::exp(-std::abs(z)));
  }
  return sum;
}

}  // namespace aerie::track::kernels::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace aerie::track::kernels {

HWY_EXPORT(FeatureRun);
HWY_EXPORT(AddLogRatio);
HWY_EXPORT(SoftplusSum);

void feature_run(const IntegralImage& ii, const RectFeature& f, int x, int y, int count, float* out) {
  HWY_DYNAMIC_DISPATCH(FeatureRun)(ii, f, x, y, count, out);
}
void add_log_ratio(const float* v, size_t n, float mu1, float sigma1, float mu0, float sigma0, float log_floor,
                   float* acc) {
  HWY_DYNAMIC_DISPATCH(AddLogRatio)(v, n, mu1, sigma1, mu0, sigma0, log_floor, acc);
}
double softplus_sum(const float* H, const float* h, size_t n) { return HWY_DYNAMIC_DISPATCH(SoftplusSum)(H, h, n); }

}  // namespace aerie::track::kernels
#endif
