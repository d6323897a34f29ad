// FHOG features and the DCF tracker's own properties (the shared motion tests are in
// test_trackers.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "air/track/dcf/dcf.hpp"
#include "air/track/dcf/fhog.hpp"
#include "air/track/dcf/scale_filter.hpp"
#include "tests/air/track/fhog_reference.hpp"
#include "tests/air/track/synthetic.hpp"

using namespace aerie::track;
using aerie::track::test::Motion;
using aerie::track::test::Scene;

namespace {

// Index of the channel in [first, first + count) with the largest sum.
int strongest(const std::vector<cv::Mat>& h, int first, int count) {
  int best = first;
  for (int c = first; c < first + count; ++c)
    if (cv::sum(h[c])[0] > cv::sum(h[best])[0]) best = c;
  return best;
}

}  // namespace

TEST(Fhog, CellGridAndChannels) {
  const auto h = fhog(test::texture({67, 45}, 1, 2, 0, 255), 4);
  ASSERT_EQ(h.size(), size_t(kFhogChannels));
  for (const auto& c : h) {
    EXPECT_EQ(c.size(), cv::Size(16, 11));  // floor(67 / 4) x floor(45 / 4)
    EXPECT_EQ(c.type(), CV_32F);
  }
}

TEST(Fhog, FlatImageHasNoFeatures) {
  for (const auto& c : fhog(cv::Mat(32, 32, CV_8UC3, cv::Scalar(10, 200, 90)), 4))
    EXPECT_EQ(cv::norm(c, cv::NORM_INF), 0.0);
}

// A ramp brightening to the right has gradient orientation 0: signed bin 0, unsigned bin 0;
// brightening downwards: 90 degrees = signed bin 4.5 (bins 4 and 5), unsigned bins 4 and 5;
// darkening to the right: 180 degrees = signed bin 9, unsigned bin 0 again.
TEST(Fhog, OrientationBins) {
  cv::Mat ramp(40, 40, CV_8U);
  for (int y = 0; y < ramp.rows; ++y)
    for (int x = 0; x < ramp.cols; ++x) ramp.at<uchar>(y, x) = static_cast<uchar>(5 * x);
  auto h = fhog(ramp, 4);
  EXPECT_EQ(strongest(h, 0, 18), 0);
  EXPECT_EQ(strongest(h, 18, 9), 18);
  h = fhog(ramp.t(), 4);
  const int s = strongest(h, 0, 18);
  EXPECT_TRUE(s == 4 || s == 5) << s;
  EXPECT_NEAR(cv::sum(h[4])[0], cv::sum(h[5])[0], 1e-3 * cv::sum(h[4])[0]);
  const int u = strongest(h, 18, 9);
  EXPECT_TRUE(u == 22 || u == 23) << u;
  cv::Mat falling;
  cv::flip(ramp, falling, 1);
  h = fhog(falling, 4);
  EXPECT_EQ(strongest(h, 0, 18), 9);
  EXPECT_EQ(strongest(h, 18, 9), 18);
}

// Every orientation feature is half the sum of four values truncated at 0.2: at most 0.4;
// doubling the contrast leaves the features unchanged (block normalisation).
TEST(Fhog, TruncatedAndContrastInvariant) {
  const cv::Mat img = test::texture({48, 48}, 3, 1.5, 20, 120);
  cv::Mat brighter;
  img.convertTo(brighter, CV_8U, 2.0);
  const auto a = fhog(img, 4), b = fhog(brighter, 4);
  for (int c = 0; c < 27; ++c) {
    double hi;
    cv::minMaxLoc(a[c], nullptr, &hi);
    EXPECT_LE(hi, 0.4 + 1e-6);
    EXPECT_LT(cv::norm(a[c], b[c], cv::NORM_INF), 1e-3) << c;
  }
}

