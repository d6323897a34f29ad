#pragma once
// Synthetic pinhole (or distorted) views of a fiducial board at a known pose, for the fiducial
// tests and bench: the board's image (render_board) is sampled where every pixel's ray, from
// the camera model's unproject, meets the board's plane, supersampled and box-filtered.
#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "air/track/fiducial/fiducial.hpp"

namespace aerie::track::test {

struct BoardPose {
  Eigen::Matrix3d rotation;  // board axes in the camera frame
  Eigen::Vector3d position;  // board origin in the camera frame (m)
};

// The camera `height` m above the point (ax, ay) of the board, looking straight down with the
// board upright in the image, then turned by `yaw_deg` about its optical axis and tilted by
// `tilt_deg` about its x axis (about the point looked at).
inline BoardPose looking_down(double height, double yaw_deg = 0, double tilt_deg = 0, double ax = 0, double ay = 0) {
  const double d2r = M_PI / 180;
  const Eigen::Matrix3d down = Eigen::Vector3d(1, -1, -1).asDiagonal();  // board x -> image x, board y -> image up
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(tilt_deg * d2r, Eigen::Vector3d::UnitX()) *
                             Eigen::AngleAxisd(yaw_deg * d2r, Eigen::Vector3d::UnitZ()))
                                .toRotationMatrix() *
                            down;
  // The aimed point sits on the optical axis at `height`.
  return {R, Eigen::Vector3d(0, 0, height) - R * Eigen::Vector3d(ax, ay, 0)};
}

inline cv::Mat render_view(const BoardImage& board, const camera::CameraModel& camera, const BoardPose& pose,
                           int supersample = 3, uint8_t background = 128) {
  camera::CameraModel hi = camera;  // the same lens at s x the resolution (pixel centres kept)
  const int s = supersample;
  hi.width *= s, hi.height *= s;
  hi.fx *= s, hi.fy *= s;
  hi.cx = hi.cx * s + (s - 1) / 2.0, hi.cy = hi.cy * s + (s - 1) / 2.0;
  cv::Mat mapx(hi.height, hi.width, CV_32F), mapy(hi.height, hi.width, CV_32F);
  const Eigen::Matrix3d Rt = pose.rotation.transpose();
  const Eigen::Vector3d o = -Rt * pose.position;  // camera centre in the board frame
  const double half = board.side_m / 2, ppm = board.pixels_per_metre;
  for (int v = 0; v < hi.height; ++v)
    for (int u = 0; u < hi.width; ++u) {
      // The pinhole's ray directly (unproject iterates for a distorted lens).
      const Eigen::Vector3d ray = hi.distortion == camera::Distortion::None
                                      ? Eigen::Vector3d((u - hi.cx) / hi.fx, (v - hi.cy) / hi.fy, 1)
                                      : hi.unproject({u, v});
      const Eigen::Vector3d d = Rt * ray;
      const double lambda = -o.z() / d.z();
      float x = -1e6f, y = -1e6f;
      if (std::isfinite(lambda) && lambda > 0) {
        const Eigen::Vector3d p = o + lambda * d;
        x = static_cast<float>((p.x() + half) * ppm - 0.5);
        y = static_cast<float>((half - p.y()) * ppm - 0.5);
      }
      mapx.at<float>(v, u) = x;
      mapy.at<float>(v, u) = y;
    }
  cv::Mat big, out;
  cv::remap(board.image, big, mapx, mapy, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(background));
  cv::resize(big, out, camera.size(), 0, 0, cv::INTER_AREA);
  return out;
}

inline camera::CameraModel vga_camera() {
  camera::CameraModel c;
  c.width = 640, c.height = 480;
  c.fx = c.fy = 500;
  c.cx = 319.5, c.cy = 239.5;
  return c;
}

// Angle of the rotation between two rotation matrices, degrees.
inline double rotation_error_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() * 180 / M_PI;
}

}  // namespace aerie::track::test
