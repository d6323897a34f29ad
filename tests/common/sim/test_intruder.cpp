// Intruder-aircraft scene: the ground-truth box is the aircraft, determinism, motion.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "common/sim/intruder.hpp"

namespace aerie::sim {
namespace {

TEST(SimIntruder, BoxIsTheSilhouette) {
  IntruderConfig cfg;
  cfg.frames = 60;
  cfg.noise_sigma = 0;
  IntruderConfig bg_cfg = cfg;
  bg_cfg.draw_target = false;
  const IntruderScene scene(cfg), background(bg_cfg);
  for (int k = 0; k < cfg.frames; k += 7) {
    const MonoFrame f = scene.frame(k), b = background.frame(k);
    ASSERT_EQ(f.image.size(), cv::Size(640, 480));
    ASSERT_EQ(f.image.type(), CV_8UC1);
    EXPECT_TRUE(f.target_visible);
    cv::Mat diff;
    cv::absdiff(f.image, b.image, diff);
    const cv::Rect changed = cv::boundingRect(diff > 3);
    // Every changed pixel (centres on integers) lies within 1 px (bilinear resampling) of
    // the box, and the box is tight.
    const cv::Rect2d box = f.target_box;
    EXPECT_GE(changed.x, box.x - 1.0);
    EXPECT_GE(changed.y, box.y - 1.0);
    EXPECT_LE(changed.x + changed.width - 1, box.x + box.width + 1.0);
    EXPECT_LE(changed.y + changed.height - 1, box.y + box.height + 1.0);
    EXPECT_GT(changed.area(), 0.85 * box.area()) << "frame " << k;
    EXPECT_TRUE(box.contains(f.target_center));
  }
}

TEST(SimIntruder, MotionScaleAndVibration) {
  IntruderConfig cfg;
  cfg.frames = 100;
  IntruderScene scene(cfg);
  MonoFrame f;
  std::vector<MonoFrame> frames;
  while (scene.next(f)) frames.push_back(f);
  ASSERT_EQ(frames.size(), 100u);
  EXPECT_EQ(frames[10].utime, 500'000);
  EXPECT_NEAR(frames.back().target_scale / frames.front().target_scale, cfg.scale_change, 1e-9);
  // Crosses a good part of the image.
  EXPECT_GT(std::abs(frames.back().target_center.x - frames.front().target_center.x), 0.4 * cfg.width);
  // The whole image vibrates: the background moves between frames.
  IntruderConfig bg = cfg;
  bg.draw_target = false;
  bg.noise_sigma = 0;
  const IntruderScene still(bg);
  EXPECT_GT(cv::norm(still.frame(0).image, still.frame(1).image, cv::NORM_L1) / (640.0 * 480.0), 0.2);
  bg.vibration_px = 0;
  const IntruderScene steady(bg);
  EXPECT_EQ(cv::norm(steady.frame(0).image, steady.frame(1).image, cv::NORM_INF), 0.0);
}

TEST(SimIntruder, Deterministic) {
  IntruderConfig cfg;
  cfg.frames = 10;
  const MonoFrame a = IntruderScene(cfg).frame(9), b = IntruderScene(cfg).frame(9);
  EXPECT_EQ(cv::norm(a.image, b.image, cv::NORM_INF), 0.0);
  EXPECT_EQ(a.target_box, b.target_box);
  cfg.seed = 3;
  const MonoFrame c = IntruderScene(cfg).frame(9);
  EXPECT_GT(cv::norm(a.image, c.image, cv::NORM_L1) / a.image.total(), 2.0);
  cfg.color = true;
  EXPECT_EQ(IntruderScene(cfg).frame(0).image.type(), CV_8UC3);
  cfg.frames = 0;
  EXPECT_THROW(IntruderScene{cfg}, std::invalid_argument);
}

}  // namespace
}  // namespace aerie::sim
