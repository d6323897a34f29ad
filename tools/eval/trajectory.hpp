#pragma once
// Trajectories for evaluation: timestamped poses T_world_body, read from and written
// to the TUM format ("t x y z qx qy qz qw", '#' comments) and read from KITTI pose
// files (12 floats per line, row-major 3x4 [R|t], frame i in frame 0).
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

// Reads TUM or KITTI by content (a KITTI line has 12 numbers, a TUM line 8).
Trajectory read_trajectory(const std::string& path);

// Pairs of poses with |t_est - t_ref| <= max_dt (each used at most once, nearest in
// time, as evo's associate); returns the two matched trajectories in time order.
// Throws when nothing matches.
struct Associated {
  Trajectory ref, est;
};
Associated associate(const Trajectory& ref, const Trajectory& est, double max_dt = 0.01);

}  // namespace aerie::eval
