// aerie-eval-track: a box file scored against a ground truth with the benchmark's metric code:
// boxes equal to the ground truth give the exact maximum, a shifted file its value by hand, NaN
// rows count as failures, files of different lengths are refused; and the command's interface.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <fstream>

#include "air/track/eval/box_file_score.hpp"
#include "air/track/eval/sequence.hpp"
#include "tests/support/test_support.hpp"

using namespace aerie::track::eval;
namespace fs = std::filesystem;

namespace {

// 10 frames of a 40 x 20 box moving right; frame 4 has no ground truth (out of view).
std::vector<cv::Rect2d> truth() {
  std::vector<cv::Rect2d> gt;
  for (int i = 0; i < 10; ++i) gt.emplace_back(100 + 3 * i, 50, 40, 20);
  gt[4] = cv::Rect2d(NAN, NAN, NAN, NAN);
  return gt;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

}  // namespace

TEST(EvalTrack, EqualBoxesGiveTheMaximumAndShiftedBoxesTheirValue) {
  const auto dir = aerie::test::scratch_dir("score");
  const auto gt = dir / "groundtruth.txt";
  write_boxes(gt, truth());

  // Equal: IoU 1 > every threshold but the last (IoU > 1 never holds): AUC 20/21.
  const auto same = score_box_file(gt, gt);
  EXPECT_EQ(same.rows, 10);
  EXPECT_EQ(same.score.frames, 9);
  EXPECT_EQ(same.missing, 0);
  EXPECT_DOUBLE_EQ(same.score.auc, 20.0 / 21.0);
  EXPECT_DOUBLE_EQ(same.score.precision20, 1.0);
  EXPECT_DOUBLE_EQ(same.score.mean_centre_error, 0.0);

  // Shifted 8 px right: overlap 32 x 20 = 640, union 960, IoU 2/3 > thresholds 0 ... 0.65 (14 of
  // 21); centre error 8 px.
  auto shifted = truth();
  for (auto& b : shifted) b.x += 8;
  write_boxes(dir / "shifted.txt", shifted);
  const auto s = score_box_file(dir / "shifted.txt", gt);
  EXPECT_NEAR(s.score.auc, 14.0 / 21.0, 1e-12);
  EXPECT_DOUBLE_EQ(s.score.precision20, 1.0);
  EXPECT_NEAR(s.score.mean_centre_error, 8.0, 1e-9);

  // Two frames the tracker skipped (NaN rows): failures, IoU 0 and the diagonal as error.
  auto skipped = truth();
  skipped[2] = skipped[6] = cv::Rect2d(NAN, NAN, NAN, NAN);
  write_boxes(dir / "skipped.txt", skipped);
  const auto k = score_box_file(dir / "skipped.txt", gt);
  EXPECT_EQ(k.missing, 2);
  EXPECT_NEAR(k.score.auc, 7.0 / 9.0 * 20.0 / 21.0, 1e-12);
  EXPECT_NEAR(k.score.precision20, 7.0 / 9.0, 1e-12);
  EXPECT_NEAR(k.score.mean_centre_error, 2.0 * std::hypot(40.0, 20.0) / 9.0, 1e-9);

  // The skipped frames dropped instead: every box after them shifts, so it is refused.
  auto dropped = truth();
  dropped.erase(dropped.begin() + 2);
  write_boxes(dir / "dropped.txt", dropped);
  const std::string e = aerie::test::refusal(
      [&](const std::string& p) { score_box_file(p, gt); }, (dir / "dropped.txt").string());
  EXPECT_NE(e.find("dropped.txt: 9 boxes for 10 frames in " + gt.string()), std::string::npos) << e;
  EXPECT_NE(e.find("one row per frame"), std::string::npos) << e;

  const std::string json = to_json(s);
  EXPECT_NE(json.find("\"rows\": 10, \"frames\": 9, \"missing\": 0"), std::string::npos) << json;
  EXPECT_NE(json.find("\"precision_20px\": 1,"), std::string::npos) << json;
}

TEST(EvalTrack, TheCommand) {
  const auto dir = aerie::test::scratch_dir("cmd");
  write_boxes(dir / "gt.txt", truth());
  auto shifted = truth();
  for (auto& b : shifted) b.x += 8;
  write_boxes(dir / "boxes.txt", shifted);
  const auto bin = (aerie::test::binary_dir() / "bin" / "aerie-eval-track").string();
  auto run = [&](const std::string& args) {
    const std::string cmd = bin + " " + args + " > " + (dir / "out.txt").string() + " 2> " + (dir / "err.txt").string();
    const int rc = std::system(cmd.c_str());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  };
  ASSERT_EQ(run((dir / "boxes.txt").string() + " " + (dir / "gt.txt").string() + " --json " +
                (dir / "s.json").string()),
            0);
  const std::string out = slurp(dir / "out.txt");
  EXPECT_NE(out.find("success AUC        0.6667\n"), std::string::npos) << out;
  EXPECT_NE(out.find("precision @ 20 px  1.0000\n"), std::string::npos) << out;
  EXPECT_NE(out.find("mean CLE           8.00 px\n"), std::string::npos) << out;
  EXPECT_NE(slurp(dir / "s.json").find("\"success_auc\": 0.666666"), std::string::npos);

  EXPECT_EQ(run("--help"), 0);
  EXPECT_NE(slurp(dir / "out.txt").find("Score a tracker's box file against a ground truth"), std::string::npos);
  EXPECT_EQ(run((dir / "boxes.txt").string() + " " + (dir / "gt.txt").string() + " --bogus"), 2);
  EXPECT_EQ(run((dir / "boxes.txt").string()), 2);
  write_boxes(dir / "short.txt", {cv::Rect2d(1, 2, 3, 4)});
  EXPECT_EQ(run((dir / "short.txt").string() + " " + (dir / "gt.txt").string()), 1);
  EXPECT_NE(slurp(dir / "err.txt").find("short.txt: 1 boxes for 10 frames"), std::string::npos)
      << slurp(dir / "err.txt");
}
