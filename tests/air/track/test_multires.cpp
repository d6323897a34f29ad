// The multi-resolution framework (eqs. 3.23-3.26) with a classifier whose scores are known:
// sample counts of the thesis' 3-level example (radii 5/6/8 -> 371 samples) against one
// full-resolution radius 20 (1245 samples), and the location propagation.
#include <gtest/gtest.h>

#include "air/track/pyramid/discriminative.hpp"

using namespace aerie::track;

namespace {

// Scores every sample by minus its squared centre distance to a fixed point (full-res pixels).
class PeakClassifier : public SampleClassifier {
 public:
  PeakClassifier(cv::Size t, int level, const cv::Point2d* peak) : t_(t), level_(level), peak_(peak) {}
  cv::Size footprint(double s) const override {
    return {static_cast<int>(std::lround(t_.width * s)), static_cast<int>(std::lround(t_.height * s))};
  }
  void score(const ChannelImages&, const SampleSet& samples, double s, std::vector<float>& out) override {
    out.clear();
    const cv::Point2d peak = *peak_ * (1.0 / (1 << level_));
    for (const auto& p : samples.positions()) {
      const cv::Point2d c(p.x + t_.width * s / 2, p.y + t_.height * s / 2);
      out.push_back(static_cast<float>(-(c - peak).dot(c - peak)));
    }
  }
  void update(const ChannelImages&, const SampleSet&, const SampleSet&, double) override { ++updates; }
  int terms() const override { return 1; }
  std::unique_ptr<SampleClassifier> clone() const override { return std::make_unique<PeakClassifier>(*this); }
  int updates = 0;

 private:
  cv::Size t_;
  int level_;
  const cv::Point2d* peak_;
};

ClassifierFactory peak_factory(const cv::Point2d* peak) {
  auto level = std::make_shared<int>(0);
  return [peak, level](cv::Size t, const std::vector<int>&, Rng&) -> std::unique_ptr<SampleClassifier> {
    // levels are made finest first after every init
    const int p = t.width >= 64 ? 0 : t.width >= 32 ? 1 : 2;
    *level = p;
    return std::make_unique<PeakClassifier>(t, p, peak);
  };
}

DiscriminativeParams exact_params(int levels) {
  DiscriminativeParams p;
  p.max_levels = levels;
  p.min_size = 8;
  p.search_radius = 20;  // one level
  p.coarse_radius = 5;   // the coarsest of several
  p.scale_estimation = "none";
  p.redetection = false;
  // xi^1, xi^2 chosen so that the critical samples lie at distance 4 (level 1) and 3 (level 2)
  p.reject_ratio = {0.59, 0.64};
  return p;
}

}  // namespace

TEST(MultiResolution, ThreeLevelsEvaluate371SamplesWhereOneLevelNeeds1245) {
  const cv::Mat frame(400, 400, CV_8UC1, cv::Scalar(0));
  const cv::Rect2d box(160, 160, 64, 64);  // centre (192, 192); templates 64, 32, 16 (eq. 3.23: 3 levels)
  cv::Point2d peak(192, 192);

  DiscriminativeTracker hierarchical("test", exact_params(3), peak_factory(&peak), 1);
  hierarchical.init(frame, box);
  ASSERT_EQ(hierarchical.levels(), 3);
  const TrackState s = hierarchical.update(frame);
  ASSERT_EQ(s.levels.size(), 3u);
  // coarsest first: radius 5 -> 69 samples; 44 rejected (floor(0.64 * 69)), the best
  // of them at distance 3 -> radius 6 -> 109 samples; 64 rejected, critical distance 4 -> radius 8.
  EXPECT_EQ(s.levels[0].level, 2);
  EXPECT_EQ(s.levels[0].evaluated, 69);
  EXPECT_EQ(s.levels[0].rejected, 44);
  EXPECT_FLOAT_EQ(s.levels[0].search_radius, 5);
  EXPECT_EQ(s.levels[1].evaluated, 109);
  EXPECT_EQ(s.levels[1].rejected, 64);
  EXPECT_FLOAT_EQ(s.levels[1].search_radius, 6);
  EXPECT_EQ(s.levels[2].evaluated, 193);
  EXPECT_FLOAT_EQ(s.levels[2].search_radius, 8);
  EXPECT_EQ(s.samples_evaluated(), 371);  // the thesis' count (Fig. 3.35)
  EXPECT_NEAR(s.pose.x, 192, 1e-9);
  EXPECT_NEAR(s.pose.y, 192, 1e-9);

  DiscriminativeTracker single("test", exact_params(1), peak_factory(&peak), 1);
  single.init(frame, box);
  ASSERT_EQ(single.levels(), 1);
  EXPECT_EQ(single.update(frame).samples_evaluated(), 1245);  // Table 3.1, radius 20
}

TEST(MultiResolution, LocationPropagatesFromTheCoarsestLevel) {
  const cv::Mat frame(400, 400, CV_8UC1, cv::Scalar(0));
  cv::Point2d peak(192, 192);
  DiscriminativeTracker t("test", exact_params(3), peak_factory(&peak), 1);
  t.init(frame, {160, 160, 64, 64});
  // a jump of (17, -13) pixels: inside the coarsest radius (5 at level 2 = 20 at level 0),
  // outside the finest level's radius: only the propagation 2 l^p (eq. 3.24) can reach it
  peak = {192 + 17, 192 - 13};
  const TrackState s = t.update(frame);
  EXPECT_NEAR(s.pose.x, peak.x, 1e-9);
  EXPECT_NEAR(s.pose.y, peak.y, 1e-9);
  // every level's sample positions are reported in full-resolution pixels, inside its radius
  // around its best sample (the peak, within two of the level's pixels: (4, -3) is on the coarsest radius)
  for (const auto& l : s.levels) {
    const double px = 1 << l.level;
    const size_t best = std::max_element(l.scores.begin(), l.scores.end()) - l.scores.begin();
    EXPECT_LE(cv::norm(cv::Point2d(l.samples[best]) - peak), 2 * px);
    for (const auto& q : l.samples) EXPECT_LT(cv::norm(q - l.samples[best]), 2 * l.search_radius * px + 1e-6);
  }
}
