#pragma once
// The rectified stereo rig and triangulation of thesis eq. 4.1 in the left camera's
// optical frame (x right, y down, z forward): a pixel (u, v) with disparity d gives
//   X = ((u - c_x) b / d, (v - c_y) b / d, f b / d).
// With fx != fy the y coordinate is (v - c_y) Z / f_y, which is eq. 4.1 when fx = fy.
#include <Eigen/Core>
#include <stdexcept>
#include <string>

namespace aerie::stereo {

struct StereoCamera {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  double baseline = 0;  // metres
  int width = 0, height = 0;

  bool operator==(const StereoCamera&) const = default;
  void validate(const std::string& what = "stereo camera") const {
    if (!(fx > 0) || !(fy > 0) || !(baseline > 0) || width <= 0 || height <= 0)
      throw std::invalid_argument(what + ": fx, fy, baseline, width and height must be positive");
  }
  // Eq. 4.1. d > 0.
  Eigen::Vector3d triangulate(double u, double v, double d) const {
    const double z = fx * baseline / d;
    return {(u - cx) * baseline / d, (v - cy) * z / fy, z};
  }
  double depth(double d) const { return fx * baseline / d; }
  double disparity(double z) const { return fx * baseline / z; }
  Eigen::Vector2d project(const Eigen::Vector3d& X) const { return {fx * X.x() / X.z() + cx, fy * X.y() / X.z() + cy}; }
  // Normalised image coordinates (x^, y^) = ((u - c_x) / f_x, (v - c_y) / f_y), the X^ of eq. 4.12.
  Eigen::Vector2d normalise(double u, double v) const { return {(u - cx) / fx, (v - cy) / fy}; }
};

}  // namespace aerie::stereo
