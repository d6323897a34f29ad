// Naive Bayes (eqs. 3.20-3.22) and online MILBoost (eqs. 3.27-3.30, Algorithm 2) against
// values computed by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "air/track/ct/naive_bayes.hpp"
#include "air/track/mil/mil_boost.hpp"

using namespace aerie::track;

namespace {
cv::Mat row(std::vector<float> v) { return cv::Mat(v, true).reshape(1, 1); }
double sigmoid(double z) { return 1 / (1 + std::exp(-z)); }
}  // namespace

TEST(NaiveBayes, Eq322UpdateByHand) {
  // old N(10, 2), new samples {4, 6, 8}: mu^1 = 6, sigma^1 = sqrt(8/3), eta = 0.85
  const Gaussian g = blend_ct({10, 2}, {6, static_cast<float>(std::sqrt(8.0 / 3))}, 0.85);
  EXPECT_NEAR(g.mu, 9.4, 1e-5);  // 0.85 * 10 + 0.15 * 6
  // sqrt(0.85 * 4 + 0.15 * 8/3 + 0.85 * 0.15 * (10 - 6)^2) = sqrt(5.84)
  EXPECT_NEAR(g.sigma, std::sqrt(5.84), 1e-5);

  const float v[] = {4, 6, 8};
  const Gaussian s = sample_gaussian(v, 3);
  EXPECT_NEAR(s.mu, 6, 1e-6);
  EXPECT_NEAR(s.sigma, std::sqrt(8.0 / 3), 1e-6);
}

TEST(NaiveBayes, FirstUpdateInitialisesThenBlendsAndClassifiesWithTheLogRatio) {
  NaiveBayes nb({0.5f}, 0.85, std::log(1e-30));
  nb.update(row({9, 11}), row({-3, 3}));  // pos N(10, 1), neg N(0, 3)
  EXPECT_NEAR(nb.positive()[0].mu, 10, 1e-6);
  EXPECT_NEAR(nb.positive()[0].sigma, 1, 1e-6);
  EXPECT_NEAR(nb.negative()[0].sigma, 3, 1e-6);
  nb.update(row({4, 6, 8}), row({0}));  // eq. 3.22; the single negative has sigma 0
  EXPECT_NEAR(nb.positive()[0].mu, 0.85 * 10 + 0.15 * 6, 1e-5);
  EXPECT_NEAR(nb.positive()[0].sigma, std::sqrt(0.85 * 1 + 0.15 * 8.0 / 3 + 0.85 * 0.15 * 16), 1e-5);
  EXPECT_NEAR(nb.negative()[0].sigma, std::sqrt(0.85 * 9 + 0.15 * 0 + 0), 1e-5);

  // eq. 3.20 with one feature: log N(v; mu1, s1) - log N(v; mu0, s0)
  std::vector<float> scores;
  nb.classify(row({5, 40}), scores);
  const double m1 = nb.positive()[0].mu, s1 = nb.positive()[0].sigma, m0 = nb.negative()[0].mu,
               s0 = nb.negative()[0].sigma;
  auto logn = [](double x, double m, double s) { return -(x - m) * (x - m) / (2 * s * s) - std::log(s); };
  EXPECT_NEAR(scores[0], logn(5, m1, s1) - logn(5, m0, s0), 1e-4);
  // far in the tails both densities are below the 1e-30 floor: the ratio saturates
  EXPECT_NEAR(scores[1], std::max(logn(40, m1, s1), std::log(1e-30)) - std::max(logn(40, m0, s0), std::log(1e-30)),
              1e-3);
}

TEST(NaiveBayes, SigmaFloorAndBadInput) {
  NaiveBayes nb({1.0f, 1.0f}, 0.85, -69);
  cv::Mat pos(2, 3, CV_32F, cv::Scalar(7)), neg(2, 3, CV_32F, cv::Scalar(1));
  nb.update(pos, neg);
  EXPECT_EQ(nb.positive()[1].sigma, 1.0f);  // all samples equal: floored, not zero
  EXPECT_THROW(nb.update(cv::Mat(3, 3, CV_32F), neg), std::invalid_argument);
  EXPECT_THROW(NaiveBayes({1.0f, 1.0f}, 1.0, -69), std::invalid_argument);
  EXPECT_THROW(NaiveBayes({1.0f, 0.0f}, 0.5, -69), std::invalid_argument);
}

