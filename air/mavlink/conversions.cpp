#include "air/mavlink/conversions.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "common/geometry/frames.hpp"

namespace aerie::bridge {

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;
constexpr float kUnknown = std::numeric_limits<float>::quiet_NaN();
constexpr uint8_t kVisionOther = 3;  // LANDING_TARGET_TYPE_VISION_OTHER: a pad found by a tracker, not a fiducial

// The upper triangle of a symmetric 6x6 matrix, row by row (MAVLink's 21-element covariances).
std::array<float, 21> upper_triangle(const Eigen::Matrix<double, 6, 6>& C) {
  std::array<float, 21> out{};
  size_t k = 0;
  for (int r = 0; r < 6; ++r)
    for (int c = r; c < 6; ++c) out[k++] = static_cast<float>(C(r, c));
  return out;
}

void require_target(const CameraTarget& t) {
  if (!t.position_cam.allFinite() || !(t.position_cam.z() > 0))
    throw std::invalid_argument("landing target: position is not finite or not in front of the camera");
}
}  // namespace

mavlink::SetPositionTargetLocalNed velocity_setpoint(const Eigen::Vector3d& velocity_heading, double yaw_rate_cw_deg_s,
                                                     uint32_t time_boot_ms, Target target) {
  if (!velocity_heading.allFinite() || !std::isfinite(yaw_rate_cw_deg_s))
    throw std::invalid_argument("velocity setpoint: velocity or yaw rate is not finite");
  const Eigen::Vector3d v = geometry::flip_yz(velocity_heading);  // heading FLU -> yaw-only FRD
  mavlink::SetPositionTargetLocalNed sp{};
  sp.time_boot_ms = time_boot_ms;
  sp.target_system = target.system;
  sp.target_component = target.component;
  sp.coordinate_frame = mavlink::mav_frame::kBodyNed;
  sp.type_mask = kVelocityYawRateMask;
  sp.vx = static_cast<float>(v.x());
  sp.vy = static_cast<float>(v.y());
  sp.vz = static_cast<float>(v.z());
  sp.yaw_rate = static_cast<float>(yaw_rate_cw_deg_s * kDeg);  // NED yaw grows clockwise seen from above
  return sp;
}

void velocity_from_setpoint(const mavlink::SetPositionTargetLocalNed& sp, Eigen::Vector3d& velocity_heading,
                            double& yaw_rate_cw_deg_s) {
  if (sp.coordinate_frame != mavlink::mav_frame::kBodyNed || sp.type_mask != kVelocityYawRateMask)
    throw std::invalid_argument("velocity setpoint: expected MAV_FRAME_BODY_NED with type_mask 0x05C7");
  velocity_heading = geometry::flip_yz(Eigen::Vector3d(sp.vx, sp.vy, sp.vz));
  yaw_rate_cw_deg_s = sp.yaw_rate / kDeg;
}

