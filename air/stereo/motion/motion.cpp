#include "air/stereo/motion/motion.hpp"

#include <ceres/ceres.h>
#include <opencv2/calib3d.hpp>

#include <Eigen/Cholesky>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "air/stereo/motion/residuals.hpp"

namespace aerie::stereo {
namespace {

// Eqs. 4.14-4.15 scaled by (f_x, f_y) / z^{k+1} (depth in frame k+1 under the current
// estimate, held constant during a solve): near the solution each is the reprojection error
// in pixels, so near and far features weigh alike.
struct Cost3D {
  Eigen::Vector3d X;
  Eigen::Vector2d x;
  double sx, sy;
  template <typename T>
  bool operator()(const T* w, const T* t, T* r) const {
    residual_3d(w, t, X, x, r);
    r[0] *= T(sx);
    r[1] *= T(sy);
    return true;
  }
};

// Eq. 4.16 scaled by f / |(l_1, l_2)|, l = t x R X^k the epipolar line of the feature in frame
// k+1 under the current estimate (held constant during a solve): the residual is then the
// distance (pixels) of the feature from its epipolar line.
struct Cost2D {
  Eigen::Vector2d xk, xn;
  double s;
  template <typename T>
  bool operator()(const T* w, const T* t, T* r) const {
    residual_2d(w, t, xk, xn, r);
    r[0] *= T(s);
    return true;
  }
};

}  // namespace

void MotionParams::validate(const std::string& what) const {
  if (ransac_iterations < 1 || max_iterations < 1 || rounds < 1)
    throw std::invalid_argument(what + ": ransac_iterations, max_iterations and rounds must be >= 1");
  if (!(ransac_threshold_px > 0) || !(inlier_threshold_px > 0) || !(huber_px > 0))
    throw std::invalid_argument(what + ": thresholds must be positive");
  if (weight_2d < 0) throw std::invalid_argument(what + ".weight_2d: >= 0");
  if (min_3d < 4) throw std::invalid_argument(what + ".min_3d: at least 4 (P3P + 1)");
}

MotionEstimator::MotionEstimator(const MotionParams& params) : params_(params) { params_.validate(); }

MotionResult MotionEstimator::estimate(const StereoCamera& cam, const std::vector<Correspondence3D>& c3,
                                       const std::vector<Correspondence2D>& c2,
                                       const std::optional<geometry::SE3>& prior) const {
  MotionResult res;
  res.inlier_3d.assign(c3.size(), false);
  res.inlier_2d.assign(c2.size(), false);
  if (static_cast<int>(c3.size()) < params_.min_3d) {
    res.failure = "only " + std::to_string(c3.size()) + " features with depth (need " +
                  std::to_string(params_.min_3d) + ")";
    return res;
  }
  const double f = 0.5 * (cam.fx + cam.fy);

  // 1. Initial motion: RANSAC P3P on the 3D -> 2D set (normalised coordinates, K = I).
  std::vector<cv::Point3d> obj;
  std::vector<cv::Point2d> img;
  for (const auto& c : c3) {
    obj.emplace_back(c.X_k.x(), c.X_k.y(), c.X_k.z());
    img.emplace_back(c.x_next.x(), c.x_next.y());
  }
  auto count_inliers = [&](const geometry::SE3& T, double thr_px, std::vector<bool>* mask) {
    int n = 0;
    for (size_t i = 0; i < c3.size(); ++i) {
      const Eigen::Vector3d p = T * c3[i].X_k;
      const bool in = p.z() > 0 && (f * (p.head<2>() / p.z() - c3[i].x_next)).norm() < thr_px;
      if (mask) (*mask)[i] = in;
      n += in;
    }
    return n;
  };
  geometry::SE3 init;
  int best = -1;
  {
    cv::Mat rvec, tvec;
    std::vector<int> inl;
    const bool found = cv::solvePnPRansac(obj, img, cv::Matx33d::eye(), cv::noArray(), rvec, tvec, false,
                                          params_.ransac_iterations, params_.ransac_threshold_px / f, 0.999, inl,
                                          cv::SOLVEPNP_AP3P);
    if (found) {
      init = geometry::SE3::from_rotation_vector(
          Eigen::Vector3d(rvec.at<double>(0), rvec.at<double>(1), rvec.at<double>(2)),
          Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2)));
      best = count_inliers(init, params_.ransac_threshold_px, nullptr);
    }
  }
  if (prior) {
    const int n = count_inliers(*prior, params_.ransac_threshold_px, nullptr);
    if (n > best) {
      best = n;
      init = *prior;
    }
  }
  if (best < params_.min_3d) {
    res.failure = "RANSAC found " + std::to_string(std::max(best, 0)) + " consistent features with depth of " +
                  std::to_string(c3.size());
    return res;
  }

  // 2. Levenberg-Marquardt over M = [w; t] with both residual kinds, robust loss; reject the
  //    features whose residual exceeds the threshold and solve again.
  Eigen::Vector3d w = geometry::so3_log(init.rotation_matrix());
  Eigen::Vector3d t = init.translation();
  std::vector<bool> use3(c3.size()), use2(c2.size(), true);
  count_inliers(init, params_.ransac_threshold_px, &res.inlier_3d);
  use3 = res.inlier_3d;
  // Per-feature weights from the current estimate (recomputed before every solve).
  std::vector<double> w3(c3.size()), w2(c2.size());
  auto update_weights = [&] {
    const Eigen::Matrix3d R = geometry::so3_exp<double>(w);
    for (size_t i = 0; i < c3.size(); ++i) w3[i] = 1.0 / std::max(0.05, (R * c3[i].X_k + t).z());
    for (size_t i = 0; i < c2.size(); ++i) {
      const Eigen::Vector3d l = t.cross(R * Eigen::Vector3d(c2[i].x_k.x(), c2[i].x_k.y(), 1.0));
      // Below 5 mm of translation the epipolar geometry carries no information: cap the weight.
      w2[i] = params_.weight_2d * f / std::max(l.head<2>().norm(), 0.005);
    }
  };
  auto cost3 = [&](size_t i) { return new Cost3D{c3[i].X_k, c3[i].x_next, cam.fx * w3[i], cam.fy * w3[i]}; };
  auto cost2 = [&](size_t i) { return new Cost2D{c2[i].x_k, c2[i].x_next, w2[i]}; };
  update_weights();
  ceres::HuberLoss loss(params_.huber_px);
  ceres::Solver::Options opts;
  opts.linear_solver_type = ceres::DENSE_QR;
  opts.max_num_iterations = params_.max_iterations;
  opts.logging_type = ceres::SILENT;
  opts.num_threads = 1;
  ceres::Problem::Options popts;
  popts.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  popts.enable_fast_removal = false;

  const double thr2 = params_.inlier_threshold_px * params_.inlier_threshold_px;
  std::vector<double> r3(2 * c3.size()), r2(c2.size());
  auto residuals_at = [&](const double* wp, const double* tp) {
    for (size_t i = 0; i < c3.size(); ++i) {
      const std::unique_ptr<Cost3D> c(cost3(i));
      (*c)(wp, tp, &r3[2 * i]);
    }
    for (size_t i = 0; i < c2.size(); ++i) {
      const std::unique_ptr<Cost2D> c(cost2(i));
      (*c)(wp, tp, &r2[i]);
    }
  };
  // 2D features start as inliers only if the initial motion already roughly satisfies them.
  residuals_at(w.data(), t.data());
  for (size_t i = 0; i < c2.size(); ++i) use2[i] = std::abs(r2[i]) < 3 * params_.weight_2d * params_.inlier_threshold_2d_px;

  for (int round = 0; round < params_.rounds; ++round) {
    if (round > 0) update_weights();
    ceres::Problem problem(popts);
    for (size_t i = 0; i < c3.size(); ++i)
      if (use3[i])
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<Cost3D, 2, 3, 3>(cost3(i)), &loss, w.data(), t.data());
    if (params_.weight_2d > 0)
      for (size_t i = 0; i < c2.size(); ++i)
        if (use2[i])
          problem.AddResidualBlock(new ceres::AutoDiffCostFunction<Cost2D, 1, 3, 3>(cost2(i)), &loss, w.data(),
                                   t.data());
    ceres::Solver::Summary summary;
    ceres::Solve(opts, &problem, &summary);
    res.iterations += static_cast<int>(summary.iterations.size());

    update_weights();
    residuals_at(w.data(), t.data());
    res.inliers_3d = res.inliers_2d = 0;
    for (size_t i = 0; i < c3.size(); ++i) {
      res.inlier_3d[i] = r3[2 * i] * r3[2 * i] + r3[2 * i + 1] * r3[2 * i + 1] < thr2;
      res.inliers_3d += res.inlier_3d[i];
    }
    for (size_t i = 0; i < c2.size(); ++i) {
      res.inlier_2d[i] = params_.weight_2d > 0 && std::abs(r2[i]) < params_.weight_2d * params_.inlier_threshold_2d_px;
      res.inliers_2d += res.inlier_2d[i];
    }
    use3 = res.inlier_3d;
    use2 = res.inlier_2d;
    if (res.inliers_3d < params_.min_3d) {
      res.failure = "only " + std::to_string(res.inliers_3d) + " features with depth fit the motion";
      return res;
    }
  }

  // 3. Covariance of M from the Jacobian of the inlier residuals: sigma^2 (J^T J)^-1.
  Eigen::Matrix<double, 6, 6> JtJ = Eigen::Matrix<double, 6, 6>::Zero();
  double sse = 0;
  int m = 0;
  {
    const double* params[2] = {w.data(), t.data()};
    double r[2], j_w[6], j_t[6];
    double* jac[2] = {j_w, j_t};
    auto add = [&](const ceres::CostFunction& cf, int nres) {
      cf.Evaluate(params, r, jac);
      for (int k = 0; k < nres; ++k) {
        Eigen::Matrix<double, 6, 1> row;
        row << j_w[3 * k], j_w[3 * k + 1], j_w[3 * k + 2], j_t[3 * k], j_t[3 * k + 1], j_t[3 * k + 2];
        JtJ += row * row.transpose();
        sse += r[k] * r[k];
        ++m;
      }
    };
    for (size_t i = 0; i < c3.size(); ++i)
      if (res.inlier_3d[i]) add(ceres::AutoDiffCostFunction<Cost3D, 2, 3, 3>(cost3(i)), 2);
    for (size_t i = 0; i < c2.size(); ++i)
      if (res.inlier_2d[i]) add(ceres::AutoDiffCostFunction<Cost2D, 1, 3, 3>(cost2(i)), 1);
  }
  res.rms_px = std::sqrt(sse / std::max(1, m));
  const double sigma2 = sse / std::max(1, m - 6);
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(JtJ);
  if (ldlt.info() == Eigen::Success) res.covariance = sigma2 * ldlt.solve(Eigen::Matrix<double, 6, 6>::Identity());
  res.T_next_k = geometry::SE3::from_rotation_vector(w, t);
  res.ok = true;
  return res;
}

}  // namespace aerie::stereo
