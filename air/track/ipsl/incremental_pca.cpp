#include "air/track/ipsl/incremental_pca.hpp"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <cmath>
#include <stdexcept>
#include <string>

namespace aerie::track {

IncrementalPca::IncrementalPca(int dim, int max_basis, double forgetting)
    : dim_(dim), max_basis_(max_basis), forgetting_(forgetting) {
  if (dim < 1) throw std::invalid_argument("IncrementalPca: dim must be >= 1, got " + std::to_string(dim));
  if (max_basis < 1)
    throw std::invalid_argument("IncrementalPca: max_basis must be >= 1, got " + std::to_string(max_basis));
  if (!(forgetting > 0 && forgetting <= 1))
    throw std::invalid_argument("IncrementalPca: forgetting factor must be in (0, 1], got " +
                                std::to_string(forgetting));
  mean_ = Eigen::VectorXd::Zero(dim);
  basis_.resize(dim, 0);
}

// Keeps at most k left singular vectors and drops the numerically null ones (rank < k when
// fewer observations than k have been seen).
void IncrementalPca::truncate(const Eigen::MatrixXd& u, const Eigen::VectorXd& s) {
  const double tol = s.size() ? 1e-10 * s(0) : 0.0;
  int keep = 0;
  while (keep < s.size() && keep < max_basis_ && s(keep) > tol) ++keep;
  basis_ = u.leftCols(keep);
  singular_values_ = s.head(keep);
}

void IncrementalPca::update(const Eigen::Ref<const Eigen::MatrixXd>& block) {
  if (block.rows() != dim_)
    throw std::invalid_argument("IncrementalPca::update: block has " + std::to_string(block.rows()) +
                                " rows, expected " + std::to_string(dim_));
  const int m = static_cast<int>(block.cols());
  if (m < 1) throw std::invalid_argument("IncrementalPca::update: empty block");
  if (!block.allFinite()) throw std::invalid_argument("IncrementalPca::update: block is not finite");

  const Eigen::VectorXd mean_b = block.rowwise().mean();
  if (count_ == 0) {  // first block: batch SVD of the centred data
    const Eigen::MatrixXd centred = block.colwise() - mean_b;
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred, Eigen::ComputeThinU);
    truncate(svd.matrixU(), svd.singularValues());
    mean_ = mean_b;
    count_ = m;
    return;
  }

  const double n = count_, eta = forgetting_;
  // E: the centred new block plus the mean-correction column of Ross et al. (2008).
  Eigen::MatrixXd E(dim_, m + 1);
  E.leftCols(m) = block.colwise() - mean_b;
  E.col(m) = std::sqrt(n * m / (n + m)) * (mean_ - mean_b);

  const int k = rank();
  const Eigen::MatrixXd proj = basis_.transpose() * E;        // U^T E
  const Eigen::MatrixXd residual = E - basis_ * proj;          // E - U U^T E
  // Ẽ: an orthonormal basis of the residual's column space (thin Q of a QR).
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(residual);
  const Eigen::MatrixXd e_orth = qr.householderQ() * Eigen::MatrixXd::Identity(dim_, m + 1);

  // R of eq. 3.3.
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(k + m + 1, k + m + 1);
  R.topLeftCorner(k, k) = (eta * singular_values_).asDiagonal();
  R.topRightCorner(k, m + 1) = proj;
  R.bottomRightCorner(m + 1, m + 1) = e_orth.transpose() * residual;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(R, Eigen::ComputeFullU);

  // eq. 3.2: U' = [U Ẽ] Ũ, Σ' = Σ̃.
  Eigen::MatrixXd q(dim_, k + m + 1);
  q.leftCols(k) = basis_;
  q.rightCols(m + 1) = e_orth;
  truncate(q * svd.matrixU(), svd.singularValues());

  // eq. 3.4: the forgetting factor weights the old mean by eta n.
  mean_ = (eta * n * mean_ + m * mean_b) / (eta * n + m);
  count_ = eta * n + m;
}

}  // namespace aerie::track
