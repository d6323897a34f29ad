#pragma once
// The frames the viewer draws in (no VTK, no LCM: tested alone).
//
// VO's world is the first camera's optical frame (x right, y down, z forward), so the
// 3D scene shows it in a gravity-aligned display frame D (z up, the grid on z = 0):
//  * first GT pose: D is the ground truth's world (z up for EuRoC's Vicon frame and the
//    simulator), T_D_vo = T_gt_cam(t0) * T_vo_cam(t0)^-1 at the first VO pose t0 that has a
//    ground-truth pose at the same time;
//  * IMU: the average specific force f of the first samples at rest (imu_t, body frame)
//    points up, so gravity in VO's world is g_vo = -R_vo_cam R_body_cam^T f; R_D_vo is the
//    smallest rotation taking g_vo to -z (Eigen's FromTwoVectors), the origin unchanged;
//  * none: D = VO's world.
// The ground truth is drawn in the estimate's frame as trajeval aligns it (tools/eval:
// eval::associate by time, then eval::umeyama, SE(3) for stereo), T_vo_gt.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "common/geometry/se3.hpp"
#include "tools/eval/trajectory.hpp"

namespace aerie::viewer {

enum class GravitySource { None, Imu, FirstGtPose };
// "gravity: IMU", "gravity: first GT pose", "gravity: none (camera frame)".
std::string gravity_label(GravitySource s);

// R_D_vo with R_D_vo * g_vo = -|g_vo| z exactly (see above). Throws std::invalid_argument
// when there are no samples or their mean is not near 1 g (7..12.6 m/s^2: not at rest).
Eigen::Matrix3d gravity_rotation(const std::vector<Eigen::Vector3d>& specific_force_body,
                                 const geometry::SE3& T_body_cam, const geometry::SE3& T_vo_cam);

// T_D_vo from the first pose pair (same frame time): T_gt_cam * T_vo_cam^-1.
geometry::SE3 frame_from_first_gt_pose(const geometry::SE3& T_gt_cam, const geometry::SE3& T_vo_cam);

struct GtAlignment {
  geometry::SE3 T_vo_gt;   // ground truth -> the estimate's world
  size_t pairs = 0;        // poses matched by time
  double ate_m = 0;        // RMSE of |p_vo - T_vo_gt p_gt| over the pairs
  // The matched positions span less than kMinSpreadM in two directions (a vehicle at rest,
  // a straight line): Umeyama's rotation is undetermined, so the rotation is the mean of
  // R_vo R_gt^T over the pairs and the translation matches the centroids.
  bool degenerate = false;
  std::string label() const;  // "GT aligned: SE(3), 94 pairs, ATE 0.004 m"
};
inline constexpr double kMinSpreadM = 0.05;
// Pairs within max_dt seconds (eval::associate); nullopt when fewer than 3 match.
std::optional<GtAlignment> align_ground_truth(const eval::Trajectory& gt, const eval::Trajectory& vo,
                                              double max_dt = 0.01);

}  // namespace aerie::viewer
