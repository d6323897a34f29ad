#pragma once
// Heading from a pose message: the pose's forward axis (a camera's optical axis, +z in the
// OpenCV convention; a body's +x) rotated into the world, projected on the horizontal plane,
// measured clockwise (to the right) from the world's zero-heading direction.
#include <Eigen/Core>

namespace aerie::control {

struct HeadingFrame {
  Eigen::Vector3d up{0.0, -1.0, 0.0};      // world "up" (VO's world is its first camera frame: y down)
  Eigen::Vector3d forward{0.0, 0.0, 1.0};  // zero heading (VO: the first camera's optical axis)
  Eigen::Vector3d axis{0.0, 0.0, 1.0};     // the pose's own forward axis (camera +z; NAV_STATE's body: +x)
  void validate() const;                   // non-zero, up and forward orthogonal; throws std::invalid_argument
};

// q = (w, x, y, z) of T_world_pose. Throws std::invalid_argument if q is not a unit
// quaternion (tolerance 1e-3) or the axis points (nearly) straight up or down.
double heading_from_quaternion(const double q[4], const HeadingFrame& frame);

}  // namespace aerie::control
