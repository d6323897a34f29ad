#include "air/control/heading_from_pose.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace aerie::control {

void HeadingFrame::validate() const {
  if (!(up.norm() > 1e-9) || !(forward.norm() > 1e-9) || std::abs(up.normalized().dot(forward.normalized())) > 1e-6)
    throw std::invalid_argument("heading frame: up and forward must be non-zero and orthogonal");
  if (!(axis.norm() > 1e-9)) throw std::invalid_argument("heading frame: axis must be non-zero");
}

double heading_from_quaternion(const double q[4], const HeadingFrame& frame) {
  const Eigen::Quaterniond r(q[0], q[1], q[2], q[3]);
  const double n = r.norm();
  if (!std::isfinite(n) || std::abs(n - 1.0) > 1e-3)
    throw std::invalid_argument("orientation is not a unit quaternion (norm " + std::to_string(n) + ")");
  const Eigen::Vector3d d = r.normalized() * frame.axis.normalized();
  const Eigen::Vector3d up = frame.up.normalized(), fwd = frame.forward.normalized();
  const Eigen::Vector3d right = fwd.cross(up);
  const double f = d.dot(fwd), s = d.dot(right);
  if (std::hypot(f, s) < 1e-3) throw std::invalid_argument("the heading axis is vertical: heading undefined");
  return std::atan2(s, f) * 180.0 / std::numbers::pi;
}

}  // namespace aerie::control
