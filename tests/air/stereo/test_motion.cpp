// Triangulation (eq. 4.1), the so(3) exponential map (4.9-4.11), the residuals (4.14-4.16)
// against hand-computed values, and the 2D+3D LM motion on synthetic correspondences.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>

#include "air/stereo/motion/motion.hpp"
#include "air/stereo/motion/residuals.hpp"

using namespace aerie::stereo;
using aerie::geometry::SE3;

namespace {

StereoCamera camera() {
  StereoCamera c;
  c.fx = c.fy = 400;
  c.cx = 188;
  c.cy = 120;
  c.baseline = 0.12;
  c.width = 376;
  c.height = 240;
  return c;
}

struct Scene {
  std::vector<Correspondence3D> c3;
  std::vector<Correspondence2D> c2;
  std::vector<bool> outlier3;
};

// Points in front of the camera at frame k, seen at k+1 after motion T (X' = R X + t).
Scene make_scene(const SE3& T, int n3, int n2, double pixel_noise, double disparity_noise, double outliers,
                 unsigned seed) {
  const StereoCamera cam = camera();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> g(0, 1);
  Scene s;
  auto random_point = [&] {
    for (;;) {
      const double z = 2 + 18 * u(rng);
      const Eigen::Vector3d X((u(rng) * cam.width - cam.cx) * z / cam.fx, (u(rng) * cam.height - cam.cy) * z / cam.fy,
                              z);
      const Eigen::Vector3d Xn = T * X;
      const Eigen::Vector2d px = cam.project(Xn);
      if (Xn.z() > 0.5 && px.x() > 0 && px.x() < cam.width && px.y() > 0 && px.y() < cam.height) return X;
    }
  };
  for (int i = 0; i < n3 + n2; ++i) {
    const Eigen::Vector3d X = random_point();
    Eigen::Vector2d uv_k = cam.project(X), uv_n = cam.project(T * X);
    uv_k += pixel_noise * Eigen::Vector2d(g(rng), g(rng));
    uv_n += pixel_noise * Eigen::Vector2d(g(rng), g(rng));
    const bool bad = u(rng) < outliers;
    if (bad) uv_n += Eigen::Vector2d(20 + 30 * u(rng), -15 - 30 * u(rng));
    if (i < n3) {
      const double d = cam.disparity(X.z()) + disparity_noise * g(rng);
      s.c3.push_back({cam.triangulate(uv_k.x(), uv_k.y(), d), cam.normalise(uv_n.x(), uv_n.y())});
      s.outlier3.push_back(bad);
    } else {
      s.c2.push_back({cam.normalise(uv_k.x(), uv_k.y()), cam.normalise(uv_n.x(), uv_n.y())});
    }
  }
  return s;
}

}  // namespace

TEST(Motion, TriangulationEq4_1) {
  const StereoCamera cam = camera();
  // u = 288, v = 170, d = 20 px: X = (100 * 0.12 / 20, 50 * 0.12 / 20, 400 * 0.12 / 20).
  const Eigen::Vector3d X = cam.triangulate(288, 170, 20);
  EXPECT_DOUBLE_EQ(X.x(), 0.6);
  EXPECT_DOUBLE_EQ(X.y(), 0.3);
  EXPECT_DOUBLE_EQ(X.z(), 2.4);
  EXPECT_NEAR((cam.project(X) - Eigen::Vector2d(288, 170)).norm(), 0, 1e-12);
  EXPECT_DOUBLE_EQ(cam.disparity(2.4), 20);
}

TEST(Motion, ExponentialMapEq4_10) {
  using aerie::geometry::so3_exp;
  using aerie::geometry::so3_log;
  // A quarter turn about z.
  const Eigen::Matrix3d Rz = so3_exp<double>(Eigen::Vector3d(0, 0, M_PI / 2));
  Eigen::Matrix3d expect;
  expect << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  EXPECT_LT((Rz - expect).norm(), 1e-15);
  // Rodrigues (4.10) against Eigen's angle-axis, and log(exp(w)) = w.
  const Eigen::Vector3d w(0.3, -0.2, 0.5);
  const Eigen::Matrix3d R = so3_exp<double>(w);
  EXPECT_LT((R - Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix()).norm(), 1e-15);
  EXPECT_LT((so3_log(R) - w).norm(), 1e-14);
  EXPECT_NEAR(R.determinant(), 1.0, 1e-14);
  // Near zero the Taylor branch keeps exp continuous.
  EXPECT_LT((so3_exp<double>(Eigen::Vector3d(1e-9, 0, 0)) - Eigen::Matrix3d::Identity()).norm(), 2e-9);
  // SE3 twists round-trip.
  Eigen::Matrix<double, 6, 1> xi;
  xi << 0.1, -0.4, 0.2, 1.0, -2.0, 0.5;
  EXPECT_LT((SE3::exp(xi).log() - xi).norm(), 1e-12);
}

