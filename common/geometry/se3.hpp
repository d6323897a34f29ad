#pragma once
// Rigid-body transforms T = [R t; 0 1] with exp/log through so(3).
// Convention: T_a_b maps points from frame b into frame a (p_a = T_a_b * p_b).
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/geometry/so3.hpp"

namespace aerie::geometry {

class SE3 {
 public:
  SE3() = default;
  SE3(const Eigen::Quaterniond& q, const Eigen::Vector3d& t) : q_(q.normalized()), t_(t) {}
  SE3(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) : q_(Eigen::Quaterniond(R).normalized()), t_(t) {}
  explicit SE3(const Eigen::Matrix4d& T) : SE3(Eigen::Matrix3d(T.topLeftCorner<3, 3>()), T.topRightCorner<3, 1>()) {}

  static SE3 identity() { return {}; }

  // exp of the twist xi = [w; v] (rotation first, as M = [w; t] in thesis eq. 4.9),
  // with t = V(w) v so that log(exp(xi)) == xi.
  static SE3 exp(const Eigen::Matrix<double, 6, 1>& xi);
  // Rotation from a rotation vector, translation taken as is (the thesis' motion M = [w; t]).
  static SE3 from_rotation_vector(const Eigen::Vector3d& w, const Eigen::Vector3d& t) {
    return SE3(Eigen::Matrix3d(so3_exp<double>(w)), t);
  }
  Eigen::Matrix<double, 6, 1> log() const;

  const Eigen::Quaterniond& rotation() const { return q_; }
  Eigen::Matrix3d rotation_matrix() const { return q_.toRotationMatrix(); }
  const Eigen::Vector3d& translation() const { return t_; }
  Eigen::Matrix4d matrix() const;

  SE3 inverse() const { return {q_.conjugate(), -(q_.conjugate() * t_)}; }
  SE3 operator*(const SE3& o) const { return {q_ * o.q_, q_ * o.t_ + t_}; }
  Eigen::Vector3d operator*(const Eigen::Vector3d& p) const { return q_ * p + t_; }

  // Unit quaternion as (w, x, y, z), the order every Aerie message uses.
  void to_wxyz(double out[4]) const;
  static SE3 from_wxyz(const double q[4], const double t[3]);

 private:
  Eigen::Quaterniond q_ = Eigen::Quaterniond::Identity();
  Eigen::Vector3d t_ = Eigen::Vector3d::Zero();
};

// Rotation angle of R in radians.
double rotation_angle(const Eigen::Matrix3d& R);

}  // namespace aerie::geometry
