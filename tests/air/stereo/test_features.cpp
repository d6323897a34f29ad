// Bucketed FAST + modified BRIEF: bucket limits (eq. 4.5), the sampling distribution of
// the test pairs (eq. 4.7), descriptor definition (eq. 4.6) and matching.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "air/stereo/features/features.hpp"

using namespace aerie::stereo;

namespace {

cv::Mat textured(cv::Size size, int seed) {
  cv::RNG rng(seed);
  cv::Mat noise(size, CV_8UC1), img;
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(noise, img, cv::Size(0, 0), 1.5);
  cv::normalize(img, img, 0, 255, cv::NORM_MINMAX);
  return img;
}

void mean_std(const std::vector<double>& v, double& mean, double& sd) {
  mean = 0;
  for (double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  sd = 0;
  for (double x : v) sd += (x - mean) * (x - mean);
  sd = std::sqrt(sd / static_cast<double>(v.size()));
}

}  // namespace

TEST(Features, BriefSamplingFollowsEq4_7) {
  const int sr = 25;
  const BriefPattern p = BriefPattern::sample(sr, 40000, 11);
  ASSERT_EQ(p.x.size(), 40000u);
  std::vector<double> xs, dys;
  for (size_t j = 0; j < p.x.size(); ++j) {
    ASSERT_LE(std::abs(p.x[j].x), sr / 2);
    ASSERT_LE(std::abs(p.y[j].y), sr / 2);
    ASSERT_NE(p.x[j], p.y[j]);
    for (int axis = 0; axis < 2; ++axis) {
      const double xj = axis ? p.x[j].y : p.x[j].x, yj = axis ? p.y[j].y : p.y[j].x;
      xs.push_back(xj);
      dys.push_back(yj - xj);
    }
  }
  double m, sd;
  mean_std(xs, m, sd);
  EXPECT_NEAR(m, 0.0, 0.1);
  EXPECT_NEAR(sd, sr / 5.0, 0.05 * sr / 5.0);  // x_j ~ N(0, (S_r/5)^2): 5 px
  mean_std(dys, m, sd);
  EXPECT_NEAR(m, 0.0, 0.05);
  EXPECT_NEAR(sd, 2.0 * sr / 25.0, 0.1 * 2.0 * sr / 25.0);  // y_j - x_j ~ N(0, (2 S_r/25)^2): 2 px
  // The same seed gives the same pattern, another seed another one.
  const BriefPattern again = BriefPattern::sample(sr, 256, 11), other = BriefPattern::sample(sr, 256, 12);
  EXPECT_TRUE(std::equal(again.x.begin(), again.x.end(), p.x.begin()));
  EXPECT_FALSE(std::equal(other.x.begin(), other.x.end(), p.x.begin()));
}

TEST(Features, DescriptorIsEq4_6) {
  FeatureExtractor fx;
  const cv::Mat img = textured({200, 150}, 3);
  const cv::Point p(100, 70);
  const Descriptor d = fx.describe(img, p);
  const BriefPattern& pat = fx.pattern();
  for (size_t j = 0; j < pat.x.size(); ++j) {
    const bool bit = (d[j / 64] >> (j % 64)) & 1;
    EXPECT_EQ(bit, img.at<uint8_t>(p + pat.x[j]) < img.at<uint8_t>(p + pat.y[j])) << "bit " << j;
  }
}

TEST(Features, BucketLimitsAndGeometry) {
  FeatureParams fp;  // 6 x 4 buckets, 20 each
  FeatureExtractor fx(fp);
  const cv::Mat img = textured({376, 240}, 5);
  const FeatureFrame f = fx.extract(img);
  ASSERT_EQ(f.per_bucket.size(), 24u);
  int total = 0;
  for (int n : f.per_bucket) {
    EXPECT_LE(n, 20);
    EXPECT_GT(n, 10);  // dense texture: every bucket has corners
    total += n;
  }
  EXPECT_EQ(total, static_cast<int>(f.features.size()));
  EXPECT_LE(total, 480);
  // Eq. 4.5: B_W = (I_W - 2 O_W) / N_x, B_H = (I_H - 2 O_H) / N_y.
  EXPECT_EQ(f.roi, cv::Rect(16, 16, 376 - 32, 240 - 32));
  EXPECT_EQ(FeatureExtractor::bucket_rect(fp, img.size(), 0, 0), cv::Rect(16, 16, 344 / 6, 208 / 4));
  for (const auto& feat : f.features) {
    const cv::Rect b = FeatureExtractor::bucket_rect(fp, img.size(), feat.bucket % 6, feat.bucket / 6);
    EXPECT_TRUE(b.contains(cv::Point(cvRound(feat.pt.x), cvRound(feat.pt.y))));
  }
  // Fewer allowed per bucket: the limit holds exactly on a rich image.
  fp.max_per_bucket = 3;
  FeatureExtractor few(fp);
  const FeatureFrame g = few.extract(img);
  for (int n : g.per_bucket) EXPECT_EQ(n, 3);
  // A flat image has no corners; an image smaller than margins + buckets is refused.
  EXPECT_TRUE(fx.extract(cv::Mat(240, 376, CV_8UC1, cv::Scalar(128))).features.empty());
  EXPECT_THROW(fx.extract(cv::Mat(40, 60, CV_8UC1, cv::Scalar(0))), std::invalid_argument);
  fp.margin_x = 4;  // smaller than the BRIEF window needs
  EXPECT_THROW(FeatureExtractor{fp}, std::invalid_argument);
}

TEST(Features, MatchesAShiftedImage) {
  FeatureExtractor fx;
  const cv::Mat a = textured({376, 240}, 9);
  cv::Mat b;
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 5, 0, 1, 3);
  cv::warpAffine(a, b, shift, a.size(), cv::INTER_NEAREST, cv::BORDER_REFLECT);
  const FeatureFrame fa = fx.extract(a), fb = fx.extract(b);
  const auto matches = match_features(fa.features, fb.features, fx.descriptor_words(), MatchParams{});
  ASSERT_GT(matches.size(), 200u);
  int exact = 0;
  for (const auto& m : matches) {
    const cv::Point2f d = fb.features[m.cur].pt - fa.features[m.prev].pt;
    if (std::abs(d.x - 5) < 0.5 && std::abs(d.y - 3) < 0.5) ++exact;
  }
  EXPECT_GT(exact, 0.98 * static_cast<double>(matches.size()));
  // With a prediction far away nothing is found within the search radius.
  std::vector<cv::Point2f> far(fa.features.size(), cv::Point2f(-1000, -1000));
  EXPECT_TRUE(match_features(fa.features, fb.features, fx.descriptor_words(), MatchParams{}, &far).empty());
}
