#include <gtest/gtest.h>

#include "air/track/pyramid/pyramid.hpp"
#include "air/track/tracker.hpp"

using namespace aerie::track;

// Table 3.1: test samples are the integer offsets strictly inside the search radius.
TEST(Pyramid, SampleCountsOfTable31) {
  const std::pair<double, size_t> expected[] = {{5, 69}, {6, 109}, {8, 193}, {10, 305}, {20, 1245}, {30, 2809}};
  for (auto [r, n] : expected) EXPECT_EQ(pyramid::offsets_within(r).size(), n) << "radius " << r;
}

TEST(Pyramid, LevelCountRejectionAndRanges) {
  EXPECT_EQ(pyramid::num_levels(64, 48, 12), 2);  // floor(log2(4)) = 2
  EXPECT_EQ(pyramid::num_levels(100, 100, 12), 3);
  EXPECT_EQ(pyramid::num_levels(10, 10, 12), 1);
  EXPECT_EQ(pyramid::num_rejected(0.8, 2, 100), 64);
  EXPECT_DOUBLE_EQ(pyramid::next_search_range(3.5), 7.0);
  EXPECT_EQ(pyramid::next_block_size(10, 3), 5);  // floor(10 / log2(4))
}

TEST(TrackState, CornersAndBox) {
  TrackState s;
  s.pose = {50, 40, 2.0, M_PI / 2};
  s.initial_size = {10, 4};
  const auto c = s.corners();
  // rotated by 90 degrees: the 20-wide box now spans 20 pixels in y
  EXPECT_NEAR(c[0].x, 54, 1e-9);
  EXPECT_NEAR(c[0].y, 30, 1e-9);
  EXPECT_EQ(s.box(), cv::Rect2d(40, 36, 20, 8));
}

TEST(Tracker, ValidateInitRejectsBadInput) {
  const cv::Mat frame(100, 120, CV_8UC1, cv::Scalar(0));
  EXPECT_NO_THROW(validate_init(frame, {10, 10, 20, 20}));
  EXPECT_THROW(validate_init(cv::Mat(), {10, 10, 20, 20}), std::invalid_argument);
  EXPECT_THROW(validate_init(frame, {10, 10, 0, 20}), std::invalid_argument);
  EXPECT_THROW(validate_init(frame, {110, 10, 20, 20}), std::invalid_argument);
  EXPECT_THROW(validate_init(frame, {NAN, 10, 20, 20}), std::invalid_argument);
  EXPECT_THROW(validate_init(cv::Mat(10, 10, CV_32F), {1, 1, 5, 5}), std::invalid_argument);
}