TEST(Motion, ResidualsEq4_14To4_16) {
  const Eigen::Vector3d w(0.1, -0.05, 0.02), t(0.2, -0.1, 0.3);
  const Eigen::Matrix3d R = aerie::geometry::so3_exp<double>(w);
  const Eigen::Vector3d X(1, 2, 5), Xn = R * X + t;
  const Eigen::Vector2d xn = Xn.head<2>() / Xn.z();
  double r[2];
  residual_3d(w.data(), t.data(), X, xn, r);
  EXPECT_NEAR(r[0], 0, 1e-15);
  EXPECT_NEAR(r[1], 0, 1e-15);
  // T_1 + 0.01 changes eq. 4.14 by exactly 0.01 and eq. 4.15 not at all.
  const Eigen::Vector3d t2 = t + Eigen::Vector3d(0.01, 0, 0);
  residual_3d(w.data(), t2.data(), X, xn, r);
  EXPECT_NEAR(r[0], 0.01, 1e-15);
  EXPECT_NEAR(r[1], 0, 1e-15);
  // Eq. 4.16 vanishes for the true motion, whatever the depths.
  const Eigen::Vector2d xk = X.head<2>() / X.z();
  double e;
  residual_2d(w.data(), t.data(), xk, xn, &e);
  EXPECT_NEAR(e, 0, 1e-15);
  // R = I, t = (1, 0, 0), X^k = (0, 0, 1), X^{k+1} = (0, 0.1, 1):
  // [T2 - y T3, x T3 - T1, y T1 - x T2] . X^k = y T1 = 0.1.
  const Eigen::Vector3d w0 = Eigen::Vector3d::Zero(), t1(1, 0, 0);
  residual_2d(w0.data(), t1.data(), Eigen::Vector2d(0, 0), Eigen::Vector2d(0, 0.1), &e);
  EXPECT_NEAR(e, 0.1, 1e-15);
}

TEST(Motion, RecoversNoiselessMotionExactly) {
  const SE3 T = SE3::from_rotation_vector(Eigen::Vector3d(0.02, -0.05, 0.01), Eigen::Vector3d(0.1, -0.03, 0.4));
  const Scene s = make_scene(T, 150, 100, 0, 0, 0, 1);
  MotionEstimator est;
  const MotionResult r = est.estimate(camera(), s.c3, s.c2);
  ASSERT_TRUE(r.ok) << r.failure;
  EXPECT_LT((r.T_next_k.log() - T.log()).norm(), 1e-8);
  EXPECT_EQ(r.inliers_3d, 150);
  EXPECT_EQ(r.inliers_2d, 100);
  EXPECT_LT(r.rms_px, 1e-6);
}

TEST(Motion, NoisyFeaturesWithOutliersWithinBounds) {
  const SE3 T = SE3::from_rotation_vector(Eigen::Vector3d(-0.03, 0.08, 0.02), Eigen::Vector3d(-0.2, 0.05, 0.5));
  const Scene s = make_scene(T, 200, 150, 0.5, 0.2, 0.2, 2);
  MotionEstimator est;
  const MotionResult r = est.estimate(camera(), s.c3, s.c2);
  ASSERT_TRUE(r.ok) << r.failure;
  const SE3 E = T.inverse() * r.T_next_k;
  EXPECT_LT(aerie::geometry::rotation_angle(E.rotation_matrix()) * 180 / M_PI, 0.1);
  EXPECT_LT(E.translation().norm(), 0.02);  // 2 cm of a 54 cm motion
  int caught = 0, outliers = 0;
  for (size_t i = 0; i < s.c3.size(); ++i)
    if (s.outlier3[i]) {
      ++outliers;
      caught += !r.inlier_3d[i];
    }
  EXPECT_EQ(caught, outliers);
  EXPECT_GT(r.inliers_3d, 140);
  // The covariance is a positive-definite 6x6 with small translation variance.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(r.covariance);
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0);
  EXPECT_LT((r.covariance.bottomRightCorner<3, 3>().trace()), 1e-3);
}

TEST(Motion, RefusesWithoutDepth) {
  const SE3 T = SE3::from_rotation_vector(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 0, 0.5));
  const Scene s = make_scene(T, 3, 100, 0, 0, 0, 3);
  const MotionResult r = MotionEstimator().estimate(camera(), s.c3, s.c2);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("depth"), std::string::npos) << r.failure;
}