// The vectorised fhog() against the scalar version it replaced, on random images of odd sizes
// (gradients at every border, partial cells, vector tails), grey and BGR, smooth and rough,
// several cell sizes.
TEST(Fhog, MatchesTheScalarReference) {
  cv::RNG rng(5);
  const cv::Size sizes[] = {{67, 45}, {1, 1}, {3, 7}, {19, 23}, {33, 17}, {101, 77}, {257, 129}};
  for (const cv::Size size : sizes)
    for (const int type : {CV_8UC1, CV_8UC3})
      for (const double blur : {0.0, 1.3}) {
        cv::Mat img(size, type);
        rng.fill(img, cv::RNG::UNIFORM, 0, 256);
        if (blur > 0) cv::GaussianBlur(img, img, {0, 0}, blur);
        for (const int cell : {1, 2, 3, 4, 5, 6, 8}) {
          if (size.width < cell || size.height < cell) continue;
          const auto want = reference::fhog_reference(img, cell), got = fhog(img, cell);
          ASSERT_EQ(got.size(), want.size());
          for (int c = 0; c < kFhogChannels; ++c) {
            ASSERT_EQ(got[c].size(), want[c].size());
            EXPECT_LE(cv::norm(got[c], want[c], cv::NORM_INF), 1e-5)
                << size << " channels " << img.channels() << " blur " << blur << " cell " << cell << " feature " << c;
          }
        }
      }
}

TEST(Fhog, BadInputIsRejected) {
  EXPECT_THROW(fhog(cv::Mat(), 4), std::invalid_argument);
  EXPECT_THROW(fhog(cv::Mat(10, 10, CV_32F), 4), std::invalid_argument);
  EXPECT_THROW(fhog(cv::Mat(10, 10, CV_8U), 0), std::invalid_argument);
  EXPECT_THROW(fhog(cv::Mat(3, 10, CV_8U), 4), std::invalid_argument);
}

namespace {

// J(g) = |X G - Y|^2 + lambda / 2 |g|^2 of a real spatial filter g (the objective of masked_filter).
double objective(const cv::Mat& g, const cv::Mat& xf, const cv::Mat& yf, double lambda) {
  cv::Mat gf, r;
  cv::dft(g, gf, cv::DFT_COMPLEX_OUTPUT);
  cv::mulSpectrums(gf, xf, r, 0);
  return std::pow(cv::norm(r - yf), 2) + lambda / 2 * std::pow(cv::norm(g), 2);
}

cv::Mat spatial(const cv::Mat& gf) {
  cv::Mat g;
  cv::dft(gf, g, cv::DFT_INVERSE | cv::DFT_REAL_OUTPUT | cv::DFT_SCALE);
  return g;
}

}  // namespace

// The ADMM filter is zero outside the mask and reaches the constrained least-squares optimum,
// solved here directly over the 25 unknowns of a 5x5 support: (D A'A + lambda/2 I) g = D A'y
// with A's columns the circular shifts of x (D = number of cells, Parseval).
TEST(Dcf, MaskedFilterIsTheConstrainedLeastSquaresFilter) {
  const int n = 16, d = n * n;
  cv::Mat x(n, n, CV_32F), y(n, n, CV_32F), mask = cv::Mat::zeros(n, n, CV_32F);
  cv::RNG(5).fill(x, cv::RNG::NORMAL, 0, 1);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int di = i > n / 2 ? i - n : i, dj = j > n / 2 ? j - n : j;
      y.at<float>(i, j) = std::exp(-0.5f * (di * di + dj * dj) / 2.0f);
    }
  mask(cv::Rect(6, 6, 5, 5)).setTo(1);
  cv::Mat xf, yf;
  cv::dft(x, xf, cv::DFT_COMPLEX_OUTPUT);
  cv::dft(y, yf, cv::DFT_COMPLEX_OUTPUT);
  DcfParams p;
  p.lambda = 0.5;

  // Direct solution.
  cv::Mat A(d, 25, CV_64F);
  int col = 0;
  for (int u = 6; u < 11; ++u)
    for (int v = 6; v < 11; ++v, ++col) {
      cv::Mat e = cv::Mat::zeros(n, n, CV_32F), ef, r;
      e.at<float>(u, v) = 1;
      cv::dft(e, ef, cv::DFT_COMPLEX_OUTPUT);
      cv::mulSpectrums(ef, xf, r, 0);
      spatial(r).reshape(1, d).convertTo(A.col(col), CV_64F);
    }
  cv::Mat yv;
  y.reshape(1, d).convertTo(yv, CV_64F);
  const cv::Mat lhs = d * A.t() * A + p.lambda / 2 * cv::Mat::eye(25, 25, CV_64F), rhs = d * A.t() * yv;
  cv::Mat sol;
  ASSERT_TRUE(cv::solve(lhs, rhs, sol, cv::DECOMP_CHOLESKY));
  cv::Mat best = cv::Mat::zeros(n, n, CV_32F);
  col = 0;
  for (int u = 6; u < 11; ++u)
    for (int v = 6; v < 11; ++v, ++col) best.at<float>(u, v) = static_cast<float>(sol.at<double>(col));
  const double optimum = objective(best, xf, yf, p.lambda);

  // Unconstrained least squares cut to the mask: the naive alternative.
  p.admm_iterations = 0;
  const double cut = objective(spatial(masked_filter(xf, yf, mask, p)), xf, yf, p.lambda);
  p.admm_iterations = 4;  // the tracker's setting
  const cv::Mat g4 = spatial(masked_filter(xf, yf, mask, p));
  p.admm_iterations = 300;
  const cv::Mat g300 = spatial(masked_filter(xf, yf, mask, p));

  cv::Mat outside;
  cv::bitwise_not(mask > 0, outside);
  EXPECT_LT(cv::norm(g4, cv::NORM_INF, outside), 1e-6 * cv::norm(g4, cv::NORM_INF));  // DFT round-off
  EXPECT_LT(objective(g4, xf, yf, p.lambda), cut);
  EXPECT_NEAR(objective(g300, xf, yf, p.lambda), optimum, 1e-3 * optimum);
  EXPECT_LT(cv::norm(g300, best, cv::NORM_INF), 1e-3 * cv::norm(best, cv::NORM_INF));
}

