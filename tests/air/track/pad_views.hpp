#pragma once
// Simulated down-looking views of the helipad at a known pose (for the pad pose tests).
#include <Eigen/Geometry>

#include <cmath>

#include "common/sim/simulation.hpp"

namespace aerie::track::test {

struct PadView {
  sim::StereoFrame frame;              // frame.left is the image; target_* the pad's ground truth
  camera::CameraModel camera;          // the left camera
  Eigen::Vector3d position;            // true pad centre in the camera optical frame (m)
  Eigen::Matrix3d rotation;            // true pad axes in the camera optical frame
  double yaw = 0;                      // true yaw of the pad's +x about the optical axis, (-pi/2, pi/2]

  // Pixel of a point on the pad (metres along the pad's x and y from its centre).
  cv::Point2d pixel(double x, double y) const {
    const Eigen::Vector2d uv = camera.project(rotation * Eigen::Vector3d(x, y, 0) + position);
    return {uv.x(), uv.y()};
  }
};

inline double wrap_half_turn(double a) {
  a = std::remainder(a, M_PI);
  return a <= -M_PI / 2 ? a + M_PI : a;
}

// The vehicle (heading, roll, pitch in degrees) with the landing rig's camera looking at the
// point `aim` (metres from the pad centre along world x, y) from `height` above the floor.
inline PadView pad_view(const sim::StereoRenderer& renderer, double height, double heading_deg, double roll_deg,
                        double pitch_deg, Eigen::Vector2d aim = {0.04, -0.03}, int64_t seq = 0,
                        const Eigen::Vector3d& velocity = Eigen::Vector3d::Zero()) {
  const double d2r = M_PI / 180;
  const Eigen::Matrix3d R_wb = (Eigen::AngleAxisd(heading_deg * d2r, Eigen::Vector3d::UnitZ()) *
                                Eigen::AngleAxisd(pitch_deg * d2r, Eigen::Vector3d::UnitY()) *
                                Eigen::AngleAxisd(roll_deg * d2r, Eigen::Vector3d::UnitX()))
                                   .toRotationMatrix();
  const Eigen::Matrix3d R_wc = R_wb * sim::body_to_left(renderer.rig()).rotation_matrix();
  const sim::Helipad& pad = renderer.world().helipad();
  const Eigen::Vector3d target = pad.center + Eigen::Vector3d(aim.x(), aim.y(), 0);
  const Eigen::Vector3d axis = R_wc.col(2);                      // optical axis in the world
  const Eigen::Vector3d eye = target - axis * (height / -axis.z());  // on the axis, `height` above the floor
  const geometry::SE3 T_world_left(Eigen::Quaterniond(R_wc), eye);
  std::vector<geometry::SE3> blur;  // motion blur: the poses over the exposure (10 ms)
  if (!velocity.isZero())
    for (int k = 0; k < 5; ++k) blur.emplace_back(Eigen::Quaterniond(R_wc), eye - velocity * (0.01 * k / 4));
  PadView v;
  v.frame = renderer.render(T_world_left, seq * 50'000, seq, blur);
  v.camera = renderer.intrinsics().calibration().left;
  v.position = T_world_left.inverse() * pad.center;
  v.rotation = R_wc.transpose() * Eigen::AngleAxisd(pad.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d x_cam = v.rotation.col(0);
  v.yaw = wrap_half_turn(std::atan2(x_cam.y(), x_cam.x()));
  return v;
}

// A box grown by `margin` times its size on every side and moved by `shift` pixels.
inline cv::Rect2d grown(const cv::Rect2d& b, double margin, cv::Point2d shift = {0, 0}) {
  return {b.x - margin * b.width + shift.x, b.y - margin * b.height + shift.y, b.width * (1 + 2 * margin),
          b.height * (1 + 2 * margin)};
}

}  // namespace aerie::track::test
