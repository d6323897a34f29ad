#include "common/geometry/se3.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace aerie::geometry {
namespace {

// V(w) = I + (1-cos t)/t^2 [w]x + (t - sin t)/t^3 [w]x^2, the left Jacobian of SO(3).
Eigen::Matrix3d left_jacobian(const Eigen::Vector3d& w) {
  const double t2 = w.squaredNorm();
  const Eigen::Matrix3d W = hat<double>(w);
  double b, c;
  if (t2 < 1e-12) {
    b = 0.5 - t2 / 24.0;
    c = 1.0 / 6.0 - t2 / 120.0;
  } else {
    const double t = std::sqrt(t2);
    b = (1.0 - std::cos(t)) / t2;
    c = (t - std::sin(t)) / (t2 * t);
  }
  return Eigen::Matrix3d::Identity() + b * W + c * W * W;
}

}  // namespace

SE3 SE3::exp(const Eigen::Matrix<double, 6, 1>& xi) {
  const Eigen::Vector3d w = xi.head<3>();
  const Eigen::Vector3d v = xi.tail<3>();
  return SE3(Eigen::Matrix3d(so3_exp<double>(w)), left_jacobian(w) * v);
}

Eigen::Matrix<double, 6, 1> SE3::log() const {
  Eigen::Matrix<double, 6, 1> xi;
  const Eigen::Vector3d w = so3_log(rotation_matrix());
  xi.head<3>() = w;
  xi.tail<3>() = left_jacobian(w).inverse() * t_;
  return xi;
}

Eigen::Matrix4d SE3::matrix() const {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = rotation_matrix();
  T.topRightCorner<3, 1>() = t_;
  return T;
}

void SE3::to_wxyz(double out[4]) const {
  out[0] = q_.w();
  out[1] = q_.x();
  out[2] = q_.y();
  out[3] = q_.z();
}

SE3 SE3::from_wxyz(const double q[4], const double t[3]) {
  const Eigen::Quaterniond quat(q[0], q[1], q[2], q[3]);
  const double n = quat.norm();
  if (!std::isfinite(n) || n < 1e-9) {
    throw std::invalid_argument("SE3::from_wxyz: quaternion is zero or not finite");
  }
  return SE3(quat, Eigen::Vector3d(t[0], t[1], t[2]));
}

double rotation_angle(const Eigen::Matrix3d& R) {
  return std::acos(std::clamp((R.trace() - 1.0) / 2.0, -1.0, 1.0));
}

}  // namespace aerie::geometry
