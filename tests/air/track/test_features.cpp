// Integral images, sample sets and rectangle features against brute force.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>
#include <set>

#include "air/track/features/channels.hpp"
#include "air/track/features/kernels.hpp"
#include "air/track/features/rect_features.hpp"
#include "air/track/features/samples.hpp"

using namespace aerie::track;

namespace {

cv::Mat random_image(cv::Size size, uint64_t seed) {
  cv::Mat img(size, CV_8UC1);
  cv::RNG(seed).fill(img, cv::RNG::UNIFORM, 0, 256);
  return img;
}

int brute_sum(const cv::Mat& img, cv::Point origin, int x, int y, int w, int h) {
  int s = 0;
  for (int r = y; r < y + h; ++r)
    for (int c = x; c < x + w; ++c) s += img.at<uint8_t>(r - origin.y, c - origin.x);
  return s;
}

}  // namespace

TEST(IntegralImage, SumsInGlobalCoordinatesMatchBruteForce) {
  const cv::Mat img = random_image({37, 29}, 1);
  const cv::Point origin(100, 50);  // the crop starts at (100, 50) of its level image
  const IntegralImage ii(img, origin);
  EXPECT_EQ(ii.roi(), cv::Rect(100, 50, 37, 29));
  EXPECT_EQ(ii.sum(100, 50, 37, 29), brute_sum(img, origin, 100, 50, 37, 29));
  EXPECT_EQ(ii.sum(107, 61, 5, 9), brute_sum(img, origin, 107, 61, 5, 9));
  EXPECT_EQ(ii.sum(136, 78, 1, 1), img.at<uint8_t>(28, 36));
  EXPECT_THROW(IntegralImage(cv::Mat(4, 4, CV_32F), {}), std::invalid_argument);
}

// Table 3.1: the test samples are the integer offsets strictly inside the search radius.
TEST(Samples, DiscCountsOfTable31) {
  const std::pair<double, size_t> table[] = {{5, 69},    {6, 109},   {7, 145},   {8, 193},   {9, 249},
                                             {10, 305},  {11, 373},  {12, 437},  {13, 517},  {14, 609},
                                             {15, 697},  {16, 793},  {17, 889},  {18, 1005}, {19, 1125},
                                             {20, 1245}, {21, 1369}, {22, 1513}, {23, 1649}, {24, 1789},
                                             {25, 1941}, {26, 2109}, {27, 2285}, {28, 2449}, {29, 2617},
                                             {30, 2809}};
  const cv::Rect big(0, 0, 1000, 1000);
  for (auto [r, n] : table) {
    const SampleSet s = disc_samples({500, 500}, r, {10, 10}, big);
    EXPECT_EQ(s.size(), n) << "radius " << r;
    size_t in_runs = 0;
    for (const auto& run : s.runs()) in_runs += run.count;
    EXPECT_EQ(in_runs, n);
    EXPECT_EQ(s.runs().size(), 2 * static_cast<size_t>(std::ceil(r)) - 1) << "one run per row";
  }
}

TEST(Samples, DiscKeepsBoxesInsideBounds) {
  const SampleSet s = disc_samples({2, 3}, 5, {10, 8}, cv::Rect(0, 0, 20, 15));
  ASSERT_FALSE(s.empty());
  for (const auto& p : s.positions()) {
    EXPECT_GE(p.x, 0);
    EXPECT_GE(p.y, 0);
    EXPECT_LE(p.x + 10, 20);
    EXPECT_LE(p.y + 8, 15);
    EXPECT_LT((p.x - 2) * (p.x - 2) + (p.y - 3) * (p.y - 3), 25);
  }
}

TEST(Samples, RingDrawsDistinctOffsetsInTheAnnulusReproducibly) {
  Rng a(7), b(7);
  const SampleSet s = ring_samples({200, 200}, 8, 30, 50, {20, 20}, cv::Rect(0, 0, 500, 500), a);
  const SampleSet t = ring_samples({200, 200}, 8, 30, 50, {20, 20}, cv::Rect(0, 0, 500, 500), b);
  ASSERT_EQ(s.size(), 50u);
  EXPECT_EQ(s.positions(), t.positions());
  std::set<std::pair<int, int>> seen;
  for (const auto& p : s.positions()) {
    const double d = std::hypot(p.x - 200, p.y - 200);
    EXPECT_GT(d, 8);
    EXPECT_LT(d, 30);
    EXPECT_TRUE(seen.insert({p.x, p.y}).second) << "drawn twice";
  }
  // fewer candidates than asked: all of them
  Rng c(1);
  EXPECT_EQ(ring_samples({50, 50}, 0.5, 1.5, 100, {4, 4}, cv::Rect(0, 0, 100, 100), c).size(), 8u);
}