// DSST's scale filter learned on one frame finds the target's scale change in the next, taking
// every sample from the frame or (resize_once) from one resized region: the same factor on the
// training frame, and for shrinking and growing targets a change in the right direction within
// two sample steps of the truth (one frame's filter and the Hann window along the scales pull
// large changes towards 1: a tracker gets there over a few frames), the two samplings within a
// step of each other.
TEST(ScaleFilter, FindsTheScaleChangeWithEitherSampling) {
  const test::Scene scene({320, 240}, {72, 48}, 5, 2.0);
  const cv::Point2d centre(150.3, 118.6);
  const cv::Mat first = scene.render({centre});
  const std::vector<double> truths{0.9, 0.95, 1.04, 1.1, 1.16};
  std::vector<double> found[2];
  for (const bool once : {false, true}) {
    ScaleFilterParams p;
    p.resize_once = once;
    ScaleFilter filter(p, scene.target_size());
    filter.learn(first, centre, 1.0, 1.0);
    EXPECT_DOUBLE_EQ(filter.best_change(first, centre, 1.0), 1.0) << "resize_once " << once;
    for (const double truth : truths) {
      Motion m{centre};
      m.scale = truth;
      found[once].push_back(filter.best_change(scene.render(m), centre, 1.0));
      EXPECT_GT((found[once].back() - 1) * (truth - 1), 0) << "resize_once " << once << ", truth " << truth;
      EXPECT_LE(std::abs(std::log(found[once].back() / truth)), 2.01 * std::log(p.step))
          << "resize_once " << once << ", truth " << truth << ", found " << found[once].back();
    }
  }
  for (size_t i = 0; i < truths.size(); ++i)
    EXPECT_LE(std::abs(std::log(found[0][i] / found[1][i])), 1.01 * std::log(1.02)) << "truth " << truths[i];
}

// Over a steady change the scale filter, learning as the trackers do (rate 0.025 after each
// estimate), follows a target shrinking or growing 0.4 % a frame for 160 frames: 33 resizes
// from the frame end within one step (2 %) of the truth; the samples warped from one region
// (resize_once) lag, never lead, by at most three steps (2.4 and 1.3 here): the factor-1 sample is the region's own
// pixels, every other one an interpolation, so the filter leans to "no change"
// (docs/results/track.md, "scale_resize_once damps the scale").
TEST(ScaleFilter, FollowsASteadyChangeAndResizeOnceLagsIt) {
  const test::Scene scene({480, 360}, {90, 180}, 7, 2.0);
  const cv::Point2d centre(240.3, 180.6);
  for (const double rate : {0.996, 1.004}) {
    for (const bool once : {false, true}) {
      ScaleFilterParams p;
      p.resize_once = once;
      ScaleFilter filter(p, scene.target_size());
      Motion m{centre};
      filter.learn(scene.render(m), centre, 1.0, 1.0);
      double scale = 1;
      for (int k = 1; k <= 160; ++k) {
        m.scale = std::pow(rate, k);
        const cv::Mat frame = scene.render(m);
        scale *= filter.best_change(frame, centre, scale);
        filter.learn(frame, centre, scale, 0.025);
      }
      const double steps = std::log(scale / m.scale) / std::log(p.step);  // > 0: larger than the truth
      if (once) {
        EXPECT_GE(steps * (rate < 1 ? 1 : -1), 0.0) << "rate " << rate << ": resize_once leads the change";
        EXPECT_LE(std::abs(steps), 3.0) << "rate " << rate << ", resize_once, scale " << scale;
      } else {
        EXPECT_LE(std::abs(steps), 1.0) << "rate " << rate << ", scale " << scale << ", truth " << m.scale;
      }
    }
  }
}

