#pragma once
// The observation side of IPSL: warped, vectorised patches (the observation O of eq. 3.1), the
// robust error norm, and the subspace likelihood p(O | X) of eqs. 3.8-3.10 over an
// incrementally updated eigenbasis (eqs. 3.2-3.4).
#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "air/track/ipsl/incremental_pca.hpp"
#include "air/track/tracker.hpp"

namespace aerie::track {

// Robust error norm rho(x, y) = x^2 / (x^2 + y^2) (thesis after eq. 3.10); 0 for x = y = 0.
inline double robust_norm(double x, double y) {
  const double x2 = x * x, d = x2 + y * y;
  return d > 0 ? x2 / d : 0.0;
}

struct ObservationParams {
  double robust_scale = 0.6;     // y of rho(e, y) for each pixel of the reconstruction error
  double to_temperature = 4;     // log p_dt = -sum_i rho(e_i, y) / to_temperature  (eq. 3.8)
  double within_weight = 0.01;   // log p_dw = -within_weight / 2 * sum_j c_j^2 / lambda_j (eq. 3.9)
  double within_epsilon = 1e-3;  // added to the subspace variances lambda_j
};

// The terms of log p(O | X) = log p_dt + log p_dw (eq. 3.10) for one observation.
struct ObservationScore {
  double distance_to = 0;      // sum_i rho(e_i, robust_scale), e = (O - mu) - U U^T (O - mu)
  double distance_within = 0;  // sum_j c_j^2 / (lambda_j + eps), c = U^T (O - mu), lambda_j = sigma_j^2 / n
  double log_likelihood = 0;
  double residual = 0;         // distance_to / dim: mean robust error per pixel, in [0, 1)
};

// Warps the template region at `pose` into a patch_size x patch_size observation (bilinear,
// border pixels replicated): patch pixel (u, v) samples the image at
//   centre + R(theta) * s * (w / P * (u - (P-1)/2), h / P * (v - (P-1)/2)).
// image: 8-bit single channel; pose and template_size (w, h at s = 1) in that image's pixels.
// out: patch_size^2 floats, row-major, intensities in [0, 1].
void warp_patch(const cv::Mat& image, const Similarity& pose, const cv::Size2d& template_size, int patch_size,
                float* out);
// Zero mean, unit variance (a flat patch becomes all zeros).
void normalize_patch(float* v, int n);

// One IPSL appearance model: the subspace (mean, eigenbasis, singular values), the block of
// observations waiting for the next incremental update, and the likelihood.
class AppearanceModel {
 public:
  // anchor: every update block after the first also holds the first observation.
  AppearanceModel(int dim, int max_basis, double forgetting, int block_size, const ObservationParams& params,
                  bool anchor = false);

  // Starts from the first observation: it is the mean until the first update (the first
  // block, which includes it, is learnt by a batch SVD).
  void init(const Eigen::Ref<const Eigen::VectorXf>& first);
  // Queues an observation; every block_size observations update the subspace.
  // Returns true when an update happened.
  bool add(const Eigen::Ref<const Eigen::VectorXf>& observation);

  // Scores each column of `observations` (dim x N).
  void score(const Eigen::Ref<const Eigen::MatrixXf>& observations, std::vector<ObservationScore>& out) const;
  ObservationScore score(const Eigen::Ref<const Eigen::VectorXf>& observation) const;

  const IncrementalPca& pca() const { return pca_; }
  int dim() const { return pca_.dim(); }
  int block_size() const { return block_size_; }
  int pending() const { return pending_; }

 private:
  void refresh();  // float copies of the subspace for scoring

  IncrementalPca pca_;
  int block_size_;
  ObservationParams params_;
  bool anchor_;
  Eigen::MatrixXd block_;  // block_size observations + the first one (the anchor column)
  int pending_ = 0;
  Eigen::VectorXf mean_;
  Eigen::MatrixXf basis_;
  Eigen::VectorXf inv_variance_;  // 1 / (lambda_j + eps)
};

}  // namespace aerie::track
