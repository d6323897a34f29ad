// Metric pose of the helipad from its corners (IPPE) against the simulator's ground truth.
#include <gtest/gtest.h>

#include "air/track/landing/pad_pose.hpp"
#include "tests/air/track/pad_views.hpp"

using namespace aerie::track;
using aerie::track::test::grown;
using aerie::track::test::pad_view;
using aerie::track::test::PadView;
using aerie::track::test::wrap_half_turn;

namespace {

const aerie::sim::World& world() {
  static const aerie::sim::World w = aerie::sim::World::room({});
  return w;
}

aerie::sim::StereoRenderer renderer(double noise_sigma = 2.0) {
  aerie::sim::RigConfig rig = aerie::sim::landing_rig();
  rig.noise_sigma = noise_sigma;
  return {world(), rig};
}

double yaw_error_deg(double a, double b) { return std::abs(wrap_half_turn(a - b)) * 180 / M_PI; }

// The H's bounding rectangle (0.38 x 0.48 of the pad's side) is in the image, `margin` px clear.
bool h_inside(const PadView& v, double size, double margin) {
  for (const double x : {-0.19, 0.19})
    for (const double y : {-0.24, 0.24}) {
      const cv::Point2d p = v.pixel(x * size, y * size);
      if (p.x < margin || p.y < margin || p.x > v.camera.width - 1 - margin || p.y > v.camera.height - 1 - margin) return false;
    }
  return true;
}

// The pad is seen whole, `margin` pixels clear of the image border.
bool inside(const PadView& v, double margin) {
  const auto& b = v.frame.target_box;
  return v.frame.target_visible && b.x >= margin && b.y >= margin && b.br().x <= v.camera.width - 1 - margin &&
         b.br().y <= v.camera.height - 1 - margin;
}

struct Errors {
  double position = 0, yaw = 0;
  int n = 0;
  void add(const PadView& v, const PadObservation& o) {
    position = std::max(position, (o.position - v.position).norm());
    yaw = std::max(yaw, yaw_error_deg(o.yaw, v.yaw));
    ++n;
  }
};

}  // namespace

// Heights 0.8 .. 3 m, the pad turned 0 .. 170 deg in the image, the vehicle tilted up to 10 deg,
// image noise sigma 2; the search window is the true box grown by 30 % and off-centre.
TEST(PadPose, AccurateOverHeightsYawsAndTilts) {
  const auto r = renderer();
  const double tilts[][2] = {{0, 0}, {10, 0}, {0, -10}, {7, 7}, {-7, 5}};  // roll, pitch (deg)
  const PadGeometry pad{world().helipad().size};
  Errors err;
  int k = 0, skipped = 0;
  for (double height : {0.8, 1.2, 1.8, 2.4, 3.0})
    for (int heading = 0; heading < 180; heading += 10, ++k) {
      const auto& tilt = tilts[k % 5];
      const PadView v = pad_view(r, height, heading, tilt[0], tilt[1], {0.04, -0.03}, k);
      if (!inside(v, 3)) {  // at 0.8 m the turned pad does not fit in 240 rows
        ++skipped;
        continue;
      }
      PadMiss miss = PadMiss::None;
      const auto o = observe_pad(v.frame.left, grown(v.frame.target_box, 0.3, {5, -4}), v.camera, pad, {}, &miss);
      ASSERT_TRUE(o) << "height " << height << " heading " << heading << ": " << to_string(miss);
      EXPECT_LT((o->position - v.position).norm(), 0.02) << "height " << height << " heading " << heading;
      EXPECT_LT(yaw_error_deg(o->yaw, v.yaw), 2.0) << "height " << height << " heading " << heading;
      EXPECT_LT(o->reprojection_rms, 1.0);
      // The box of the dark square's corners: the true box (outer corners) less the border.
      EXPECT_NEAR(o->box.x, v.frame.target_box.x, 0.05 * v.frame.target_box.width);
      EXPECT_NEAR(o->box.width, v.frame.target_box.width, 0.08 * v.frame.target_box.width);
      err.add(v, *o);
    }
  RecordProperty("max_position_error_m", std::to_string(err.position));
  RecordProperty("max_yaw_error_deg", std::to_string(err.yaw));
  std::printf("%d views (%d skipped: pad cut): max position error %.4f m, max yaw error %.3f deg\n", err.n, skipped,
              err.position, err.yaw);
  EXPECT_GE(err.n, 70);
}

