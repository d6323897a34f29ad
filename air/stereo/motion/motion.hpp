#pragma once
// 6-DoF motion between consecutive stereo frames from both kinds of tracked features
// (thesis "6-DOF Motion Estimation of Stereo Camera"): features with depth in frame k
// (3D -> 2D, eqs. 4.14-4.15) and features without (2D -> 2D, eq. 4.16), M = [w; t] on
// so(3) x R^3, solved by Levenberg-Marquardt (Ceres) with a robust loss, initialised by
// RANSAC P3P on the 3D -> 2D set, outliers rejected and the problem solved again.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "air/stereo/motion/stereo_camera.hpp"
#include "common/geometry/se3.hpp"

namespace aerie::stereo {

struct Correspondence3D {
  Eigen::Vector3d X_k;     // point in frame k (left camera, metres)
  Eigen::Vector2d x_next;  // normalised image coordinates in frame k+1
};
struct Correspondence2D {
  Eigen::Vector2d x_k;     // normalised image coordinates in frame k
  Eigen::Vector2d x_next;  // ... and in frame k+1
};

struct MotionParams {
  int ransac_iterations = 100;
  double ransac_threshold_px = 2.0;  // reprojection error of an inlier in RANSAC
  double inlier_threshold_px = 2.0;  // residual (pixels) above which a feature is rejected after LM
  double inlier_threshold_2d_px = 1.0;  // the same for features without depth (epipolar distance)
  double huber_px = 1.0;             // robust loss scale (pixels)
  double weight_2d = 1.0;            // weight of the 2D -> 2D residuals relative to the 3D ones
  int max_iterations = 20;           // LM iterations per round
  int rounds = 2;                    // solve, reject outliers, solve again
  int min_3d = 6;                    // fewer 3D correspondences: no estimate (scale unobservable)
  void validate(const std::string& what = "motion") const;
};

struct MotionResult {
  bool ok = false;
  std::string failure;                    // why not ok
  geometry::SE3 T_next_k;                 // X^{k+1} = R X^k + t
  Eigen::Matrix<double, 6, 6> covariance  // over [w; t], from the final Jacobian
      = Eigen::Matrix<double, 6, 6>::Identity();
  std::vector<bool> inlier_3d, inlier_2d;
  int inliers_3d = 0, inliers_2d = 0;
  double rms_px = 0;                      // of the inlier residuals
  int iterations = 0;
};

class MotionEstimator {
 public:
  explicit MotionEstimator(const MotionParams& params = {});
  // `prior` (optional) is a guess of T_next_k (e.g. the previous motion); RANSAC keeps
  // whichever of the prior and its own hypothesis explains more features.
  MotionResult estimate(const StereoCamera& cam, const std::vector<Correspondence3D>& c3,
                        const std::vector<Correspondence2D>& c2,
                        const std::optional<geometry::SE3>& prior = std::nullopt) const;
  const MotionParams& params() const { return params_; }

 private:
  MotionParams params_;
};

}  // namespace aerie::stereo
