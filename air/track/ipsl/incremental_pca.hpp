#pragma once
// Incremental PCA with mean update and forgetting factor (Ross et al. 2008, "Incremental
// learning for robust visual tracking", Algorithm 1; thesis eqs. 3.2-3.4).
#include <Eigen/Core>

namespace aerie::track {

class IncrementalPca {
 public:
  // dim: length of an observation; max_basis: k eigenvectors kept; forgetting: eta in (0, 1].
  // Throws std::invalid_argument for dim < 1, max_basis < 1 or eta outside (0, 1].
  IncrementalPca(int dim, int max_basis, double forgetting);

  // Adds a block S_b of m >= 1 observations (one per column). The first block is a batch SVD
  // of the centred data; later blocks follow eqs. 3.2-3.4:
  //   E = [S_b - mean_b, sqrt(n m / (n + m)) (mean_a - mean_b)],  Ẽ = orth(E - U U^T E),
  //   R = [eta Sigma, U^T E; 0, Ẽ^T (E - U U^T E)] = Ũ Σ̃ Ṽ^T,  U' = [U Ẽ] Ũ,  Σ' = Σ̃,
  //   mean_c = (eta n mean_a + m mean_b) / (eta n + m),  n' = eta n + m.
  void update(const Eigen::Ref<const Eigen::MatrixXd>& block);

  int dim() const { return dim_; }
  int max_basis() const { return max_basis_; }
  double forgetting() const { return forgetting_; }
  int rank() const { return static_cast<int>(basis_.cols()); }
  bool empty() const { return count_ == 0; }
  const Eigen::MatrixXd& basis() const { return basis_; }                  // dim x rank, orthonormal
  const Eigen::VectorXd& singular_values() const { return singular_values_; }  // descending
  const Eigen::VectorXd& mean() const { return mean_; }
  double count() const { return count_; }  // effective number of observations n (eta-weighted)

 private:
  void truncate(const Eigen::MatrixXd& u, const Eigen::VectorXd& s);

  int dim_, max_basis_;
  double forgetting_;
  Eigen::MatrixXd basis_;
  Eigen::VectorXd singular_values_;
  Eigen::VectorXd mean_;
  double count_ = 0;
};

}  // namespace aerie::track