TEST(RectFeatures, EvaluationMatchesBruteForceOnEveryChannel) {
  const cv::Size size(90, 70);
  cv::Mat gray = random_image(size, 3), chroma(size, CV_8UC2);
  cv::RNG(4).fill(chroma, cv::RNG::UNIFORM, 0, 256);
  const cv::Point origin(10, 20);
  ChannelImages ch;
  ch.compute(gray, chroma, {kGray, kGradient, kChromaCr, kChromaCb}, origin);
  cv::Mat planes[2];
  cv::split(chroma, planes);
  const cv::Mat images[4] = {gray, gradient_magnitude(gray), planes[0], planes[1]};

  Rng rng(5);
  const cv::Size box(21, 17);
  auto features = make_haar_features(box, 40, 2, 4, {kGray, kGradient, kChromaCr, kChromaCb}, rng);
  const auto ct = make_compressive_features(box, 40, 2, 4, {kGray, kGradient}, rng);
  features.insert(features.end(), ct.begin(), ct.end());
  for (const auto& f : features) {
    ASSERT_GE(f.count, 2);
    ASSERT_LE(f.count, 4);
    for (int r = 0; r < f.count; ++r) {
      EXPECT_LE(f.rects[r].x + f.rects[r].w, box.width);
      EXPECT_LE(f.rects[r].y + f.rects[r].h, box.height);
    }
  }
  // runs of 19, 10, 6 and 3 samples and singletons: every kernel path (wide and narrow
  // vectors with lanes past the run's end, scalar)
  SampleSet samples;
  for (int x = 12; x < 31; ++x) samples.add(x, 25);
  for (int x = 14; x < 24; ++x) samples.add(x, 30);
  for (int x = 20; x < 26; ++x) samples.add(x, 33);
  for (int x = 40; x < 43; ++x) samples.add(x, 40);
  samples.add(40, 48);
  samples.add(68, 22);
  cv::Mat out;
  evaluate_features(ch, features, samples, out);
  ASSERT_EQ(out.rows, static_cast<int>(features.size()));
  ASSERT_EQ(out.cols, static_cast<int>(samples.size()));
  for (size_t f = 0; f < features.size(); ++f)
    for (size_t i = 0; i < samples.size(); ++i) {
      const cv::Point p = samples.positions()[i];
      double expect = 0;
      for (int r = 0; r < features[f].count; ++r) {
        const auto& q = features[f].rects[r];
        expect += q.weight * brute_sum(images[features[f].channel], origin, p.x + q.x, p.y + q.y, q.w, q.h);
      }
      EXPECT_NEAR(out.at<float>(static_cast<int>(f), static_cast<int>(i)), expect, 1e-3 * (1 + std::abs(expect)))
          << "feature " << f << " sample " << i;
    }
  // subset evaluation: row k = feature which[k]
  cv::Mat sub;
  evaluate_features(ch, features, {5, 2}, samples, sub);
  EXPECT_EQ(sub.at<float>(0, 3), out.at<float>(5, 3));
  EXPECT_EQ(sub.at<float>(1, 20), out.at<float>(2, 20));
  EXPECT_EQ(sub.at<float>(1, 39), out.at<float>(2, 39));
  // a sample reaching outside the integral image is a programming error, not a silent read
  SampleSet outside;
  outside.add(origin.x + size.width - 5, 25);
  EXPECT_THROW(evaluate_features(ch, features, outside, out), std::logic_error);
}

TEST(RectFeatures, CompressiveWeightsAreSignsAndHaarWeightsAreMeans) {
  Rng rng(9);
  for (const auto& f : make_compressive_features({30, 30}, 100, 2, 4, {kGray}, rng))
    for (int r = 0; r < f.count; ++r) EXPECT_EQ(std::abs(f.rects[r].weight), 1.0f);
  for (const auto& f : make_haar_features({30, 30}, 100, 2, 4, {kGray}, rng))
    for (int r = 0; r < f.count; ++r) EXPECT_LE(std::abs(f.rects[r].weight) * f.rects[r].w * f.rects[r].h, 1.0f + 1e-6f);
  EXPECT_THROW(make_haar_features({3, 30}, 10, 2, 4, {kGray}, rng), std::invalid_argument);
  EXPECT_THROW(make_haar_features({30, 30}, 10, 3, 2, {kGray}, rng), std::invalid_argument);
}

TEST(RectFeatures, ScaledFeaturesKeepValuesComparable) {
  // On a constant image a feature's value is weight x area x grey (CT) at every scale.
  const cv::Mat flat(200, 200, CV_8UC1, cv::Scalar(100));
  ChannelImages ch;
  ch.compute(flat, {}, {kGray}, {0, 0});
  Rng rng(2);
  const auto base = make_compressive_features({40, 30}, 20, 2, 4, {kGray}, rng);
  ScaledFeatures sf(base, {40, 30});
  SampleSet one;
  one.add(50, 50);
  cv::Mat v1, v2;
  evaluate_features(ch, sf.at(1.0), one, v1);
  evaluate_features(ch, sf.at(1.6), one, v2);
  for (int f = 0; f < v1.rows; ++f) EXPECT_NEAR(v2.at<float>(f, 0), v1.at<float>(f, 0), 1e-3 * std::abs(v1.at<float>(f, 0)));
  EXPECT_GE(sf.footprint(1.6).width, 64);
  EXPECT_GE(sf.footprint(1.6).height, 48);
}

TEST(Kernels, SoftplusSumsMatchScalarReference) {
  // 37 instances x 32 weak classifiers (row j holds every m), more than 64 instances too
  for (size_t n : {37u, 150u}) {
    const size_t M = 32;
    std::vector<float> H(n), h(n * M);
    for (size_t j = 0; j < n; ++j) H[j] = static_cast<float>(std::sin(j) * 30);
    for (size_t i = 0; i < h.size(); ++i) h[i] = static_cast<float>(std::cos(3.0 * i) * 20 - 5);
    std::vector<double> S(M);
    kernels::softplus_sums(H.data(), h.data(), n, M, M, S.data());
    for (size_t m = 0; m < M; ++m) {
      double expect = 0;
      for (size_t j = 0; j < n; ++j) expect += std::log1p(std::exp(static_cast<double>(H[j]) + h[j * M + m]));
      EXPECT_NEAR(S[m], expect, 1e-5 * expect + 1e-5) << "m " << m << " n " << n;
    }
  }
}

TEST(Channels, UnknownChannelNameIsAnError) {
  EXPECT_EQ(parse_channels({"gray", "color"}), (std::vector<int>{kGray, kChromaCr, kChromaCb}));
  EXPECT_THROW(parse_channels({"hog"}), std::invalid_argument);
  EXPECT_THROW(parse_channels({}), std::invalid_argument);
}
