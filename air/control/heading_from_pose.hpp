#pragma once
// Heading of the camera from a pose message: the optical axis (camera +z, OpenCV
// convention) rotated into the world, projected on the horizontal plane, measured
// clockwise (to the right) from the world's zero-heading direction.
#include <Eigen/Core>

namespace aerie::control {

struct HeadingFrame {
  Eigen::Vector3d up{0.0, -1.0, 0.0};      // world "up" (VO's world is its first camera frame: y down)
  Eigen::Vector3d forward{0.0, 0.0, 1.0};  // zero heading (VO: the first camera's optical axis)
  void validate() const;                   // non-zero, orthogonal; throws std::invalid_argument
};

// q = (w, x, y, z) of T_world_camera. Throws std::invalid_argument if q is not a unit
// quaternion (tolerance 1e-3) or the optical axis points (nearly) straight up or down.
double heading_from_quaternion(const double q[4], const HeadingFrame& frame);

}  // namespace aerie::control
