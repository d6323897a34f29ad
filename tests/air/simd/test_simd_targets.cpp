// Vectorised against scalar (docs/arm.md): the SIMD kernels of air/track/features and
// air/stereo/sgbm_ctf, compiled here with every target Highway can attain (HWY_COMPILE_ALL_ATTAINABLE:
// the portable EMU128/SCALAR path too, which the product build leaves out where the baseline is a vector
// target, as NEON is on arm64), run on each target the CPU has and compared with that scalar path:
// bit for bit for the semi-global matcher (integer costs), within float rounding for the tracker
// kernels (sums of products and exp/log, where FMA contraction and lane order differ).
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cmath>
#include <cstring>
#include <iostream>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <string>
#include <vector>

#include "air/stereo/sgbm_ctf/sgm.hpp"
#include "air/track/features/channels.hpp"
#include "air/track/features/kernels.hpp"
#include "air/track/features/random.hpp"
#include "air/track/features/rect_features.hpp"
#include "air/track/features/samples.hpp"

#include "tests/air/simd/cpu_targets.hpp"

namespace {

// cpu_targets() includes the scalar target too (it must be there: HWY_COMPILE_ALL_ATTAINABLE).
// Highway's portable path: EMU128 (or SCALAR where the compiler cannot build EMU128), the worst.
int64_t scalar_target() { return cpu_targets().back(); }

std::string names(const std::vector<int64_t>& targets) {
  std::string s;
  for (int64_t t : targets) s += (s.empty() ? "" : " ") + std::string(hwy::TargetName(t));
  return s;
}

// Forces the dispatch of every kernel to one target for the scope's lifetime.
struct ForceTarget {
  explicit ForceTarget(int64_t t) { hwy::SetSupportedTargetsForTest(t); }
  ~ForceTarget() { hwy::SetSupportedTargetsForTest(0); }
};

}  // namespace

TEST(SimdTargets, TheScalarPathIsCompiledIn) {
  const std::vector<int64_t> cpu = cpu_targets();
  std::cout << "[simd] targets compared with the scalar one (" << hwy::TargetName(scalar_target()) << "): " << names(cpu)
            << std::endl;
  ASSERT_GE(cpu.size(), 2u) << "no vector target to compare";
  EXPECT_TRUE(cpu.back() == HWY_EMU128 || cpu.back() == HWY_SCALAR) << hwy::TargetName(cpu.back());
}

TEST(SimdTargets, TrackKernelsGiveTheSameResultsOnEveryTarget) {
  using namespace aerie::track;
  const cv::Size size(90, 70);
  cv::Mat gray(size, CV_8UC1), chroma(size, CV_8UC2);
  cv::RNG(3).fill(gray, cv::RNG::UNIFORM, 0, 256);
  cv::RNG(4).fill(chroma, cv::RNG::UNIFORM, 0, 256);
  const cv::Point origin(10, 20);
  ChannelImages ch;
  ch.compute(gray, chroma, {kGray, kGradient, kChromaCr, kChromaCb}, origin);
  Rng rng(5);
  const cv::Size box(21, 17);
  auto features = make_haar_features(box, 40, 2, 4, {kGray, kGradient, kChromaCr, kChromaCb}, rng);
  const auto ct = make_compressive_features(box, 40, 2, 4, {kGray, kGradient}, rng);
  features.insert(features.end(), ct.begin(), ct.end());
  SampleSet samples;  // runs of 19, 10, 6, 3 and 1: wide, narrow and partial vectors
  for (int x = 12; x < 31; ++x) samples.add(x, 25);
  for (int x = 14; x < 24; ++x) samples.add(x, 30);
  for (int x = 20; x < 26; ++x) samples.add(x, 33);
  for (int x = 40; x < 43; ++x) samples.add(x, 40);
  samples.add(68, 22);

  const size_t n = 103, M = 32, bag = 150;  // n: not a multiple of any vector width
  std::vector<float> v(n), H(bag), h(bag * M);
  for (size_t i = 0; i < n; ++i) v[i] = static_cast<float>(std::sin(0.7 * i) * 40 + 10);
  for (size_t j = 0; j < bag; ++j) H[j] = static_cast<float>(std::sin(j) * 30);
  for (size_t i = 0; i < h.size(); ++i) h[i] = static_cast<float>(std::cos(3.0 * i) * 20 - 5);

  struct Result {
    cv::Mat feats;
    std::vector<float> ratio;
    std::vector<double> sums;
  };
  auto run = [&] {
    Result r;
    evaluate_features(ch, features, samples, r.feats);
    r.ratio.assign(n, 0.5f);
    kernels::add_log_ratio(v.data(), n, 12.f, 9.f, -3.f, 20.f, -50.f, r.ratio.data());
    r.sums.assign(M, 0.0);
    kernels::softplus_sums(H.data(), h.data(), bag, M, M, r.sums.data());
    return r;
  };

  Result reference;  // the portable target: plain C++ lanes
  {
    ForceTarget force(scalar_target());
    ASSERT_STREQ(kernels::target_name(), hwy::TargetName(scalar_target()));
    reference = run();
  }
  for (int64_t t : cpu_targets()) {
    SCOPED_TRACE(hwy::TargetName(t));
    ForceTarget force(t);
    ASSERT_STREQ(kernels::target_name(), hwy::TargetName(t));  // the mock reaches the kernels
    const Result r = run();
    ASSERT_EQ(r.feats.size(), reference.feats.size());
    for (int f = 0; f < r.feats.rows; ++f)
      for (int i = 0; i < r.feats.cols; ++i) {
        const float a = r.feats.at<float>(f, i), b = reference.feats.at<float>(f, i);
        ASSERT_NEAR(a, b, 1e-5f * (1 + std::abs(b))) << "feature " << f << " sample " << i;
      }
    for (size_t i = 0; i < n; ++i) ASSERT_NEAR(r.ratio[i], reference.ratio[i], 1e-5f * (1 + std::abs(reference.ratio[i]))) << i;
    for (size_t m = 0; m < M; ++m) ASSERT_NEAR(r.sums[m], reference.sums[m], 1e-6 * (1 + std::abs(reference.sums[m]))) << m;
  }
}