TEST(Dcf, TheTrainingFrameGivesTheSameBox) {
  const Scene scene({240, 180}, {40, 32});
  Motion m;
  m.centre = {100.3, 80.6};
  DcfTracker t(DcfParams{});
  t.init(scene.render(m), scene.box(m));
  const TrackState s = t.update(scene.render(m));
  EXPECT_NEAR(s.pose.x, m.centre.x, 0.25);
  EXPECT_NEAR(s.pose.y, m.centre.y, 0.25);
  EXPECT_DOUBLE_EQ(s.pose.scale, 1.0);
  EXPECT_NEAR(s.confidence, 1.0, 1e-9);
  ASSERT_EQ(s.levels.size(), 1u);
  EXPECT_GT(s.levels[0].evaluated, 33);  // every cell shift + the 33 scales
}

// 12.8 px per frame over a static textured background, grey frames, window twice the target
// per side: the spatially constrained filter follows; the unconstrained one learns the
// background too and stays with it (why spatial_mask is on by default).
TEST(Dcf, FastMotionOverAStaticBackground) {
  const Scene scene({400, 320}, {40, 32});
  auto worst_error = [&](bool spatial_mask) {
    DcfParams p;
    p.padding = 2.0;
    p.spatial_mask = spatial_mask;
    DcfTracker t(p);
    Motion m;
    m.centre = {80, 90};
    cv::Mat gray;
    cv::cvtColor(scene.render(m), gray, cv::COLOR_BGR2GRAY);
    t.init(gray, scene.box(m));
    double worst = 0;
    for (int i = 1; i < 20; ++i) {
      m.centre += cv::Point2d(10, 8);
      cv::cvtColor(scene.render(m), gray, cv::COLOR_BGR2GRAY);
      const TrackState s = t.update(gray);
      worst = std::max(worst, std::hypot(s.pose.x - m.centre.x, s.pose.y - m.centre.y));
    }
    return worst;
  };
  EXPECT_LT(worst_error(true), 3.0);
  EXPECT_GT(worst_error(false), 50.0);
}

// The target jumps 112 px (beyond the window) after 10 frames: with re-detection the filter is
// searched for in the windows around the last one once the confidence has stayed low, and
// the target is found again; without, the tracker stays behind.
TEST(Dcf, RedetectionAfterAJump) {
  const Scene scene({320, 240}, {40, 32});
  auto run = [&](bool redetection, int* lost, int* redetected) {
    DcfParams p;
    p.redetection = redetection;
    DcfTracker t(p);
    Motion m;
    m.centre = {80, 90};
    t.init(scene.render(m), scene.box(m));
    double error = 0;
    for (int i = 1; i < 30; ++i) {
      m.centre += cv::Point2d(1, 0.5);
      if (i == 10) m.centre += cv::Point2d(100, 50);
      const TrackState s = t.update(scene.render(m));
      *lost += s.lost;
      *redetected += s.redetected;
      error = std::hypot(s.pose.x - m.centre.x, s.pose.y - m.centre.y);
    }
    return error;
  };
  int lost = 0, redetected = 0;
  EXPECT_LT(run(true, &lost, &redetected), 4.0);
  EXPECT_GE(lost, 3);
  EXPECT_EQ(redetected, 1);
  lost = redetected = 0;
  EXPECT_GT(run(false, &lost, &redetected), 100.0);
  EXPECT_EQ(redetected, 0);
}

TEST(Dcf, BadParametersAreNamed) {
  auto message = [](auto change) { return test::rejection<DcfTracker, DcfParams>(change); };
  EXPECT_NE(message([](DcfParams& p) { p.hist_bins = 30; }).find("hist_bins"), std::string::npos);
  EXPECT_NE(message([](DcfParams& p) { p.learning_rate = 0; }).find("learning rates"), std::string::npos);
  EXPECT_NE(message([](DcfParams& p) { p.padding = NAN; }).find("padding"), std::string::npos);
  EXPECT_NE(message([](DcfParams& p) { p.min_scale = 2, p.max_scale = 1; }).find("min_scale"), std::string::npos);
}