// Heavier noise and motion blur (1 m/s over the 10 ms exposure), and a window three times
// the pad (the pad fills a ninth of it, among floor texture).
TEST(PadPose, NoiseBlurAndALargeWindow) {
  const auto r = renderer(5.0);
  const PadGeometry pad{world().helipad().size};
  Errors err;
  for (int k = 0; k < 6; ++k) {
    const PadView v = pad_view(r, 1.5 + 0.2 * k, 30 * k, 5, -5, {0.1, 0.05}, k, Eigen::Vector3d(1.0, 0.5, 0));
    ASSERT_TRUE(inside(v, 3));
    const auto o = observe_pad(v.frame.left, grown(v.frame.target_box, 1.0), v.camera, pad);
    ASSERT_TRUE(o) << "view " << k;
    err.add(v, *o);
  }
  std::printf("noise + blur: max position error %.4f m, max yaw error %.3f deg\n", err.position, err.yaw);
  EXPECT_LT(err.position, 0.02);
  EXPECT_LT(err.yaw, 2.0);
}

TEST(PadPose, NothingWhereThereIsNoPad) {
  const auto r = renderer();
  const PadGeometry pad{world().helipad().size};
  // Looking at the floor 2.5 m beside the pad, and at the floor beside the pad in its own view.
  const PadView away = pad_view(r, 2.0, 20, 0, 0, {2.5, 0.0});
  ASSERT_FALSE(away.frame.target_box.area() > 0 && inside(away, 0));
  PadMiss miss = PadMiss::None;
  EXPECT_FALSE(observe_pad(away.frame.left, {100, 50, 150, 140}, away.camera, pad, {}, &miss));
  EXPECT_NE(miss, PadMiss::None);
  const PadView v = pad_view(r, 3.0, 0, 0, 0);
  ASSERT_TRUE(inside(v, 3));
  const auto& b = v.frame.target_box;
  const cv::Rect2d beside = b.x > 150 ? cv::Rect2d(0, 0, b.x - 5, 240) : cv::Rect2d(b.br().x + 5, 0, 370 - b.br().x, 240);
  EXPECT_FALSE(observe_pad(v.frame.left, beside, v.camera, pad, {}, &miss));
  EXPECT_NE(miss, PadMiss::None);
  EXPECT_FALSE(observe_pad(v.frame.left, {10, 10, 5, 5}, v.camera, pad, {}, &miss));  // too small to hold one
  EXPECT_EQ(miss, PadMiss::EmptyWindow);
}

TEST(PadPose, PartlyVisiblePadIsRejected) {
  const auto r = renderer();
  const PadGeometry pad{world().helipad().size};
  for (const Eigen::Vector2d& aim : {Eigen::Vector2d(0.9, 0.0), Eigen::Vector2d(0.0, 1.5), Eigen::Vector2d(-0.8, -1.3)}) {
    const PadView v = pad_view(r, 1.5, 0, 0, 0, aim);
    ASSERT_FALSE(v.frame.target_visible) << "the pad should be cut by the image border";
    // The tracker's box: the visible part of the pad.
    const cv::Rect2d box = v.frame.target_box & cv::Rect2d(0, 0, v.camera.width, v.camera.height);
    ASSERT_GT(box.area(), 400);
    PadMiss miss = PadMiss::None;
    EXPECT_FALSE(observe_pad(v.frame.left, grown(box, 0.3), v.camera, pad, {}, &miss));
    EXPECT_EQ(miss, PadMiss::TouchesBorder) << to_string(miss);
  }
}