TEST(SimdTargets, SgmGivesIdenticalDisparitiesOnEveryTarget) {
  using namespace aerie::stereo;
  // A textured pair with a disparity ramp, at a size that is no multiple of a vector width.
  const cv::Size size(157, 61);
  cv::Mat noise(size, CV_8UC1), left, right;
  cv::RNG(7).fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(noise, left, cv::Size(0, 0), 1.0);
  cv::normalize(left, left, 0, 255, cv::NORM_MINMAX);
  cv::Mat mx(size, CV_32FC1), my(size, CV_32FC1);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      mx.at<float>(y, x) = static_cast<float>((x + 9.0 + 0.1 * y) / (1.0 - 0.04));
      my.at<float>(y, x) = static_cast<float>(y);
    }
  cv::remap(left, right, mx, my, cv::INTER_CUBIC, cv::BORDER_REFLECT);
  const cv::Mat offsets(size, CV_16SC1, cv::Scalar(4));

  for (int paths : {4, 8}) {
    SgmParams p;
    p.num_disparities = 32;
    p.paths = paths;
    auto run = [&] {
      SemiGlobalMatcher sgm(p);
      std::vector<cv::Mat> out{sgm.compute(left, right).clone(), sgm.compute(left, right, offsets, 16).clone()};
      return out;
    };
    std::vector<cv::Mat> reference;
    {
      ForceTarget force(scalar_target());
      ASSERT_STREQ(SemiGlobalMatcher::simd_target(), hwy::TargetName(scalar_target()));
      reference = run();
    }
    ASSERT_GT(cv::countNonZero(reference[0] >= 0), size.area() / 2);  // it matched something
    for (int64_t t : cpu_targets()) {
      SCOPED_TRACE(std::string(hwy::TargetName(t)) + ", " + std::to_string(paths) + " paths");
      ForceTarget force(t);
      ASSERT_STREQ(SemiGlobalMatcher::simd_target(), hwy::TargetName(t));
      const std::vector<cv::Mat> out = run();
      for (size_t k = 0; k < out.size(); ++k) {
        ASSERT_EQ(out[k].size(), reference[k].size());
        // Bit for bit: census, costs and aggregation are integer; the subpixel step is one
        // float division per pixel, the same instructions on every target (no FMA contraction).
        EXPECT_EQ(cv::norm(out[k], reference[k], cv::NORM_INF), 0.0) << (k ? "restricted window" : "full range");
        EXPECT_EQ(0, std::memcmp(out[k].data, reference[k].data, out[k].total() * out[k].elemSize()));
      }
    }
  }
}
