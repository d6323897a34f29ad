#pragma once
// The two residuals of the 2D+3D motion estimate (thesis eqs. 4.12-4.16, after Zhang,
// Kaess & Singh 2014), templated so Ceres' Jets pass through. The motion M = [w; t] maps
// frame-k points into frame k+1, X^{k+1} = R X^k + t (eq. 4.8), R = exp([w]x) (eqs. 4.9-4.11).
#include <Eigen/Core>

#include "common/geometry/so3.hpp"

namespace aerie::stereo {

// Feature with depth in frame k, seen at normalised (x^, y^) in frame k+1 (eqs. 4.14-4.15):
//   (R_1 - x^ R_3) X^k + T_1 - x^ T_3 = 0,   (R_2 - y^ R_3) X^k + T_2 - y^ T_3 = 0.
template <typename T>
void residual_3d(const T* w, const T* t, const Eigen::Vector3d& X_k, const Eigen::Vector2d& x_next, T* r) {
  const geometry::Mat3<T> R = geometry::so3_exp<T>(geometry::Vec3<T>(w[0], w[1], w[2]));
  const geometry::Vec3<T> RX = R * X_k.cast<T>();
  r[0] = RX[0] + t[0] - T(x_next.x()) * (RX[2] + t[2]);
  r[1] = RX[1] + t[1] - T(x_next.y()) * (RX[2] + t[2]);
}

// Feature without depth seen at normalised X^k = (x^k, y^k, 1) and X^{k+1} (eq. 4.16):
//   [T_2 - y^{k+1} T_3,  x^{k+1} T_3 - T_1,  y^{k+1} T_1 - x^{k+1} T_2] . R X^k = 0,
// i.e. the epipolar constraint (X^{k+1} x t) . R X^k = 0. (The thesis prints the third
// entry as -x^k T_3 + y^k T_1, a typo: eliminating z^k and z^{k+1} from eq. 4.13 gives
// the one above, which vanishes for the true motion; tests/air/stereo checks it.)
template <typename T>
void residual_2d(const T* w, const T* t, const Eigen::Vector2d& x_k, const Eigen::Vector2d& x_next, T* r) {
  const geometry::Mat3<T> R = geometry::so3_exp<T>(geometry::Vec3<T>(w[0], w[1], w[2]));
  const geometry::Vec3<T> RX = R * geometry::Vec3<T>(T(x_k.x()), T(x_k.y()), T(1));
  const T xn(x_next.x()), yn(x_next.y());
  r[0] = (t[1] - yn * t[2]) * RX[0] + (xn * t[2] - t[0]) * RX[1] + (yn * t[0] - xn * t[1]) * RX[2];
}

}  // namespace aerie::stereo
