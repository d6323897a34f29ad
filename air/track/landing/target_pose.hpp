#pragma once
// 3D pose of a tracked target of known physical size relative to a calibrated camera, as the
// thesis uses it for autonomous landing (3.1.4): a planar target (helipad, landing object)
// seen roughly fronto-parallel (camera looking down at it during the approach). The range
// follows from the apparent size (pinhole: Z = f * W / w), the lateral position from the
// back-projected ray through the track centre, the yaw from the in-plane rotation theta.
#include <Eigen/Core>

#include "air/track/tracker.hpp"
#include "common/camera/camera_model.hpp"

namespace aerie::track {

struct TargetGeometry {
  double width_m = 0;   // physical size of what the init box covered
  double height_m = 0;
  double yaw_offset = 0;  // target yaw when the track was initialised (radians)
};

struct TargetPose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // camera optical frame: x right, y down, z forward (m)
  double yaw = 0;  // rotation of the target about the optical axis, radians
};

// Throws std::invalid_argument when the geometry or the camera is not usable or the track
// has no size.
TargetPose target_pose(const TrackState& track, const camera::CameraModel& camera, const TargetGeometry& target);

}  // namespace aerie::track
