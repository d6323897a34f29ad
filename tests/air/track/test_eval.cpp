// OTB one-pass metrics and the sequence reader.
#include <gtest/gtest.h>

#include <fstream>

#include "air/track/eval/metrics.hpp"
#include "air/track/eval/sequence.hpp"
#include "tests/support/test_support.hpp"

using namespace aerie::track::eval;

TEST(Metrics, IouAndCentreErrorByHand) {
  EXPECT_DOUBLE_EQ(iou({0, 0, 10, 10}, {5, 0, 10, 10}), 50.0 / 150.0);
  EXPECT_DOUBLE_EQ(iou({0, 0, 10, 10}, {20, 20, 5, 5}), 0.0);
  EXPECT_DOUBLE_EQ(iou({0, 0, 10, 10}, {0, 0, 10, 10}), 1.0);
  EXPECT_DOUBLE_EQ(centre_error({0, 0, 10, 10}, {3, 4, 10, 10}), 5.0);
}

TEST(Metrics, SuccessAucPrecisionAndMeanErrorByHand) {
  // four frames: IoU 1, 1/3 (shift 5 of 10), 0 (far), and an invalid ground truth (skipped)
  const std::vector<cv::Rect2d> gt = {{0, 0, 10, 10}, {0, 0, 10, 10}, {0, 0, 10, 10}, {0, 0, 0, 0}};
  const std::vector<cv::Rect2d> pr = {{0, 0, 10, 10}, {5, 0, 10, 10}, {100, 0, 10, 10}, {0, 0, 10, 10}};
  const Score s = score(pr, gt);
  EXPECT_EQ(s.frames, 3);
  ASSERT_EQ(s.success.size(), 21u);
  EXPECT_DOUBLE_EQ(s.success[0], 2.0 / 3);   // IoU > 0
  EXPECT_DOUBLE_EQ(s.success[6], 2.0 / 3);   // > 0.30: 1 and 0.333
  EXPECT_DOUBLE_EQ(s.success[7], 1.0 / 3);   // > 0.35
  EXPECT_DOUBLE_EQ(s.success[20], 0.0);      // > 1: never
  // AUC = mean over the 21 thresholds: 7 thresholds (0..0.30) at 2/3, 13 (0.35..0.95) at 1/3
  EXPECT_NEAR(s.auc, (7 * 2.0 / 3 + 13 * 1.0 / 3) / 21, 1e-12);
  EXPECT_DOUBLE_EQ(s.precision20, 2.0 / 3);  // errors 0, 5, 100
  EXPECT_DOUBLE_EQ(s.mean_centre_error, 35.0);
  EXPECT_THROW(score({{0, 0, 1, 1}}, gt), std::invalid_argument);
}

TEST(Sequence, BoxesRoundTripAndBadFilesNameTheLine) {
  const auto dir = aerie::test::scratch_dir("boxes");
  const std::vector<cv::Rect2d> boxes = {{1.5, 2, 30, 40.25}, {0, 0, 10, 10}};
  write_boxes(dir / "a.txt", boxes);
  EXPECT_EQ(read_boxes(dir / "a.txt"), boxes);
  std::ofstream(dir / "tabs.txt") << "1\t2\t3\t4\nNaN,NaN,NaN,NaN\n";
  const auto t = read_boxes(dir / "tabs.txt");
  ASSERT_EQ(t.size(), 2u);
  EXPECT_FALSE(is_valid_box(t[1]));
  std::ofstream(dir / "bad.txt") << "1,2,3,4\n1,2,x,4\n";
  try {
    read_boxes(dir / "bad.txt");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.txt:2"), std::string::npos) << e.what();
  }
}

TEST(Sequence, FindsOtbFoldersAndChecksCounts) {
  const auto dir = aerie::test::scratch_dir("data");
  std::filesystem::create_directories(dir / "A" / "img");
  std::filesystem::create_directories(dir / "notaseq");
  for (int i = 1; i <= 3; ++i) std::ofstream(dir / "A" / "img" / ("000" + std::to_string(i) + ".jpg")) << "x";
  std::ofstream(dir / "A" / "groundtruth.txt") << "1,2,3,4\n1,2,3,4\n";
  EXPECT_THROW(find_sequences(dir), std::runtime_error);  // 3 frames, 2 boxes
  std::ofstream(dir / "A" / "groundtruth.txt", std::ios::app) << "1,2,3,4\n";
  const auto seqs = find_sequences(dir);
  ASSERT_EQ(seqs.size(), 1u);
  EXPECT_EQ(seqs[0].name, "A");
  EXPECT_EQ(seqs[0].frames.back().filename(), "0003.jpg");
}

TEST(Sequence, SharedGirlSequence) {
  AERIE_REQUIRE_DATA("tracking/Girl");
  const Sequence s = load_sequence(aerie::test::shared_data("tracking/Girl"));
  EXPECT_EQ(s.frames.size(), 500u);
  EXPECT_EQ(s.groundtruth[0], cv::Rect2d(57, 21, 31, 45));
}
