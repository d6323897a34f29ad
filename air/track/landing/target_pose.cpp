#include "air/track/landing/target_pose.hpp"

#include <cmath>
#include <stdexcept>

namespace aerie::track {

TargetPose target_pose(const TrackState& track, const camera::CameraModel& camera, const TargetGeometry& target) {
  if (!(target.width_m > 0) || !(target.height_m > 0))
    throw std::invalid_argument("target pose: the target's width and height must be > 0 metres");
  if (!(camera.fx > 0) || !(camera.fy > 0)) throw std::invalid_argument("target pose: camera focal lengths must be > 0");
  const cv::Size2d size = track.size();
  if (!(size.width > 0) || !(size.height > 0) || !std::isfinite(track.pose.x) || !std::isfinite(track.pose.y))
    throw std::invalid_argument("target pose: the track has no finite position and size");
  // Range from the apparent size along each image axis; their geometric mean uses the area.
  const double zw = camera.fx * target.width_m / size.width;
  const double zh = camera.fy * target.height_m / size.height;
  const double z = std::sqrt(zw * zh);
  const Eigen::Vector3d ray = camera.unproject({track.pose.x, track.pose.y});  // (x/z, y/z, 1)
  TargetPose out;
  out.position = z * ray;
  out.yaw = std::remainder(track.pose.theta + target.yaw_offset, 2 * M_PI);
  return out;
}

}  // namespace aerie::track
