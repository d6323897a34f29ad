#pragma once
// Two-view initialisation of a monocular map (Mur-Artal et al., ORB-SLAM, IEEE T-RO 2015,
// section IV): a homography H and an essential matrix E are fitted to the same matches
// (OpenCV findHomography / findEssentialMat, RANSAC), each scored by its symmetric transfer
// error (eq. 2 of the paper):
//   S_M = sum_i rho(d^2_cr(x_c, x_r, M)) + rho(d^2_rc(x_c, x_r, M)),
//   rho(d^2) = Gamma - d^2 / sigma^2 if d^2 / sigma^2 < T_M, else 0,
// with T_H = 5.99, T_F = 3.84 (chi-square at 95 %, 2 and 1 degrees of freedom) and
// Gamma = T_H for both, so that the two scores are comparable; d_cr for H is the transfer
// error of x_r into the current image, for E (through F = K^-T E K^-1) the distance of x_c to
// the epipolar line of x_r. R_H = S_H / (S_H + S_F) > homography_ratio (0.45) selects H
// (planar or low-parallax scenes), otherwise E. The chosen model is decomposed
// (decomposeHomographyMat: up to four solutions; recoverPose: the cheirality-checked one),
// every solution's inliers triangulated, and a solution is accepted only when its points
// lie in front of both views, reproject within reprojection_px, enough of them are seen
// under a parallax of at least min_parallax_deg and no other solution comes close (ORB-SLAM's
// ambiguity test). Otherwise the initialisation reports why and waits for a later frame: a
// pure rotation, whatever the model, leaves no parallax and is never guessed.
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <string>
#include <vector>

#include "common/geometry/se3.hpp"

namespace aerie::mono {

struct PinholeCamera {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  int width = 0, height = 0;
  bool operator==(const PinholeCamera&) const = default;
  void validate(const std::string& what = "mono camera") const;
  cv::Matx33d K() const { return {fx, 0, cx, 0, fy, cy, 0, 0, 1}; }
  Eigen::Vector2d project(const Eigen::Vector3d& X) const { return {fx * X.x() / X.z() + cx, fy * X.y() / X.z() + cy}; }
  Eigen::Vector3d ray(const cv::Point2f& p) const { return {(p.x - cx) / fx, (p.y - cy) / fy, 1.0}; }
};

struct TwoViewParams {
  double ransac_px = 1.0;           // RANSAC threshold of findHomography / findEssentialMat (pixels)
  double sigma_px = 1.0;            // sigma of the scores' d^2 / sigma^2
  double homography_ratio = 0.45;   // R_H above this: homography
  double min_parallax_deg = 1.0;    // a triangulated point counts when its rays differ by this much
  double reprojection_px = 2.0;     // triangulated points must reproject within this in both views
  int min_points = 50;              // good triangulated points needed to accept
  double ambiguity = 0.75;          // the second best solution must have fewer than this x the best's points
  void validate(const std::string& what = "init") const;
};

enum class Model { None, Homography, Essential };
const char* to_string(Model m);

struct TwoViewResult {
  bool ok = false;
  std::string reason;                 // why not (when !ok)
  Model model = Model::None;
  double score_h = 0, score_f = 0, ratio_h = 0;
  geometry::SE3 T_cur_ref;            // X_cur = T_cur_ref X_ref, |t| = 1 before scaling
  std::vector<Eigen::Vector3d> points;  // in the reference camera frame, one per match
  std::vector<bool> good;               // triangulated and checked
  int n_good = 0;
  double median_parallax_deg = 0;
};

// ref[i] <-> cur[i] (pixels).
TwoViewResult initialise_two_view(const std::vector<cv::Point2f>& ref, const std::vector<cv::Point2f>& cur,
                                  const PinholeCamera& cam, const TwoViewParams& params);

// Linear (DLT) triangulation of one point from two views (X_cam = T X_world), in the world frame.
// Returns false when the point is at infinity.
bool triangulate(const geometry::SE3& T_c1_w, const geometry::SE3& T_c2_w, const Eigen::Vector3d& ray1,
                 const Eigen::Vector3d& ray2, Eigen::Vector3d& X_world);

// Angle between the two viewing rays of X_world from the camera centres (degrees).
double parallax_deg(const geometry::SE3& T_c1_w, const geometry::SE3& T_c2_w, const Eigen::Vector3d& X_world);

}  // namespace aerie::mono
