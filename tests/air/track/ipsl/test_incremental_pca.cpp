#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <random>

#include "air/track/ipsl/appearance.hpp"
#include "air/track/ipsl/incremental_pca.hpp"

using namespace aerie::track;

namespace {

Eigen::MatrixXd make_data(int d, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  // Anisotropic: a few strong directions plus noise, offset from the origin.
  Eigen::MatrixXd mix(d, 6);
  for (int i = 0; i < mix.size(); ++i) mix.data()[i] = g(rng);
  Eigen::MatrixXd x(d, n);
  for (int j = 0; j < n; ++j) {
    Eigen::VectorXd z(6);
    for (int i = 0; i < 6; ++i) z(i) = g(rng) * (6 - i);
    for (int i = 0; i < d; ++i) x(i, j) = 3.0 + 0.1 * g(rng);
    x.col(j) += mix * z;
  }
  return x;
}

// U diag(s^2) U^T: the scatter of the data the subspace represents (basis-sign free).
Eigen::MatrixXd scatter(const Eigen::MatrixXd& u, const Eigen::VectorXd& s) {
  return u * s.array().square().matrix().asDiagonal() * u.transpose();
}

}  // namespace

// With eta = 1 and no truncation, the incremental result equals a batch SVD of all data.
TEST(IncrementalPca, EqualsBatchSvdWithoutForgetting) {
  const int d = 40, n = 27;
  const Eigen::MatrixXd x = make_data(d, n, 1);
  IncrementalPca pca(d, d, 1.0);
  for (int start = 0; start < n; start += 5) pca.update(x.middleCols(start, std::min(5, n - start)));

  const Eigen::VectorXd mean = x.rowwise().mean();
  const Eigen::MatrixXd centred = x.colwise() - mean;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred, Eigen::ComputeThinU);
  const int rank = n - 1;  // centred data of n generic points
  ASSERT_EQ(pca.rank(), rank);
  EXPECT_DOUBLE_EQ(pca.count(), n);
  EXPECT_LT((pca.mean() - mean).cwiseAbs().maxCoeff(), 1e-9);
  const Eigen::VectorXd s = svd.singularValues().head(rank);
  EXPECT_LT(((pca.singular_values() - s).array() / s.array()).abs().maxCoeff(), 1e-6);
  const Eigen::MatrixXd ub = svd.matrixU().leftCols(rank);
  // Same subspace: equal projection matrices, and equal scatter.
  EXPECT_LT((pca.basis() * pca.basis().transpose() - ub * ub.transpose()).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT((scatter(pca.basis(), pca.singular_values()) - centred * centred.transpose()).cwiseAbs().maxCoeff() /
                s(0) / s(0),
            1e-9);
  // Orthonormal basis.
  EXPECT_LT((pca.basis().transpose() * pca.basis() - Eigen::MatrixXd::Identity(rank, rank)).cwiseAbs().maxCoeff(),
            1e-9);
}

// The top-k truncation keeps the k strongest directions of the batch result when the data
// really has k strong directions.
TEST(IncrementalPca, TruncatedBasisSpansTheDominantSubspace) {
  const int d = 60, n = 60;
  const Eigen::MatrixXd x = make_data(d, n, 2);
  IncrementalPca pca(d, 6, 1.0);
  for (int start = 0; start < n; start += 5) pca.update(x.middleCols(start, 5));
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(x.colwise() - x.rowwise().mean(), Eigen::ComputeThinU);
  const Eigen::MatrixXd ub = svd.matrixU().leftCols(6);
  ASSERT_EQ(pca.rank(), 6);
  EXPECT_LT((pca.basis() * pca.basis().transpose() - ub * ub.transpose()).norm(), 0.02);
}