std::optional<mavlink::Odometry> OdometryStream::on_sample(const NavSample& s) {
  if (!s.valid) {
    was_valid_ = false;
    return std::nullopt;
  }
  if (!s.position.allFinite() || !s.velocity.allFinite() || !s.orientation.coeffs().allFinite())
    throw std::invalid_argument("odometry: navigation state is not finite");
  if (ever_valid_ && !was_valid_) ++reset_counter_;  // re-anchored: the estimator must not blend the two
  was_valid_ = ever_valid_ = true;

  // World (z up) -> MAV_FRAME_LOCAL_FRD, body FLU -> MAV_FRAME_BODY_FRD: both the half turn about x.
  const Eigen::Quaterniond q_local_frd = geometry::flip_yz(s.orientation.normalized());
  const Eigen::Vector3d p = geometry::flip_yz(s.position);
  const Eigen::Matrix3d R_world_body = s.orientation.normalized().toRotationMatrix();
  const Eigen::Vector3d v_body_frd = geometry::flip_yz(Eigen::Vector3d(R_world_body.transpose() * s.velocity));

  mavlink::Odometry o{};
  o.time_usec = static_cast<uint64_t>(s.utime);
  o.frame_id = mavlink::mav_frame::kLocalFrd;
  o.child_frame_id = mavlink::mav_frame::kBodyFrd;
  o.x = static_cast<float>(p.x());
  o.y = static_cast<float>(p.y());
  o.z = static_cast<float>(p.z());
  o.q = {static_cast<float>(q_local_frd.w()), static_cast<float>(q_local_frd.x()), static_cast<float>(q_local_frd.y()),
         static_cast<float>(q_local_frd.z())};
  o.vx = static_cast<float>(v_body_frd.x());
  o.vy = static_cast<float>(v_body_frd.y());
  o.vz = static_cast<float>(v_body_frd.z());
  o.rollspeed = o.pitchspeed = o.yawspeed = kUnknown;  // the filter publishes no rates
  Eigen::Matrix<double, 6, 6> pose = Eigen::Matrix<double, 6, 6>::Zero();
  pose.topLeftCorner<3, 3>() = geometry::flip_yz(s.position_covariance);
  // The world-frame attitude error expressed in the local FRD axes: for small tilts these are
  // the roll, pitch and yaw errors MAVLink asks for.
  pose.bottomRightCorner<3, 3>() = geometry::flip_yz(s.attitude_covariance);
  o.pose_covariance = upper_triangle(pose);
  Eigen::Matrix<double, 6, 6> vel = Eigen::Matrix<double, 6, 6>::Zero();
  const Eigen::Matrix3d R_frd = Eigen::Vector3d(1, -1, -1).asDiagonal() * R_world_body.transpose();
  vel.topLeftCorner<3, 3>() = R_frd * s.velocity_covariance * R_frd.transpose();
  o.velocity_covariance = upper_triangle(vel);
  o.velocity_covariance[15] = kUnknown;  // first angular-rate entry NaN: rates unknown
  o.reset_counter = reset_counter_;
  o.estimator_type = mavlink::mav_estimator_type::kVio;
  o.quality = 100;
  return o;
}

mavlink::LandingTarget landing_target_px4(const CameraTarget& t, const Eigen::Matrix3d& body_from_camera,
                                          const VehicleNed& vehicle) {
  require_target(t);
  const Eigen::Vector3d in_body_frd = geometry::flip_yz(Eigen::Vector3d(body_from_camera * t.position_cam));
  const Eigen::Vector3d in_ned = vehicle.position + vehicle.attitude.normalized() * in_body_frd;
  mavlink::LandingTarget m{};
  m.time_usec = static_cast<uint64_t>(t.utime);
  m.frame = mavlink::mav_frame::kLocalNed;
  m.angle_x = static_cast<float>(std::atan2(t.position_cam.x(), t.position_cam.z()));
  m.angle_y = static_cast<float>(std::atan2(t.position_cam.y(), t.position_cam.z()));
  m.distance = static_cast<float>(t.position_cam.norm());
  m.x = static_cast<float>(in_ned.x());
  m.y = static_cast<float>(in_ned.y());
  m.z = static_cast<float>(in_ned.z());
  m.q = {1, 0, 0, 0};
  m.type = kVisionOther;
  m.position_valid = 1;
  return m;
}

mavlink::LandingTarget landing_target_ardupilot(const CameraTarget& t, const Eigen::Matrix3d& body_from_camera) {
  require_target(t);
  const Eigen::Vector3d in_body_frd = geometry::flip_yz(Eigen::Vector3d(body_from_camera * t.position_cam));
  mavlink::LandingTarget m{};
  m.time_usec = static_cast<uint64_t>(t.utime);
  m.frame = mavlink::mav_frame::kBodyFrd;
  // AC_PrecLand_Companion: the line of sight in body FRD is (-tan(angle_y), tan(angle_x), 1) for a
  // camera looking down with the image's top towards the nose: angles of the optical frame.
  m.angle_x = static_cast<float>(std::atan2(t.position_cam.x(), t.position_cam.z()));
  m.angle_y = static_cast<float>(std::atan2(t.position_cam.y(), t.position_cam.z()));
  m.distance = static_cast<float>(t.position_cam.norm());
  m.x = static_cast<float>(in_body_frd.x());
  m.y = static_cast<float>(in_body_frd.y());
  m.z = static_cast<float>(in_body_frd.z());
  m.q = {1, 0, 0, 0};
  m.type = kVisionOther;
  m.position_valid = 1;
  return m;
}

}  // namespace aerie::bridge
