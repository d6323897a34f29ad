#include "air/track/ipsl/appearance.hpp"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <cmath>
#include <stdexcept>
#include <string>

namespace aerie::track {

void warp_patch(const cv::Mat& image, const Similarity& pose, const cv::Size2d& template_size, int patch_size,
                float* out) {
  CV_Assert(image.type() == CV_8UC1 && !image.empty() && patch_size > 0);
  const int P = patch_size;
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  const double ax = pose.scale * template_size.width / P, ay = pose.scale * template_size.height / P;
  const double h = (P - 1) / 2.0;
  // Inverse map patch (u, v) -> image: [c ax, -s ay; s ax, c ay] (u - h, v - h) + centre.
  const double m[6] = {c * ax, -s * ay, pose.x - h * (c * ax - s * ay),
                       s * ax, c * ay,  pose.y - h * (s * ax + c * ay)};
  // OpenCV's warp is vectorised (SSE/AVX/NEON through its universal intrinsics) and reads only
  // the pixels it needs; the 8-bit patch goes to [0, 1] floats.
  thread_local cv::Mat patch;
  cv::warpAffine(image, patch, cv::Mat(2, 3, CV_64F, const_cast<double*>(m)), {P, P},
                 cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REPLICATE);
  patch.convertTo(cv::Mat(P, P, CV_32F, out), CV_32F, 1.0 / 255.0);
}

void normalize_patch(float* v, int n) {
  Eigen::Map<Eigen::VectorXf> x(v, n);
  const float mean = x.mean();
  x.array() -= mean;
  const float norm = x.norm();
  if (norm > 1e-6f * n) {
    x *= std::sqrt(static_cast<float>(n)) / norm;
  } else {
    x.setZero();
  }
}

AppearanceModel::AppearanceModel(int dim, int max_basis, double forgetting, int block_size,
                                 const ObservationParams& params, bool anchor)
    : pca_(dim, max_basis, forgetting), block_size_(block_size), params_(params), anchor_(anchor) {
  if (block_size < 1)
    throw std::invalid_argument("AppearanceModel: block_size must be >= 1, got " + std::to_string(block_size));
  block_.resize(dim, block_size + 1);
  mean_ = Eigen::VectorXf::Zero(dim);
  basis_.resize(dim, 0);
}

void AppearanceModel::init(const Eigen::Ref<const Eigen::VectorXf>& first) {
  if (first.size() != dim()) throw std::invalid_argument("AppearanceModel::init: wrong observation length");
  pca_ = IncrementalPca(pca_.dim(), pca_.max_basis(), pca_.forgetting());
  pending_ = 0;
  mean_ = first;
  basis_.resize(dim(), 0);
  inv_variance_.resize(0);
  block_.col(block_size_) = first.cast<double>();  // the anchor column
  add(first);
}

bool AppearanceModel::add(const Eigen::Ref<const Eigen::VectorXf>& observation) {
  if (observation.size() != dim()) throw std::invalid_argument("AppearanceModel::add: wrong observation length");
  block_.col(pending_++) = observation.cast<double>();
  if (pending_ < block_size_) return false;
  // With the anchor, every later block also holds the first observation, so that the subspace
  // never forgets the initial appearance (the first block already has it).
  pca_.update(block_.leftCols(anchor_ && !pca_.empty() ? pending_ + 1 : pending_));
  pending_ = 0;
  refresh();
  return true;
}

void AppearanceModel::refresh() {
  mean_ = pca_.mean().cast<float>();
  basis_ = pca_.basis().cast<float>();
  const Eigen::ArrayXd variance = pca_.singular_values().array().square() / pca_.count();
  inv_variance_ = (1.0 / (variance + params_.within_epsilon)).cast<float>().matrix();
}

void AppearanceModel::score(const Eigen::Ref<const Eigen::MatrixXf>& observations,
                            std::vector<ObservationScore>& out) const {
  if (observations.rows() != dim()) throw std::invalid_argument("AppearanceModel::score: wrong observation length");
  const Eigen::Index n = observations.cols();
  out.assign(n, {});
  // e = (O - mu) - U U^T (O - mu), c = U^T (O - mu)  (eqs. 3.8, 3.9)
  Eigen::MatrixXf e = observations.colwise() - mean_;
  if (basis_.cols() > 0) {
    const Eigen::MatrixXf coef = basis_.transpose() * e;
    e.noalias() -= basis_ * coef;
    const Eigen::RowVectorXf within =
        (coef.array().square().colwise() * inv_variance_.array()).colwise().sum().matrix();
    for (Eigen::Index i = 0; i < n; ++i) out[i].distance_within = within(i);
  }
  // Robust error norm rho(e, y) = e^2 / (e^2 + y^2) summed over the pixels.
  const float y2 = static_cast<float>(params_.robust_scale * params_.robust_scale);
  const Eigen::ArrayXXf e2 = e.array().square();
  const Eigen::RowVectorXf to = (e2 / (e2 + y2)).colwise().sum().matrix();
  for (Eigen::Index i = 0; i < n; ++i) {
    auto& s = out[i];
    s.distance_to = to(i);
    s.residual = s.distance_to / dim();
    // eq. 3.10: log p = log p_dt + log p_dw
    s.log_likelihood = -s.distance_to / params_.to_temperature - 0.5 * params_.within_weight * s.distance_within;
  }
}

ObservationScore AppearanceModel::score(const Eigen::Ref<const Eigen::VectorXf>& observation) const {
  std::vector<ObservationScore> out;
  score(Eigen::MatrixXf(observation), out);
  return out.front();
}

}  // namespace aerie::track
