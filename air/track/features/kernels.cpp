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

// One feature over a run of samples with vectors of tag D: whole vectors only (the integral
// image rows and the output rows have slack for the lanes past the run's end).
template <class D>
HWY_INLINE void FeatureVectors(D df, const RectFeature& f, const int32_t* const* top, const int32_t* const* bottom,
                               int count, float* o) {
  const hn::RebindToSigned<D> di;
  const int N = static_cast<int>(hn::Lanes(df));
  for (int i = 0; i < count; i += N) {
    auto acc = hn::Zero(df);
    for (int r = 0; r < f.count; ++r) {
      const int w = f.rects[r].w;
      // rectangle sum = D - B - C + A over N consecutive sample positions (exact in int32)
      const auto s = hn::Sub(hn::Add(hn::LoadU(di, bottom[r] + i + w), hn::LoadU(di, top[r] + i)),
                             hn::Add(hn::LoadU(di, bottom[r] + i), hn::LoadU(di, top[r] + i + w)));
      acc = hn::MulAdd(hn::ConvertTo(df, s), hn::Set(df, f.rects[r].weight), acc);
    }
    hn::StoreU(acc, df, o + i);
  }
}

void FeaturesRun(const ChannelImages& ch, const RectFeature* const* features, size_t nf, const SampleRun& run,
                 float* out, size_t stride) {
  const hn::CappedTag<float, kOutputPad> wide;  // at most 16 lanes: the padding of rows and outputs
  const hn::CappedTag<float, 8> narrow;
  const int n_wide = static_cast<int>(hn::Lanes(wide)), n_narrow = static_cast<int>(hn::Lanes(narrow));
  for (size_t k = 0; k < nf; ++k) {
    const RectFeature& f = *features[k];
    const IntegralImage& ii = ch[f.channel];
    const int32_t* top[RectFeature::kMaxRects];
    const int32_t* bottom[RectFeature::kMaxRects];
    for (int r = 0; r < f.count; ++r) {
      top[r] = ii.row(run.y + f.rects[r].y) + run.x + f.rects[r].x;
      bottom[r] = ii.row(run.y + f.rects[r].y + f.rects[r].h) + run.x + f.rects[r].x;
    }
    float* o = out + k * stride;
    if (run.count * 2 < n_narrow) {  // short runs (random negatives, small discs): scalar
      for (int i = 0; i < run.count; ++i) {
        float acc = 0;
        for (int r = 0; r < f.count; ++r) {
          const int w = f.rects[r].w;
          acc += f.rects[r].weight * static_cast<float>(bottom[r][i + w] - bottom[r][i] - top[r][i + w] + top[r][i]);
        }
        o[i] = acc;
      }
    } else if (run.count <= n_narrow || n_wide == n_narrow || run.count % n_wide <= n_narrow / 2) {
      FeatureVectors(narrow, f, top, bottom, run.count, o);
    } else {
      FeatureVectors(wide, f, top, bottom, run.count, o);
    }
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

void SoftplusSums(const float* H, const float* h, size_t n, size_t M, size_t stride, double* S) {
  // Vectorised over the weak classifiers m. softplus(z) = max(z, 0) + log(1 + exp(-|z|)); the
  // second terms are multiplied per lane (each factor is in [1, 2]) and turned into one log per
  // 64 instances, so the loop needs one exp per entry and no log.
  const hn::CappedTag<float, 16> d;  // M is a multiple of 16
  const size_t N = hn::Lanes(d);
  const auto one = hn::Set(d, 1.0f), zero = hn::Zero(d);
  HWY_ALIGN float lanes[16];
  for (size_t m = 0; m < M; m += N) {
    auto linear = zero, product = one, logs = zero;
    for (size_t j = 0; j < n; ++j) {
      const auto z = hn::Add(hn::Set(d, H[j]), hn::LoadU(d, h + j * stride + m));
      linear = hn::Add(linear, hn::Max(z, zero));
      product = hn::Mul(product, hn::Add(one, hn::Exp(d, hn::Neg(hn::Abs(z)))));
      if ((j & 63) == 63) {
        logs = hn::Add(logs, hn::Log(d, product));
        product = one;
      }
    }
    hn::Store(hn::Add(hn::Add(linear, logs), hn::Log(d, product)), d, lanes);
    for (size_t l = 0; l < N && m + l < M; ++l) S[m + l] = lanes[l];
  }
}

// The target this copy was compiled for: dispatched like the kernels, it names the one they take.
int64_t CompiledTarget() { return HWY_TARGET; }

}  // namespace aerie::track::kernels::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace aerie::track::kernels {

HWY_EXPORT(FeaturesRun);
HWY_EXPORT(AddLogRatio);
HWY_EXPORT(SoftplusSums);
HWY_EXPORT(CompiledTarget);

void features_run(const ChannelImages& ch, const RectFeature* const* features, size_t nf, const SampleRun& run,
                  float* out, size_t stride) {
  HWY_DYNAMIC_DISPATCH(FeaturesRun)(ch, features, nf, run, out, stride);
}
void add_log_ratio(const float* v, size_t n, float mu1, float sigma1, float mu0, float sigma0, float log_floor,
                   float* acc) {
  HWY_DYNAMIC_DISPATCH(AddLogRatio)(v, n, mu1, sigma1, mu0, sigma0, log_floor, acc);
}
void softplus_sums(const float* H, const float* h, size_t n, size_t M, size_t stride, double* S) {
  HWY_DYNAMIC_DISPATCH(SoftplusSums)(H, h, n, M, stride, S);
}
const char* target_name() { return hwy::TargetName(HWY_DYNAMIC_DISPATCH(CompiledTarget)()); }

}  // namespace aerie::track::kernels
#endif
