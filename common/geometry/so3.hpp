#pragma once
// Rotations on so(3): the exponential map (Rodrigues, thesis eqs. 4.9-4.11) and
// its inverse. Templated on the scalar so Ceres' Jets pass through unchanged.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace aerie::geometry {

template <typename T>
using Vec3 = Eigen::Matrix<T, 3, 1>;
template <typename T>
using Mat3 = Eigen::Matrix<T, 3, 3>;

// [w]x, the skew-symmetric matrix with hat(w) * v == w.cross(v).
template <typename T>
Mat3<T> hat(const Vec3<T>& w) {
  Mat3<T> m;
  m << T(0), -w.z(), w.y(),
       w.z(), T(0), -w.x(),
       -w.y(), w.x(), T(0);
  return m;
}

template <typename T>
Vec3<T> vee(const Mat3<T>& m) {
  return Vec3<T>(m(2, 1), m(0, 2), m(1, 0));
}

// exp: R = I + sin(|w|)/|w| [w]x + (1 - cos|w|)/|w|^2 [w]x^2 (eq. 4.10), with the
// Taylor expansion near zero so derivatives stay exact at w = 0.
template <typename T>
Mat3<T> so3_exp(const Vec3<T>& w) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T theta2 = w.squaredNorm();
  const Mat3<T> W = hat(w);
  T a, b;
  if (theta2 < T(1e-12)) {
    a = T(1) - theta2 / T(6);
    b = T(0.5) - theta2 / T(24);
  } else {
    const T theta = sqrt(theta2);
    a = sin(theta) / theta;
    b = (T(1) - cos(theta)) / theta2;
  }
  return Mat3<T>::Identity() + a * W + b * W * W;
}

// log: the rotation vector w with so3_exp(w) == R, |w| in [0, pi].
inline Eigen::Vector3d so3_log(const Eigen::Matrix3d& R) {
  // Eigen's angle-axis handles the angle-near-pi case robustly.
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

}  // namespace aerie::geometry
