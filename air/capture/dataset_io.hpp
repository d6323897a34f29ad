#pragma once
// Small readers shared by the file-based sources: image listings, timestamp files,
// ground-truth trajectories (TUM, EuRoC ASL CSV, KITTI poses). Errors name the file
// and line.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/geometry/se3.hpp"

namespace aerie::capture {

// Image files of a folder (png, jpg, jpeg, bmp, pgm, ppm, tif, tiff), sorted by name.
// Throws std::runtime_error naming the folder if it does not exist.
std::vector<std::string> list_images(const std::string& dir);

// Decimal seconds to microseconds without floating-point rounding ("1403715273.262143" ->
// 1403715273262143; more than 6 decimals are rounded half up). nullopt if not a number or
// beyond what int64 microseconds hold.
std::optional<int64_t> parse_seconds(const std::string& text);

// One time per line, seconds (first token; '#' comment lines and blank lines skipped).
std::vector<int64_t> read_timestamps(const std::string& file);

// A time-stamped trajectory: poses T_world_x by utime.
using Trajectory = std::map<int64_t, geometry::SE3>;

// TUM: "t x y z qx qy qz qw" (seconds), '#' comments.
Trajectory read_tum(const std::string& file);
// EuRoC ASL state_groundtruth_estimate0/data.csv: "ns, px, py, pz, qw, qx, qy, qz, ...".
Trajectory read_euroc_groundtruth(const std::string& file);
// KITTI poses.txt: one row-major 3x4 [R|t] per line (T_0_i, left camera).
std::vector<geometry::SE3> read_kitti_poses(const std::string& file);

// Pose at utime by linear interpolation of the position and slerp of the rotation
// between the two neighbouring samples; nullopt outside the trajectory or when the
// neighbours are more than max_gap_us apart.
std::optional<geometry::SE3> interpolate(const Trajectory& traj, int64_t utime, int64_t max_gap_us);

}  // namespace aerie::capture

namespace cv {
class Mat;
}
namespace aerie::capture {
// An 8-bit image file as gray (CV_8UC1) or BGR (CV_8UC3). Throws FrameError naming
// the file if it cannot be read.
cv::Mat load_image(const std::string& file, bool color);
}  // namespace aerie::capture
