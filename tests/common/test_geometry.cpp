#include <gtest/gtest.h>

#include <random>

#include "common/geometry/se3.hpp"

using aerie::geometry::SE3;
using aerie::geometry::so3_exp;
using aerie::geometry::so3_log;

TEST(So3, ExpOfZeroIsIdentity) {
  EXPECT_TRUE(so3_exp<double>(Eigen::Vector3d::Zero()).isApprox(Eigen::Matrix3d::Identity()));
}

TEST(So3, ExpMatchesAngleAxis) {
  const Eigen::Vector3d w(0.3, -0.2, 0.9);
  const Eigen::Matrix3d expected = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  EXPECT_LT((so3_exp<double>(w) - expected).norm(), 1e-12);
}

TEST(So3, LogInvertsExpIncludingSmallAndNearPiAngles) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (double angle : {1e-9, 1e-4, 0.5, 2.0, 3.1, M_PI - 1e-6}) {
    for (int i = 0; i < 20; ++i) {
      const Eigen::Vector3d w = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized() * angle;
      const Eigen::Vector3d back = so3_log(so3_exp<double>(w));
      EXPECT_LT((so3_exp<double>(back) - so3_exp<double>(w)).norm(), 1e-9) << "angle " << angle;
      if (angle < 3.0) {
        EXPECT_LT((back - w).norm(), 1e-9) << "angle " << angle;
      }
    }
  }
}

TEST(Se3, ExpLogRoundTrip) {
  Eigen::Matrix<double, 6, 1> xi;
  xi << 0.1, -0.4, 0.25, 1.5, -0.3, 2.0;
  const SE3 T = SE3::exp(xi);
  EXPECT_LT((T.log() - xi).norm(), 1e-12);
}

TEST(Se3, ComposeAndInverse) {
  const SE3 A = SE3::from_rotation_vector({0.1, 0.2, 0.3}, {1, 2, 3});
  const SE3 B = SE3::from_rotation_vector({-0.3, 0.0, 0.5}, {-1, 0.5, 2});
  const Eigen::Vector3d p(0.3, -2, 5);
  EXPECT_LT(((A * B) * p - A * (B * p)).norm(), 1e-12);
  EXPECT_LT(((A * A.inverse()).matrix() - Eigen::Matrix4d::Identity()).norm(), 1e-12);
}

TEST(Se3, QuaternionWxyzRoundTripAndRejectsZero) {
  const SE3 A = SE3::from_rotation_vector({0.4, -0.1, 0.2}, {1, 2, 3});
  double q[4];
  A.to_wxyz(q);
  const double t[3] = {1, 2, 3};
  EXPECT_LT((SE3::from_wxyz(q, t).matrix() - A.matrix()).norm(), 1e-12);
  const double zero[4] = {0, 0, 0, 0};
  EXPECT_THROW(SE3::from_wxyz(zero, t), std::invalid_argument);
}
