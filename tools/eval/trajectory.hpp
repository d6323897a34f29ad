#pragma once
// Trajectories for evaluation: timestamped poses T_world_body, read from and written
// to the TUM format ("t x y z qx qy qz qw", '#' comments), read from KITTI pose files (12
// floats per line, row-major 3x4 [R|t], frame i in frame 0) and EuRoC ground-truth CSVs.
#include <string>
#include <vector>

#include "common/geometry/se3.hpp"

namespace aerie::eval {

struct Trajectory {
  std::vector<double> stamps;              // seconds
  std::vector<geometry::SE3> poses;        // T_world_body
  size_t size() const { return poses.size(); }
  bool empty() const { return poses.empty(); }
  void push_back(double t, const geometry::SE3& T) {
    stamps.push_back(t);
    poses.push_back(T);
  }
  // Sum of the distances between consecutive positions (metres).
  double path_length() const;
  // Cumulative path length at each pose (first entry 0).
  std::vector<double> distances() const;
};

// Throws std::runtime_error naming the file and line on malformed input.
Trajectory read_tum(const std::string& path);
void write_tum(const Trajectory& traj, const std::string& path);

// KITTI poses. times_path "" numbers the poses 0, 1, 2 ... (seconds = index).
Trajectory read_kitti_poses(const std::string& path, const std::string& times_path = "");
void write_kitti_poses(const Trajectory& traj, const std::string& path);

// EuRoC ASL ground truth (mav0/state_groundtruth_estimate0/data.csv, or a motion-capture
// data.csv): "t[ns], px, py, pz, qw, qx, qy, qz[, ...]", header lines starting with '#'.
Trajectory read_euroc_csv(const std::string& path);

enum class TrajectoryFormat { Tum, EurocCsv, KittiPoses };
const char* format_name(TrajectoryFormat f);
// What detect_trajectory_format recognises, for help texts and messages.
inline constexpr const char* kTrajectoryFormats =
    "TUM (8 numbers: t[s] x y z qx qy qz qw), EuRoC CSV (t[ns] integer, px py pz qw qx qy qz, ...) or "
    "KITTI poses (12 numbers: row-major 3x4 [R|t], one line per frame)";
// By the first data row: 12 numbers are KITTI poses; 8 or more starting with an integer
// timestamp >= 1e12 (nanoseconds) are EuRoC CSV; 8 are TUM. Anything else throws naming the
// file and line.
TrajectoryFormat detect_trajectory_format(const std::string& path);
// Reads any of the three by content; KITTI poses take their stamps from kitti_times (a
// times.txt; "" numbers them 0, 1, 2 ...). `found` (optional) receives the format.
Trajectory read_trajectory(const std::string& path, const std::string& kitti_times = "",
                           TrajectoryFormat* found = nullptr);

// Pairs of poses with |t_est - t_ref| <= max_dt (each used at most once, nearest in
// time, as evo's associate); returns the two matched trajectories in time order.
// Throws when nothing matches.
struct Associated {
  Trajectory ref, est;
};
Associated associate(const Trajectory& ref, const Trajectory& est, double max_dt = 0.01);

}  // namespace aerie::eval