// eqs. 3.3, 3.4: the forgetting factor weights the old mean by eta n and scales the old
// singular values by eta, i.e. the model is the SVD of [eta (A - mean_a), B - mean_b,
// sqrt(n m / (n + m)) (mean_a - mean_b)].
TEST(IncrementalPca, ForgettingFactorWeightsOldDataAsEq34) {
  const int d = 12;
  const double eta = 0.5;
  const Eigen::MatrixXd a = make_data(d, 4, 3), b = make_data(d, 3, 4) * 2.0;
  IncrementalPca pca(d, d, eta);
  pca.update(a);
  pca.update(b);
  const Eigen::VectorXd ma = a.rowwise().mean(), mb = b.rowwise().mean();
  // Hand-computed weighted mean: (eta n mean_a + m mean_b) / (eta n + m), n = 4, m = 3.
  const Eigen::VectorXd expected = (0.5 * 4 * ma + 3 * mb) / (0.5 * 4 + 3);
  EXPECT_LT((pca.mean() - expected).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_DOUBLE_EQ(pca.count(), 5.0);
  Eigen::MatrixXd m(d, 4 + 3 + 1);
  m.leftCols(4) = eta * (a.colwise() - ma);
  m.middleCols(4, 3) = b.colwise() - mb;
  m.col(7) = std::sqrt(4.0 * 3 / 7) * (ma - mb);
  const Eigen::MatrixXd want = m * m.transpose();
  EXPECT_LT((scatter(pca.basis(), pca.singular_values()) - want).cwiseAbs().maxCoeff() / want.norm(), 1e-9);

  // A third block: the previous effective count 5 is weighted again by eta.
  const Eigen::MatrixXd c = make_data(d, 2, 5);
  const Eigen::VectorXd mean_before = pca.mean();
  pca.update(c);
  const Eigen::VectorXd expected3 = (0.5 * 5 * mean_before + 2 * c.rowwise().mean()) / (0.5 * 5 + 2);
  EXPECT_LT((pca.mean() - expected3).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_DOUBLE_EQ(pca.count(), 4.5);
}

TEST(IncrementalPca, RejectsBadInput) {
  EXPECT_THROW(IncrementalPca(0, 4, 1), std::invalid_argument);
  EXPECT_THROW(IncrementalPca(4, 0, 1), std::invalid_argument);
  EXPECT_THROW(IncrementalPca(4, 2, 0), std::invalid_argument);
  EXPECT_THROW(IncrementalPca(4, 2, 1.5), std::invalid_argument);
  IncrementalPca pca(4, 2, 1);
  EXPECT_THROW(pca.update(Eigen::MatrixXd::Zero(3, 2)), std::invalid_argument);
  EXPECT_THROW(pca.update(Eigen::MatrixXd::Zero(4, 0)), std::invalid_argument);
  Eigen::MatrixXd nan = Eigen::MatrixXd::Zero(4, 2);
  nan(1, 1) = std::nan("");
  EXPECT_THROW(pca.update(nan), std::invalid_argument);
}

TEST(Appearance, RobustNormHandValues) {
  EXPECT_DOUBLE_EQ(robust_norm(3, 4), 9.0 / 25.0);
  EXPECT_DOUBLE_EQ(robust_norm(-3, 4), 9.0 / 25.0);
  EXPECT_DOUBLE_EQ(robust_norm(0, 1), 0.0);
  EXPECT_DOUBLE_EQ(robust_norm(1, 0), 1.0);
  EXPECT_DOUBLE_EQ(robust_norm(0, 0), 0.0);
  EXPECT_DOUBLE_EQ(robust_norm(2, 2), 0.5);
}

// eqs. 3.8-3.10 on a subspace learnt from two observations (1,0,0,0) and (-1,0,0,0):
// mean 0, basis e1, singular value sqrt(2), n = 2, so lambda_1 = 1.
TEST(Appearance, LikelihoodHandValues) {
  ObservationParams p;
  p.robust_scale = 0.5;
  p.to_temperature = 2;
  p.within_weight = 0.1;
  p.within_epsilon = 0.25;
  AppearanceModel model(4, 4, 1.0, 2, p);
  model.init(Eigen::Vector4f(1, 0, 0, 0));
  EXPECT_EQ(model.pca().rank(), 0);
  // Before the first update the first observation is the mean: e = O - v1.
  ObservationScore s0 = model.score(Eigen::Vector4f(1, 0.5, 0, 0));
  EXPECT_NEAR(s0.distance_to, 0.5, 1e-6);  // rho(0.5, 0.5)
  EXPECT_NEAR(s0.distance_within, 0.0, 1e-9);
  EXPECT_TRUE(model.add(Eigen::Vector4f(-1, 0, 0, 0)));
  ASSERT_EQ(model.pca().rank(), 1);
  EXPECT_NEAR(model.pca().singular_values()(0), std::sqrt(2.0), 1e-12);

  const ObservationScore s = model.score(Eigen::Vector4f(2, 0.5, 0, -1));
  // c = 2 -> c^2 / (lambda + eps) = 4 / 1.25; e = (0, 0.5, 0, -1) -> rho = 0.5 + 1 / 1.25.
  EXPECT_NEAR(s.distance_within, 4.0 / 1.25, 1e-5);
  EXPECT_NEAR(s.distance_to, 0.5 + 0.8, 1e-6);
  EXPECT_NEAR(s.residual, 1.3 / 4, 1e-6);
  EXPECT_NEAR(s.log_likelihood, -1.3 / 2 - 0.5 * 0.1 * 3.2, 1e-5);
  // An observation in the subspace at the mean is the most likely.
  EXPECT_GT(model.score(Eigen::Vector4f(0, 0, 0, 0)).log_likelihood, s.log_likelihood);
}

TEST(Appearance, BlockSizeControlsUpdates) {
  AppearanceModel model(3, 2, 1.0, 3, {});
  model.init(Eigen::Vector3f(1, 2, 3));
  EXPECT_EQ(model.pending(), 1);
  EXPECT_FALSE(model.add(Eigen::Vector3f(2, 2, 3)));
  EXPECT_TRUE(model.add(Eigen::Vector3f(3, 2, 3)));
  EXPECT_EQ(model.pending(), 0);
  EXPECT_NEAR(model.pca().mean()(0), 2.0, 1e-12);
}

// Identity warp reads the image; a 90-degree rotation and a scale of 2 move the samples as
// the formula in appearance.hpp says.
TEST(Appearance, WarpPatchFollowsTheSimilarity) {
  cv::Mat img(40, 40, CV_8U);
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) img.at<uchar>(y, x) = static_cast<uchar>(x + 3 * y);
  const int P = 8;
  std::vector<float> out(P * P);
  // centre 20.5 with an 8x8 template: u -> x = 17 + u, v -> y = 17 + v
  warp_patch(img, {20.5, 20.5, 1, 0}, {8, 8}, P, out.data());
  for (int v = 0; v < P; ++v)
    for (int u = 0; u < P; ++u) EXPECT_NEAR(out[v * P + u] * 255, (17 + u) + 3 * (17 + v), 1e-3);
  warp_patch(img, {20.5, 20.5, 2, 0}, {8, 8}, P, out.data());  // x = 20.5 + 2 (u - 3.5)
  EXPECT_NEAR(out[0] * 255, 13.5 + 3 * 13.5, 1e-3);
  warp_patch(img, {20.5, 20.5, 1, CV_PI / 2}, {8, 8}, P, out.data());  // u steps along +y
  EXPECT_NEAR(out[1] * 255 - out[0] * 255, 3.0, 1e-3);
  EXPECT_NEAR(out[P] * 255 - out[0] * 255, -1.0, 1e-3);
  // Outside the image the border is replicated.
  warp_patch(img, {-50, -50, 1, 0}, {8, 8}, P, out.data());
  EXPECT_NEAR(out[0], 0.0f, 1e-6);
  std::vector<float> flat(16, 0.3f);
  normalize_patch(flat.data(), 16);
  EXPECT_FLOAT_EQ(flat[3], 0.0f);
}
