// Aerie's frames against MAVLink's: each conversion checked on a case whose answer is known
// from the definitions (docs/mavlink.md "Frames"), and round trips.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "air/mavlink/conversions.hpp"
#include "common/geometry/frames.hpp"

namespace aerie::bridge {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(VelocitySetpoint, HeadingFrameBecomesBodyNedWithYawRateClockwise) {
  // 1 m/s forward, 0.5 m/s to the left, climbing 0.2 m/s, turning right at 10 deg/s.
  const auto sp = velocity_setpoint({1.0, 0.5, 0.2}, 10.0, 1234, {1, 1});
  EXPECT_EQ(sp.coordinate_frame, mavlink::mav_frame::kBodyNed);
  EXPECT_EQ(sp.type_mask, 0x05C7);
  EXPECT_EQ(sp.time_boot_ms, 1234u);
  EXPECT_FLOAT_EQ(sp.vx, 1.0f);    // forward
  EXPECT_FLOAT_EQ(sp.vy, -0.5f);   // right is positive: left is negative
  EXPECT_FLOAT_EQ(sp.vz, -0.2f);   // down is positive: a climb is negative
  EXPECT_FLOAT_EQ(sp.yaw_rate, static_cast<float>(10.0 * kPi / 180));  // NED yaw grows clockwise
  Eigen::Vector3d v;
  double rate = 0;
  velocity_from_setpoint(sp, v, rate);
  EXPECT_NEAR((v - Eigen::Vector3d(1.0, 0.5, 0.2)).norm(), 0, 1e-6);
  EXPECT_NEAR(rate, 10.0, 1e-5);
}

TEST(VelocitySetpoint, RefusesNonFiniteInputAndForeignFrames) {
  EXPECT_THROW(velocity_setpoint({NAN, 0, 0}, 0, 0, {}), std::invalid_argument);
  EXPECT_THROW(velocity_setpoint({0, 0, 0}, INFINITY, 0, {}), std::invalid_argument);
  auto sp = velocity_setpoint({0, 0, 0}, 0, 0, {});
  sp.coordinate_frame = mavlink::mav_frame::kLocalNed;
  Eigen::Vector3d v;
  double rate;
  EXPECT_THROW(velocity_from_setpoint(sp, v, rate), std::invalid_argument);
}

NavSample level_sample(double yaw) {
  NavSample s;
  s.valid = true;
  s.utime = 5'000'000;
  s.position = {1.0, 2.0, 3.0};
  s.velocity = {0.0, 1.0, 0.0};  // moving along world +y
  s.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  s.position_covariance = Eigen::Vector3d(0.01, 0.02, 0.03).asDiagonal();
  s.position_covariance(0, 1) = s.position_covariance(1, 0) = 0.005;
  s.attitude_covariance = Eigen::Vector3d(1e-4, 2e-4, 3e-4).asDiagonal();
  s.velocity_covariance = Eigen::Matrix3d::Identity() * 0.04;
  return s;
}

TEST(Odometry, WorldZUpBecomesLocalFrdAndVelocityBodyFrd) {
  OdometryStream stream;
  const auto o = stream.on_sample(level_sample(kPi / 2));  // nose along world +y
  ASSERT_TRUE(o);
  EXPECT_EQ(o->frame_id, mavlink::mav_frame::kLocalFrd);
  EXPECT_EQ(o->child_frame_id, mavlink::mav_frame::kBodyFrd);
  EXPECT_FLOAT_EQ(o->x, 1.0f);
  EXPECT_FLOAT_EQ(o->y, -2.0f);
  EXPECT_FLOAT_EQ(o->z, -3.0f);  // 3 m up is z = -3 in a z-down frame
  // Moving along +y with the nose along +y: straight forward in the body.
  EXPECT_NEAR(o->vx, 1.0, 1e-6);
  EXPECT_NEAR(o->vy, 0.0, 1e-6);
  EXPECT_NEAR(o->vz, 0.0, 1e-6);
  // Yawed +90 deg counter-clockwise (z up) is -90 deg about the z-down axis.
  const Eigen::Quaterniond q(o->q[0], o->q[1], o->q[2], o->q[3]);
  const Eigen::Vector3d nose = q * Eigen::Vector3d::UnitX();
  EXPECT_NEAR((nose - Eigen::Vector3d(0, -1, 0)).norm(), 0, 1e-6);
  // Covariance: the x-y cross term changes sign with y, the diagonal stays.
  EXPECT_FLOAT_EQ(o->pose_covariance[0], 0.01f);
  EXPECT_FLOAT_EQ(o->pose_covariance[1], -0.005f);
  EXPECT_FLOAT_EQ(o->pose_covariance[6], 0.02f);   // (1,1): after the 6 entries of row 0
  EXPECT_FLOAT_EQ(o->pose_covariance[20], 3e-4f);  // (5,5): yaw
  EXPECT_FLOAT_EQ(o->velocity_covariance[0], 0.04f);
  EXPECT_TRUE(std::isnan(o->velocity_covariance[15]));  // angular rates unknown
  EXPECT_TRUE(std::isnan(o->rollspeed));
}

TEST(Odometry, NothingWhileInvalidAndResetCounterOnEachReanchor) {
  OdometryStream stream;
  auto s = level_sample(0);
  s.valid = false;
  EXPECT_FALSE(stream.on_sample(s));  // initialising: nothing is sent
  s.valid = true;
  EXPECT_EQ(stream.on_sample(s)->reset_counter, 0);  // the first estimate is no reset
  EXPECT_EQ(stream.on_sample(s)->reset_counter, 0);
  s.valid = false;
  EXPECT_FALSE(stream.on_sample(s));  // IMU only: the autopilot must not get its own IMU back
  s.valid = true;
  EXPECT_EQ(stream.on_sample(s)->reset_counter, 1);
  s.valid = false;
  stream.on_sample(s);
  s.valid = true;
  EXPECT_EQ(stream.on_sample(s)->reset_counter, 2);
  s.position.x() = NAN;
  EXPECT_THROW(stream.on_sample(s), std::invalid_argument);
}

TEST(LandingTarget, Px4GetsTheTargetInItsLocalNedFrame) {
  // Camera straight down, image top towards the nose; the target 0.5 m ahead of the vehicle
  // (image up = -y optical) and 0.2 m to its right (+x optical), 2 m below.
  const Eigen::Matrix3d mount = geometry::body_from_camera(90);
  CameraTarget t{7, {0.2, -0.5, 2.0}};
  VehicleNed v;
  v.position = {10, 20, -2};  // 2 m above the local origin
  v.attitude = Eigen::Quaterniond(Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitZ()));  // facing east
  const auto m = landing_target_px4(t, mount, v);
  EXPECT_EQ(m.frame, mavlink::mav_frame::kLocalNed);
  EXPECT_EQ(m.position_valid, 1);
  // Facing east: ahead is +east (NED y), right is south (NED -x).
  EXPECT_NEAR(m.x, 10 - 0.2, 1e-5);
  EXPECT_NEAR(m.y, 20 + 0.5, 1e-5);
  EXPECT_NEAR(m.z, 0.0, 1e-5);
  EXPECT_NEAR(m.distance, std::sqrt(0.04 + 0.25 + 4.0), 1e-5);
}

TEST(LandingTarget, ArduPilotGetsBodyFrdAnglesItsCompanionDriverReadsBack) {
  const Eigen::Matrix3d mount = geometry::body_from_camera(90);
  CameraTarget t{7, {0.2, -0.5, 2.0}};
  const auto m = landing_target_ardupilot(t, mount);
  EXPECT_EQ(m.frame, mavlink::mav_frame::kBodyFrd);
  EXPECT_NEAR(m.x, 0.5, 1e-6);  // forward
  EXPECT_NEAR(m.y, 0.2, 1e-6);  // right
  EXPECT_NEAR(m.z, 2.0, 1e-6);  // below
  // AC_PrecLand_Companion's line of sight from the angles: (-tan(angle_y), tan(angle_x), 1).
  EXPECT_NEAR(-std::tan(m.angle_y) * 2.0, 0.5, 1e-5);
  EXPECT_NEAR(std::tan(m.angle_x) * 2.0, 0.2, 1e-5);
  EXPECT_THROW(landing_target_ardupilot({0, {0, 0, -1}}, mount), std::invalid_argument);  // behind the camera
}

}  // namespace
}  // namespace aerie::bridge
