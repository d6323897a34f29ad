#pragma once
// Pinhole camera with optional lens distortion, and a calibrated stereo rig.
#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "common/geometry/se3.hpp"

namespace aerie::camera {

enum class Distortion {
  None,         // already rectified / ideal pinhole
  RadTan,       // radial-tangential (Brown-Conrady): k1 k2 p1 p2 [k3], OpenCV's default model
  Equidistant,  // Kannala-Brandt / OpenCV fisheye: k1 k2 k3 k4
};

std::string to_string(Distortion d);
Distortion distortion_from_string(const std::string& name);  // throws on unknown names

struct CameraModel {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  Distortion distortion = Distortion::None;
  std::vector<double> coeffs;

  cv::Size size() const { return {width, height}; }
  cv::Matx33d K() const { return {fx, 0, cx, 0, fy, cy, 0, 0, 1}; }
  cv::Mat D() const;  // distortion coefficients as OpenCV wants them

  // Largest image a camera model may have (validate refuses more).
  static constexpr int kMaxSide = 16384;
  static constexpr int64_t kMaxPixels = int64_t{1} << 26;  // 67 MP
  // Throws std::invalid_argument naming `what` and the bad field.
  void validate(const std::string& what) const;

  // Camera-frame point (z > 0) to distorted pixel coordinates.
  Eigen::Vector2d project(const Eigen::Vector3d& p) const;
  // Distorted pixel to the normalised undistorted ray (x, y, 1).
  Eigen::Vector3d unproject(const Eigen::Vector2d& uv) const;
};

struct StereoCalibration {
  CameraModel left;
  CameraModel right;
  geometry::SE3 T_right_left;  // p_right = T_right_left * p_left
  std::string source;          // file(s) it was read from, for error messages

  double baseline() const { return T_right_left.translation().norm(); }
  void validate() const;
};

}  // namespace aerie::camera
