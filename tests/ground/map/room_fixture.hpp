#pragma once
// A small analytic room (walls, floor, ceiling and one box) and an exact depth renderer
// for the mapping tests: the ground truth is the geometry itself.
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "common/geometry/se3.hpp"
#include "common/spherical/spherical_depth.hpp"

namespace aerie::map::test {

struct Box {
  Eigen::Vector3d min, max;
};

struct Room {
  Box interior{{-3.0, -2.5, 0.0}, {3.0, 2.5, 2.5}};
  Box obstacle{{0.8, -0.6, 0.0}, {1.6, 0.4, 1.2}};

  // Distance of p to the nearest surface (walls, floor, ceiling, box faces).
  double surface_distance(const Eigen::Vector3d& p) const {
    double d = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 3; ++i) d = std::min({d, std::abs(p[i] - interior.min[i]), std::abs(p[i] - interior.max[i])});
    const Eigen::Vector3d q = p.cwiseMax(obstacle.min).cwiseMin(obstacle.max);  // closest point of the box
    const bool inside = (p.array() >= obstacle.min.array()).all() && (p.array() <= obstacle.max.array()).all();
    if (inside) {
      for (int i = 0; i < 3; ++i) d = std::min({d, p[i] - obstacle.min[i], obstacle.max[i] - p[i]});
    } else {
      d = std::min(d, (p - q).norm());
    }
    return d;
  }
  bool solid(const Eigen::Vector3d& p) const {
    const bool in_room = (p.array() > interior.min.array()).all() && (p.array() < interior.max.array()).all();
    const bool in_box = (p.array() > obstacle.min.array()).all() && (p.array() < obstacle.max.array()).all();
    return !in_room || in_box;
  }
  // First surface along o + t d (o inside the room).
  double raycast(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
    double t = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 3; ++i) {
      if (d[i] > 0) t = std::min(t, (interior.max[i] - o[i]) / d[i]);
      if (d[i] < 0) t = std::min(t, (interior.min[i] - o[i]) / d[i]);
    }
    // Slab test for the box.
    double t0 = 0, t1 = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 3; ++i) {
      if (d[i] == 0) {
        if (o[i] < obstacle.min[i] || o[i] > obstacle.max[i]) return t;
        continue;
      }
      double a = (obstacle.min[i] - o[i]) / d[i], b = (obstacle.max[i] - o[i]) / d[i];
      if (a > b) std::swap(a, b);
      t0 = std::max(t0, a);
      t1 = std::min(t1, b);
    }
    if (t0 <= t1 && t0 > 0) t = std::min(t, t0);
    return t;
  }
};

// Camera looking along the body x axis (x forward, y left, z up) from `position` with `yaw`
// (rad): T_world_camera maps camera (x right, y down, z forward) to world.
inline geometry::SE3 camera_pose(const Eigen::Vector3d& position, double yaw, double pitch = 0.0) {
  Eigen::Matrix3d body_from_camera;
  body_from_camera << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  const Eigen::Matrix3d R_world_body =
      (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()))
          .toRotationMatrix();
  return geometry::SE3(Eigen::Matrix3d(R_world_body * body_from_camera), position);
}

// Exact depth (z along the optical axis) of the room seen from T_world_camera.
inline cv::Mat render_depth(const Room& room, const geometry::SE3& T_world_camera, const spherical::Intrinsics& k,
                            cv::Size size) {
  cv::Mat depth(size, CV_32F);
  const Eigen::Matrix3d R = T_world_camera.rotation_matrix();
  for (int v = 0; v < size.height; ++v)
    for (int u = 0; u < size.width; ++u) {
      const Eigen::Vector3d ray_c((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);  // z = 1
      const double t = room.raycast(T_world_camera.translation(), R * ray_c);
      depth.at<float>(v, u) = static_cast<float>(t);
    }
  return depth;
}

}  // namespace aerie::map::test
