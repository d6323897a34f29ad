#include "common/camera/camera_model.hpp"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <stdexcept>

namespace aerie::camera {

std::string to_string(Distortion d) {
  switch (d) {
    case Distortion::None: return "none";
    case Distortion::RadTan: return "radial-tangential";
    case Distortion::Equidistant: return "equidistant";
  }
  return "?";
}

Distortion distortion_from_string(const std::string& name) {
  if (name == "none" || name.empty()) return Distortion::None;
  if (name == "radial-tangential" || name == "radtan" || name == "plumb_bob") return Distortion::RadTan;
  if (name == "equidistant" || name == "fisheye" || name == "kannala-brandt") return Distortion::Equidistant;
  throw std::invalid_argument("unknown distortion model '" + name +
                              "' (expected none, radial-tangential or equidistant)");
}

cv::Mat CameraModel::D() const {
  if (distortion == Distortion::None) return cv::Mat::zeros(1, 4, CV_64F);
  return cv::Mat(coeffs, true).reshape(1, 1);
}

void CameraModel::validate(const std::string& what) const {
  auto bad = [&](const std::string& msg) { throw std::invalid_argument(what + ": " + msg); };
  if (width <= 0 || height <= 0) bad("resolution must be positive, got " + std::to_string(width) + "x" + std::to_string(height));
  // The rectifier's maps and the renderers allocate per pixel: bound the size by what a camera
  // has (a 61 MP full-frame sensor is 9504 x 6336), not by what an int holds.
  if (width > kMaxSide || height > kMaxSide || int64_t{width} * height > kMaxPixels)
    bad("resolution " + std::to_string(width) + "x" + std::to_string(height) + " exceeds " +
        std::to_string(kMaxSide) + " pixels a side or " + std::to_string(kMaxPixels) + " pixels");
  for (double v : {fx, fy, cx, cy}) {
    if (!std::isfinite(v)) bad("intrinsics are not finite");
  }
  if (fx <= 0 || fy <= 0) bad("focal lengths must be positive");
  if (cx < 0 || cx > width || cy < 0 || cy > height) bad("principal point lies outside the image");
  for (double c : coeffs) {
    if (!std::isfinite(c)) bad("distortion coefficients are not finite");
  }
  if (distortion == Distortion::RadTan && coeffs.size() != 4 && coeffs.size() != 5 && coeffs.size() != 8)
    bad("radial-tangential distortion needs 4, 5 or 8 coefficients, got " + std::to_string(coeffs.size()));
  if (distortion == Distortion::Equidistant && coeffs.size() != 4)
    bad("equidistant distortion needs 4 coefficients, got " + std::to_string(coeffs.size()));
}

Eigen::Vector2d CameraModel::project(const Eigen::Vector3d& p) const {
  std::vector<cv::Point3d> obj{{p.x(), p.y(), p.z()}};
  std::vector<cv::Point2d> img;
  const cv::Vec3d zero(0, 0, 0);
  if (distortion == Distortion::Equidistant) {
    cv::fisheye::projectPoints(obj, img, zero, zero, K(), D());
  } else {
    cv::projectPoints(obj, zero, zero, K(), D(), img);
  }
  return {img[0].x, img[0].y};
}

Eigen::Vector3d CameraModel::unproject(const Eigen::Vector2d& uv) const {
  std::vector<cv::Point2d> in{{uv.x(), uv.y()}}, out;
  if (distortion == Distortion::Equidistant) {
    cv::fisheye::undistortPoints(in, out, K(), D());
  } else {
    cv::undistortPoints(in, out, K(), D(), cv::noArray(), cv::noArray(),
                        cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 50, 1e-12));
  }
  return {out[0].x, out[0].y, 1.0};
}

void StereoCalibration::validate() const {
  left.validate(source + " (left camera)");
  right.validate(source + " (right camera)");
  if (left.size() != right.size())
    throw std::invalid_argument(source + ": left and right resolutions differ");
  const double b = baseline();
  if (!std::isfinite(b) || b < 1e-4)
    throw std::invalid_argument(source + ": stereo baseline is zero or not finite");
}

}  // namespace aerie::camera
