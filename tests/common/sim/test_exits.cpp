// Exit-and-return sequences: out-of-view frames are exactly those the geometry says, the first
// frame shows the whole aircraft, every exit keeps it out for its drawn span, determinism.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "common/sim/exits.hpp"

namespace aerie::sim {
namespace {

// 160x120, short spans.
ExitsConfig small() {
  ExitsConfig c;
  c.look.width = 160;
  c.look.height = 120;
  c.look.wingspan_px = 24;
  c.in_frames_min = 3;
  c.in_frames_max = 6;
  c.out_frames_min = c.in_frames_min + 1;
  c.out_frames_max = 2 * c.out_frames_min;
  c.pan_speed_px = 20;
  c.drift_speed_px = 4;
  return c;
}

TEST(SimExits, OutOfViewIsWhatTheGeometrySays) {
  for (uint64_t seed : {1, 2, 3}) {
    ExitsConfig cfg = small();
    cfg.look.seed = seed;
    cfg.exits = 4;
    const ExitsScene scene(cfg);
    const ExitsFrame first = scene.frame(0);
    EXPECT_DOUBLE_EQ(first.visible_fraction, 1.0);
    EXPECT_TRUE(first.mono.target_visible);
    EXPECT_TRUE(first.in_view);
    int spans = 0, run = 0;
    std::string kinds;
    for (int k = 0; k < scene.frame_count(); ++k) {
      const ExitsFrame f = scene.frame(k);
      ASSERT_EQ(f.mono.image.size(), cv::Size(160, 120));
      // The visible part of the box, from its clipped area minus the mast's share.
      const cv::Rect2d b = f.mono.target_box, in = b & cv::Rect2d(0, 0, 160, 120);
      const double hidden = f.occluder.area() > 0 ? (in & f.occluder).area() : 0.0;
      const double fraction = (in.area() - hidden) / b.area();
      EXPECT_NEAR(f.visible_fraction, fraction, 1e-9) << "seed " << seed << " frame " << k;
      EXPECT_EQ(f.in_view, fraction >= cfg.min_visible) << "seed " << seed << " frame " << k;
      if (!f.in_view) {
        EXPECT_NE(f.event, "none") << "out of view between exits, frame " << k;
        if (run++ == 0) kinds += f.event + " ";
      } else if (run > 0) {
        EXPECT_GE(run, cfg.out_frames_min) << "seed " << seed << " span ending at " << k;
        ++spans;
        run = 0;
      }
    }
    EXPECT_EQ(run, 0) << "the sequence ends in view";
    EXPECT_EQ(spans, cfg.exits) << kinds;  // one out-of-view span an exit
  }
}

TEST(SimExits, EveryKindAndTheMast) {
  ExitsConfig cfg = small();
  cfg.exits = 3;
  const ExitsScene scene(cfg);
  bool seen[3] = {false, false, false}, occluded = false;
  for (int k = 0; k < scene.frame_count(); ++k) {
    const ExitsFrame f = scene.frame(k);
    for (int i = 0; i < 3; ++i) seen[i] |= f.event == cfg.kinds[i];
    // Hidden by the mast while inside the image.
    const cv::Rect2d box = f.mono.target_box;
    occluded |= !f.in_view && (box & cv::Rect2d(0, 0, 160, 120)).area() >= 0.99 * box.area();
    if (f.occluder.area() > 0) {
      EXPECT_EQ(f.event, "occlusion");
    }
  }
  EXPECT_TRUE(seen[0] && seen[1] && seen[2]);
  EXPECT_TRUE(occluded);
}

TEST(SimExits, Deterministic) {
  ExitsConfig cfg = small();
  cfg.look.color = true;
  const ExitsScene a(cfg), b(cfg);
  ASSERT_EQ(a.frame_count(), b.frame_count());
  for (int k = 0; k < a.frame_count(); k += 5) {
    const ExitsFrame fa = a.frame(k), fb = b.frame(k);
    ASSERT_EQ(fa.mono.image.type(), CV_8UC3);
    EXPECT_EQ(cv::norm(fa.mono.image, fb.mono.image, cv::NORM_INF), 0.0);
    EXPECT_EQ(fa.mono.target_box, fb.mono.target_box);
  }
  cfg.look.seed = 2;
  const ExitsScene c(cfg);
  EXPECT_GT(cv::norm(a.frame(3).mono.image, c.frame(3).mono.image, cv::NORM_L1) / (160 * 120 * 3), 2.0);
}

TEST(SimExits, BadSizesAreRefused) {
  ExitsConfig bad = small();
  bad.look.wingspan_px = 60;  // no room to wander and pass behind the mast
  EXPECT_THROW(ExitsScene{bad}, std::invalid_argument);
  bad = small();
  bad.kinds = {"pan", "teleport"};
  EXPECT_THROW(ExitsScene{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace aerie::sim