// The H alone, low over the pad (0.4 .. 1.2 m: the dark square cut by the image border in most
// views), turned, tilted and off-centre as above; the search window is the whole image.
TEST(PadPose, MarkingOnlyLowOverThePad) {
  const auto r = renderer();
  const double tilts[][2] = {{0, 0}, {8, 0}, {0, -8}, {5, 5}, {-5, 4}};
  const PadGeometry pad{world().helipad().size};
  Errors err;
  int k = 0, cut = 0, h_cut = 0;
  for (double height : {0.4, 0.6, 0.8, 1.0, 1.2})
    for (int heading = 0; heading < 180; heading += 15, ++k) {
      const auto& tilt = tilts[k % 5];
      const PadView v = pad_view(r, height, heading, tilt[0], tilt[1], {0.03 * (k % 3 - 1), -0.02 * (k % 2)}, k);
      if (!h_inside(v, pad.size, 16)) {  // low and turned: the H itself does not fit in 240 rows
        ++h_cut;
        continue;
      }
      if (!inside(v, 3)) ++cut;
      PadMiss miss = PadMiss::None;
      const auto o = observe_marking(v.frame.left, {0, 0, 376, 240}, v.camera, pad, {}, &miss);
      ASSERT_TRUE(o) << "height " << height << " heading " << heading << ": " << to_string(miss);
      EXPECT_TRUE(o->marking_only);
      EXPECT_LT((o->position - v.position).norm(), 0.015) << "height " << height << " heading " << heading;
      EXPECT_LT(yaw_error_deg(o->yaw, v.yaw), 2.0) << "height " << height << " heading " << heading;
      EXPECT_LT(o->reprojection_rms, 1.0);
      err.add(v, *o);
    }
  std::printf("%d views (%d with the pad cut, %d skipped: the H cut): max position error %.4f m, max yaw error %.3f deg\n",
              err.n, cut, h_cut, err.position, err.yaw);
  EXPECT_GE(err.n, 45);
  EXPECT_GE(cut, 25);
}

// Where the H itself is cut, or absent, observe_marking finds nothing (it never guesses).
TEST(PadPose, MarkingOnlyNeedsTheWholeH) {
  const auto r = renderer();
  const PadGeometry pad{world().helipad().size};
  PadMiss miss = PadMiss::None;
  const PadView cut = pad_view(r, 0.6, 0, 0, 0, {0.3, 0.0});  // the H's centre 0.3 m off the axis, along the body
  ASSERT_FALSE(h_inside(cut, pad.size, 0));
  EXPECT_FALSE(observe_marking(cut.frame.left, {0, 0, 376, 240}, cut.camera, pad, {}, &miss));
  EXPECT_NE(miss, PadMiss::None);
  const PadView away = pad_view(r, 1.0, 20, 0, 0, {2.5, 0.0});
  EXPECT_FALSE(observe_marking(away.frame.left, {0, 0, 376, 240}, away.camera, pad, {}, &miss));
  EXPECT_NE(miss, PadMiss::None);
}

TEST(PadPose, RejectsBadArgumentsNamingTheProblem) {
  const PadView v = pad_view(renderer(), 2.0, 0, 0, 0);
  const cv::Rect2d box = grown(v.frame.target_box, 0.3);
  const PadGeometry pad{1.0};
  auto message = [&](const cv::Mat& img, const aerie::camera::CameraModel& cam, const PadGeometry& g) -> std::string {
    try {
      observe_pad(img, box, cam, g);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "no exception";
  };
  EXPECT_NE(message(cv::Mat(), v.camera, pad).find("empty frame"), std::string::npos);
  auto cam = v.camera;
  cam.fx = 0;
  EXPECT_NE(message(v.frame.left, cam, pad).find("focal"), std::string::npos);
  cam = v.camera;
  cam.cy = NAN;
  EXPECT_NE(message(v.frame.left, cam, pad).find("principal point"), std::string::npos);
  cam = v.camera;
  cam.width = 752;
  EXPECT_NE(message(v.frame.left, cam, pad).find("752x240"), std::string::npos);
  EXPECT_NE(message(v.frame.left, v.camera, {0.0}).find("pad size"), std::string::npos);
  EXPECT_NE(message(v.frame.left, v.camera, {1.0, 0.3}).find("border"), std::string::npos);
}
