#include "ground/viewer/world_frame.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "tools/eval/metrics.hpp"

namespace aerie::viewer {

std::string gravity_label(GravitySource s) {
  switch (s) {
    case GravitySource::Imu: return "gravity: IMU";
    case GravitySource::FirstGtPose: return "gravity: first GT pose";
    case GravitySource::None: break;
  }
  return "gravity: none (camera frame)";
}

Eigen::Matrix3d gravity_rotation(const std::vector<Eigen::Vector3d>& specific_force_body,
                                 const geometry::SE3& T_body_cam, const geometry::SE3& T_vo_cam) {
  if (specific_force_body.empty()) throw std::invalid_argument("gravity_rotation: no IMU samples");
  Eigen::Vector3d f = Eigen::Vector3d::Zero();
  for (const auto& a : specific_force_body) f += a;
  f /= static_cast<double>(specific_force_body.size());
  if (!(f.norm() > 7.0 && f.norm() < 12.6))
    throw std::invalid_argument("gravity_rotation: mean specific force " + std::to_string(f.norm()) +
                                " m/s^2 is not 1 g (7..12.6 expected): the IMU is not at rest");
  // At rest the accelerometer measures -g (imu_t: +9.81 along body z up).
  const Eigen::Vector3d g_vo = -(T_vo_cam.rotation() * (T_body_cam.rotation().conjugate() * f));
  return Eigen::Quaterniond::FromTwoVectors(g_vo, -Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

geometry::SE3 frame_from_first_gt_pose(const geometry::SE3& T_gt_cam, const geometry::SE3& T_vo_cam) {
  return T_gt_cam * T_vo_cam.inverse();
}

std::string GtAlignment::label() const {
  char b[160];
  std::snprintf(b, sizeof b, "GT aligned: SE(3)%s, %zu pairs, ATE %.3f m", degenerate ? " (at rest: mean rotation)" : "",
                pairs, ate_m);
  return b;
}

std::optional<GtAlignment> align_ground_truth(const eval::Trajectory& gt, const eval::Trajectory& vo, double max_dt) {
  if (gt.size() < 3 || vo.size() < 3) return std::nullopt;
  eval::Associated m;
  try {
    m = eval::associate(gt, vo, max_dt);
  } catch (const std::runtime_error&) {
    return std::nullopt;  // nothing matches in time (yet)
  }
  if (m.ref.size() < 3) return std::nullopt;
  std::vector<Eigen::Vector3d> p_gt, p_vo;
  Eigen::Vector3d mu = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < m.ref.size(); ++i) {
    p_gt.push_back(m.ref.poses[i].translation());
    p_vo.push_back(m.est.poses[i].translation());
    mu += p_gt.back();
  }
  mu /= static_cast<double>(p_gt.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : p_gt) cov += (p - mu) * (p - mu).transpose();
  cov /= static_cast<double>(p_gt.size());
  const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvalues();  // ascending
  GtAlignment a;
  a.pairs = p_gt.size();
  a.degenerate = std::sqrt(std::max(ev[1], 0.0)) < kMinSpreadM;
  if (!a.degenerate) {
    // vo ~ R gt + t: Umeyama with the ground truth as the points to move (tools/eval/metrics.hpp).
    a.T_vo_gt = eval::umeyama(p_gt, p_vo, false).transform;
  } else {
    Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
    for (size_t i = 0; i < m.ref.size(); ++i)
      sum += m.est.poses[i].rotation_matrix() * m.ref.poses[i].rotation_matrix().transpose();
    // The rotation nearest to the mean (chordal L2 mean): the polar factor of the sum.
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(sum, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
    D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1 : 1;
    const Eigen::Matrix3d R = svd.matrixU() * D * svd.matrixV().transpose();
    Eigen::Vector3d mu_vo = Eigen::Vector3d::Zero();
    for (const auto& p : p_vo) mu_vo += p;
    mu_vo /= static_cast<double>(p_vo.size());
    a.T_vo_gt = geometry::SE3(R, mu_vo - R * mu);
  }
  double sse = 0;
  for (size_t i = 0; i < p_gt.size(); ++i) sse += (p_vo[i] - a.T_vo_gt * p_gt[i]).squaredNorm();
  a.ate_m = std::sqrt(sse / static_cast<double>(p_gt.size()));
  return a;
}

}  // namespace aerie::viewer
