#pragma once
// Conversion between SphericalDepth and the VO_DEPTH message (aerie.spherical_depth_t).
// Kept apart from the core library so that aerie_spherical has no LCM dependency.
#include <aerie/spherical_depth_t.hpp>

#include <cstdint>
#include <optional>

#include "common/geometry/se3.hpp"
#include "common/spherical/spherical_depth.hpp"

namespace aerie::spherical {

// The message of one frame; T_world_camera is the frame's pose (nullopt: has_pose = false).
// Chooses the smaller of the sparse and the dense layout (see the .lcm file).
aerie::spherical_depth_t to_message(const SphericalDepth& depth, int64_t utime, int64_t seq,
                                    const std::optional<geometry::SE3>& T_world_camera);

// Decodes and validates a message; throws std::invalid_argument naming the field.
SphericalDepth from_message(const aerie::spherical_depth_t& msg);

// The pose carried by the message (nullopt when has_pose is false); throws
// std::invalid_argument when it is set but not finite or not a unit quaternion.
std::optional<geometry::SE3> pose_of(const aerie::spherical_depth_t& msg);

}  // namespace aerie::spherical
