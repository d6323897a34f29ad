#pragma once
// Aerie's axes against the aerospace ones (docs/mavlink.md, "Frames"), written once.
//
//   Aerie body / heading frame  FLU: x forward, y left, z up (imu_t, control_cmd_t, nav_state_t's body)
//   Aerie world                 z up, gravity-aligned (the simulator's: x east, y north = ENU)
//   MAVLink body                FRD: x forward, y right, z down (MAV_FRAME_BODY_FRD, PX4's body)
//   MAVLink local               NED (x north, y east, z down) or LOCAL_FRD (z down, x where the
//                               estimator starts)
//   camera optical              x right, y down, z forward (target_pose_t)
//
// FLU <-> FRD and z-up world <-> z-down local are both the half turn about x, S = diag(1, -1, -1)
// (its own inverse). ENU <-> NED swaps x and y and flips z (a different map: used only where
// the world really is ENU, as in the simulator's autopilot).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

namespace aerie::geometry {

// v_frd = S v_flu (and back); p_local_frd = S p_world_zup (and back).
inline Eigen::Vector3d flip_yz(const Eigen::Vector3d& v) { return {v.x(), -v.y(), -v.z()}; }
// R' = S R S: a rotation between two z-up frames expressed between the two z-down ones.
// For a unit quaternion (w, x, y, z) this is (w, x, -y, -z).
inline Eigen::Quaterniond flip_yz(const Eigen::Quaterniond& q) { return {q.w(), q.x(), -q.y(), -q.z()}; }
// C' = S C S for a 3x3 covariance.
inline Eigen::Matrix3d flip_yz(const Eigen::Matrix3d& C) {
  const Eigen::Matrix3d S = Eigen::Vector3d(1, -1, -1).asDiagonal();
  return S * C * S;
}

// ENU <-> NED (the same map both ways).
inline Eigen::Vector3d ned_from_enu(const Eigen::Vector3d& v) { return {v.y(), v.x(), -v.z()}; }
inline Eigen::Vector3d enu_from_ned(const Eigen::Vector3d& v) { return ned_from_enu(v); }
// Heading: ENU yaw is counter-clockwise from east, NED yaw clockwise from north.
inline double ned_yaw_from_enu_yaw(double yaw_enu) { return std::numbers::pi / 2 - yaw_enu; }

// The camera optical axes in the body frame (FLU) for a camera on the body's x-z plane whose
// optical axis is pitched `pitch_deg` below body x (90 = looking straight down, with the image's
// top towards the nose): columns are the camera's x (right = -y body), y, z.
inline Eigen::Matrix3d body_from_camera(double pitch_deg) {
  const double p = pitch_deg * (std::numbers::pi / 180.0);
  const Eigen::Vector3d x_c(0, -1, 0), z_c(std::cos(p), 0, -std::sin(p));
  Eigen::Matrix3d R;
  R.col(0) = x_c;
  R.col(1) = z_c.cross(x_c);
  R.col(2) = z_c;
  return R;
}

}  // namespace aerie::geometry
