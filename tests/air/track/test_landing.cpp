// Target 3D pose from a track of known size (eq.: Z = f W / w, X = Z * ray).
#include <gtest/gtest.h>

#include "air/track/landing/target_pose.hpp"

using namespace aerie::track;

namespace {
aerie::camera::CameraModel pinhole() {
  aerie::camera::CameraModel c;
  c.width = 640, c.height = 480;
  c.fx = c.fy = 500, c.cx = 320, c.cy = 240;
  return c;
}
}  // namespace

TEST(TargetPose, RecoversPositionAndYawOfAProjectedTarget) {
  // a 1.2 m x 0.8 m helipad at (0.5, -0.3, 6) m, rotated by 0.4 rad about the optical axis
  const auto cam = pinhole();
  const Eigen::Vector2d uv = cam.project({0.5, -0.3, 6});
  TrackState s;
  s.initial_size = {500 * 1.2 / 8, 500 * 0.8 / 8};  // initialised at 8 m ...
  s.pose = {uv.x(), uv.y(), 8.0 / 6, 0.4};          // ... now 6 m away: 4/3 the size
  const TargetPose p = target_pose(s, cam, {1.2, 0.8, 0.0});
  EXPECT_NEAR(p.position.x(), 0.5, 1e-9);
  EXPECT_NEAR(p.position.y(), -0.3, 1e-9);
  EXPECT_NEAR(p.position.z(), 6.0, 1e-9);
  EXPECT_NEAR(p.yaw, 0.4, 1e-12);
  EXPECT_NEAR(target_pose(s, cam, {1.2, 0.8, 3.0}).yaw, std::remainder(3.4, 2 * M_PI), 1e-12);
}

TEST(TargetPose, UsesTheDistortionModelForTheRay) {
  auto cam = pinhole();
  cam.distortion = aerie::camera::Distortion::RadTan;
  cam.coeffs = {-0.3, 0.1, 0.001, -0.002, 0.0};
  const Eigen::Vector3d truth(1.5, 1.0, 5.0);  // off-axis, where distortion matters
  const Eigen::Vector2d uv = cam.project(truth);
  TrackState s;
  s.initial_size = {500 * 1.0 / 5, 500 * 1.0 / 5};
  s.pose = {uv.x(), uv.y(), 1.0, 0.0};
  const TargetPose p = target_pose(s, cam, {1.0, 1.0, 0.0});
  EXPECT_NEAR(p.position.z(), 5.0, 1e-9);
  EXPECT_NEAR(p.position.x(), 1.5, 1e-6);
  EXPECT_NEAR(p.position.y(), 1.0, 1e-6);
}

TEST(TargetPose, RejectsUnusableInput) {
  TrackState s;
  s.initial_size = {50, 50};
  s.pose = {300, 200, 1, 0};
  EXPECT_THROW(target_pose(s, pinhole(), {0.0, 1.0, 0}), std::invalid_argument);
  auto nofocal = pinhole();
  nofocal.fx = 0;
  EXPECT_THROW(target_pose(s, nofocal, {1, 1, 0}), std::invalid_argument);
  s.pose.x = NAN;
  EXPECT_THROW(target_pose(s, pinhole(), {1, 1, 0}), std::invalid_argument);
  s.pose = {300, 200, 0, 0};  // zero size
  EXPECT_THROW(target_pose(s, pinhole(), {1, 1, 0}), std::invalid_argument);
}
