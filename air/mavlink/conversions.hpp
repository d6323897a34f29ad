#pragma once
// What Aerie tells the autopilot, in the autopilot's own frames (docs/mavlink.md, "Frames";
// the axes are common/geometry/frames.hpp's). No LCM, no I/O: the node feeds these from its
// messages and puts their results on the wire.
//
//  * Velocity setpoints: control_cmd_t's heading-frame velocity (x forward, y left, z up) and
//    yaw rate (clockwise positive) -> SET_POSITION_TARGET_LOCAL_NED in MAV_FRAME_BODY_NED, which
//    PX4 (mavlink_receiver) and ArduCopter (GUIDED) both rotate by the vehicle's yaw alone: the
//    heading frame with y and z flipped. Velocity + yaw rate only: type_mask 0x05C7.
//  * Vision odometry: nav_state_t (z-up world, FLU body) -> ODOMETRY in MAV_FRAME_LOCAL_FRD with
//    the velocity in MAV_FRAME_BODY_FRD, pose covariance, and reset_counter bumped each time the
//    estimate re-anchors (PX4 resets its EV fusion on a change).
//  * Landing target: target_pose_t (camera optical frame) -> LANDING_TARGET, PX4's way (x, y, z
//    in MAV_FRAME_LOCAL_NED, the autopilot's own local frame, position_valid = 1) or ArduPilot's
//    (MAV_FRAME_BODY_FRD: angle_x, angle_y, distance and x, y, z with position_valid = 1).
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <optional>

#include "common/mavlink/catalogue.hpp"

namespace aerie::bridge {

inline constexpr uint16_t kVelocityYawRateMask = mavlink::type_mask::kVelocityYawRate;  // 0x05C7

struct Target {
  uint8_t system = 1;
  uint8_t component = 1;
};

// velocity_heading: m/s, x forward, y left, z up; yaw_rate_cw_deg_s: clockwise seen from above.
mavlink::SetPositionTargetLocalNed velocity_setpoint(const Eigen::Vector3d& velocity_heading, double yaw_rate_cw_deg_s,
                                                     uint32_t time_boot_ms, Target target);
// The inverse (what the autopilot flies): throws std::invalid_argument unless the frame is
// BODY_NED and the mask is velocity + yaw rate.
void velocity_from_setpoint(const mavlink::SetPositionTargetLocalNed& sp, Eigen::Vector3d& velocity_heading,
                            double& yaw_rate_cw_deg_s);

// One estimate of the navigation filter, as the odometry stream needs it.
struct NavSample {
  int64_t utime = 0;
  bool valid = false;                                     // the filter's status is OK (vision fused)
  Eigen::Vector3d position = Eigen::Vector3d::Zero();     // world (z up), m
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();     // world, m/s
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // body (FLU) -> world
  Eigen::Matrix3d position_covariance = Eigen::Matrix3d::Zero();    // world, m^2
  Eigen::Matrix3d attitude_covariance = Eigen::Matrix3d::Zero();    // world-frame angle error, rad^2
  Eigen::Matrix3d velocity_covariance = Eigen::Matrix3d::Zero();    // world, (m/s)^2
};

// Turns the filter's estimates into ODOMETRY messages: nothing while the estimate is not valid
// (an IMU-only estimate would feed the autopilot its own IMU back), and reset_counter bumped
// on the first valid estimate after an invalid one.
class OdometryStream {
 public:
  std::optional<mavlink::Odometry> on_sample(const NavSample& s);
  uint8_t reset_counter() const { return reset_counter_; }

 private:
  uint8_t reset_counter_ = 0;
  bool was_valid_ = false;
  bool ever_valid_ = false;
};

// A target seen by the landing camera.
struct CameraTarget {
  int64_t utime = 0;
  Eigen::Vector3d position_cam = Eigen::Vector3d::Zero();  // optical frame, m (z > 0)
  bool fitted = true;  // fitted to the target's geometry (pad or fiducials: any source but SOURCE_BOX), not the box alone
};

// The vehicle in the autopilot's local frame, from its LOCAL_POSITION_NED and ATTITUDE_QUATERNION.
struct VehicleNed {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();            // NED, m
  Eigen::Quaterniond attitude = Eigen::Quaterniond::Identity();  // body FRD -> NED
};

// body_from_camera: the camera mount (geometry::body_from_camera). Throws std::invalid_argument
// for a target that is not finite or not in front of the camera.
mavlink::LandingTarget landing_target_px4(const CameraTarget& t, const Eigen::Matrix3d& body_from_camera,
                                          const VehicleNed& vehicle);
mavlink::LandingTarget landing_target_ardupilot(const CameraTarget& t, const Eigen::Matrix3d& body_from_camera);

}  // namespace aerie::bridge
