#pragma once
// Trajectory error metrics, checked against evo (Grupp, github.com/MichaelGrupp/evo):
//  * ATE / APE: translation error after least-squares alignment (Umeyama 1991);
//  * RPE: error of the relative motion between pose pairs (i, j), E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j),
//    pairs every `delta` frames or, as evo's `--delta_unit m`, every `delta` metres of the
//    estimated path (consecutive pairs);
//  * per-axis RMSE (x, y, z; roll, pitch, yaw) as thesis Table 4.1;
//  * end-point drift sqrt(X_F^2 + Y_F^2 + Z_F^2) of a closed loop (thesis eq. 4.18).
#include <Eigen/Core>
#include <string>
#include <vector>

#include "common/geometry/se3.hpp"
#include "tools/eval/trajectory.hpp"

namespace aerie::eval {

struct Stats {
  size_t count = 0;
  double rmse = 0, mean = 0, median = 0, std = 0, min = 0, max = 0, sse = 0;
};
Stats statistics(const std::vector<double>& values);

enum class Alignment { None, SE3, Sim3 };
Alignment alignment_from_string(const std::string& name);  // "none", "se3", "sim3"

// Umeyama: the similarity (s, R, t) minimising sum |ref_i - (s R est_i + t)|^2.
// with_scale = false fixes s = 1 (SE3). Needs >= 3 non-collinear points for a unique R.
struct Similarity {
  double scale = 1.0;
  geometry::SE3 transform;  // rotation and translation
  Eigen::Vector3d apply(const Eigen::Vector3d& p) const { return transform.rotation() * (scale * p) + transform.translation(); }
};
Similarity umeyama(const std::vector<Eigen::Vector3d>& est, const std::vector<Eigen::Vector3d>& ref, bool with_scale);

// est aligned onto ref (same length, pose i <-> pose i). Orientations are rotated, positions
// transformed (and scaled for Sim3).
Trajectory align(const Trajectory& est, const Trajectory& ref, Alignment alignment, Similarity* used = nullptr);

// Absolute trajectory error: per-pose translation error (m) of the aligned estimate.
std::vector<double> ate_errors(const Trajectory& ref, const Trajectory& aligned_est);

struct RelativeErrors {
  std::vector<std::pair<size_t, size_t>> pairs;
  std::vector<double> translation;   // |t(E)| metres
  std::vector<double> rotation_deg;  // angle(E)
  std::vector<double> ref_distance;  // |t(Q_i^-1 Q_j)| metres (for percentages)
  // 100 * sum |t(E)| / sum |t(Q_i^-1 Q_j)|: translational error as a percentage of the distance
  // travelled (a ratio of sums, so frames where the vehicle stands still do not dominate).
  double translation_percent() const;
};
// Pairs (i, i + delta_frames) for every i.
RelativeErrors rpe_frames(const Trajectory& ref, const Trajectory& est, size_t delta_frames);
// evo's delta in metres: consecutive pairs whose estimated path length between them reaches delta_m.
RelativeErrors rpe_path(const Trajectory& ref, const Trajectory& est, double delta_m);

// Per-axis RMSE of position (metres, of the aligned estimate) and orientation (roll, pitch, yaw in
// degrees of the error between the rotations since the first pose, R_ref0^T R_ref vs R_est0^T R_est).
struct AxisRmse {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d rpy_deg = Eigen::Vector3d::Zero();
};
AxisRmse per_axis_rmse(const Trajectory& ref, const Trajectory& aligned_est);

// Roll, pitch, yaw (rad) of R = Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Vector3d roll_pitch_yaw(const Eigen::Matrix3d& R);

// A loop: the trajectory ends within max(kLoopRadiusM, kLoopPathFraction * path length) of its
// start (a sequence standing still is one). Only then is the end point's distance from the start
// a drift (eq. 4.18).
inline constexpr double kLoopRadiusM = 0.5, kLoopPathFraction = 0.1;
bool is_loop(const Trajectory& t);

// End-point drift: |p_end - p_start| of the estimate relative to its first pose (eq. 4.18, for
// loops returning to the start) and, when a reference is given, |p_end_est - p_end_ref| with
// both expressed in their first pose's frame.
struct Drift {
  bool loop = false;           // is_loop of the reference (of the estimate if no reference)
  double loop_closure_m = 0;   // sqrt(X_F^2 + Y_F^2 + Z_F^2), est end in est start frame
  double vs_reference_m = 0;   // est end vs ref end, both relative to their start
  double distance_m = 0;       // reference path length (estimate's if no reference)
  double percent() const { return distance_m > 0 ? 100.0 * vs_reference_m / distance_m : 0.0; }
};
Drift end_point_drift(const Trajectory& ref, const Trajectory& est);

}  // namespace aerie::eval