TEST(MilBoost, Eq330UpdateByHand) {
  const float f[] = {4, 6, 8};
  const Gaussian g = blend_mil({10, 2}, f, 3, 0.85);
  EXPECT_NEAR(g.mu, 9.4, 1e-5);
  // sigma = 0.85 * 2 + 0.15 * sqrt(((4-9.4)^2 + (6-9.4)^2 + (8-9.4)^2) / 3)
  EXPECT_NEAR(g.sigma, 1.7 + 0.15 * std::sqrt((29.16 + 11.56 + 1.96) / 3), 1e-5);
}

TEST(MilBoost, BagLogLikelihoodOfAlgorithm2) {
  // positive bag instances with H + h = {0, 1}, one negative with -2 (Algorithm 2, lines 8-11)
  const double p_bag = 1 - (1 - sigmoid(0)) * (1 - sigmoid(1));
  const double expect = std::log(p_bag) + std::log(1 - sigmoid(-2));
  const double sp_pos = std::log1p(std::exp(0.0)) + std::log1p(std::exp(1.0));
  const double sp_neg = std::log1p(std::exp(-2.0));
  EXPECT_NEAR(bag_log_likelihood(sp_pos, sp_neg), expect, 1e-12);
}

TEST(MilBoost, SelectsTheDiscriminativeWeakClassifiersFirst) {
  // Pool of 4 features; feature 2 separates the bags, feature 0 a little, 1 and 3 not at all.
  const int np = 6, nn = 8;
  cv::Mat pos(4, np, CV_32F), neg(4, nn, CV_32F);
  for (int j = 0; j < np; ++j) {
    pos.at<float>(0, j) = 52.0f + (j % 3) * 4;
    pos.at<float>(1, j) = 100.0f + (j % 2 ? 5 : -5);
    pos.at<float>(2, j) = 200.0f + j;
    pos.at<float>(3, j) = 30.0f + (j % 3) * 10;
  }
  for (int j = 0; j < nn; ++j) {
    neg.at<float>(0, j) = 48.0f + (j % 4) * 3;
    neg.at<float>(1, j) = 100.0f + (j % 2 ? -5 : 5);
    neg.at<float>(2, j) = 20.0f + j;
    neg.at<float>(3, j) = 30.0f + (j % 3) * 10;
  }
  MilBoost boost(std::vector<float>(4, 1.0f), 2, 0.85, std::log(1e-30));
  boost.update(pos, neg);
  ASSERT_EQ(boost.selected().size(), 2u);
  EXPECT_EQ(boost.selected()[0], 2);
  EXPECT_NE(boost.selected()[1], 2);  // K distinct weak classifiers
  // the strong classifier separates the bags
  std::vector<float> sp, sn;
  cv::Mat pos_sel, neg_sel;
  cv::vconcat(pos.row(boost.selected()[0]), pos.row(boost.selected()[1]), pos_sel);
  cv::vconcat(neg.row(boost.selected()[0]), neg.row(boost.selected()[1]), neg_sel);
  boost.classify(pos_sel, sp);
  boost.classify(neg_sel, sn);
  EXPECT_GT(*std::min_element(sp.begin(), sp.end()), *std::max_element(sn.begin(), sn.end()));
  // H_K = sum of the selected weak classifiers (eq. 3.27)
  EXPECT_NEAR(sp[0], boost.weak(boost.selected()[0], pos.at<float>(boost.selected()[0], 0)) +
                         boost.weak(boost.selected()[1], pos.at<float>(boost.selected()[1], 0)),
              1e-4);
  EXPECT_THROW(MilBoost(std::vector<float>(4, 1.0f), 5, 0.85, -69), std::invalid_argument);
}
