#include "air/track/ipsl/appearance.hpp"

#include <algorithm>
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
  // Source position is affine in (u, v): step du along a patch row, dv down a column.
  const float du_x = static_cast<float>(c * ax), du_y = static_cast<float>(s * ax);
  const double dv_x = -s * ay, dv_y = c * ay;
  const float max_x = static_cast<float>(image.cols - 1), max_y = static_cast<float>(image.rows - 1);
  const int last_col = image.cols - 1, last_row = image.rows - 1;
  const size_t step = image.step[0];
  const uchar* data = image.data;
  constexpr float kScale = 1.0f / 255.0f;
  for (int v = 0; v < P; ++v) {
    const float x0 = static_cast<float>(pose.x + dv_x * (v - h) - du_x * h);
    const float y0 = static_cast<float>(pose.y + dv_y * (v - h) - du_y * h);
    float* row = out + static_cast<size_t>(v) * P;
    for (int u = 0; u < P; ++u) {
      const float sx = std::clamp(x0 + du_x * u, 0.0f, max_x);
      const float sy = std::clamp(y0 + du_y * u, 0.0f, max_y);
      const int ix = static_cast<int>(sx), iy = static_cast<int>(sy);
      const float fx = sx - ix, fy = sy - iy;
      const int ix1 = std::min(ix + 1, last_col);
      const uchar* r0 = data + iy * step;
      const uchar* r1 = data + std::min(iy + 1, last_row) * step;
      const float top = r0[ix] + fx * (r0[ix1] - r0[ix]);
      const float bottom = r1[ix] + fx * (r1[ix1] - r1[ix]);
      row[u] = (top + fy * (bottom - top)) * kScale;
    }
  }
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
                                 const ObservationParams& params)
    : pca_(dim, max_basis, forgetting), block_size_(block_size), params_(params) {
  if (block_size < 1)
    throw std::invalid_argument("AppearanceModel: block_size must be >= 1, got " + std::to_string(block_size));
  block_.resize(dim, block_size);
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
  add(first);
}

bool AppearanceModel::add(const Eigen::Ref<const Eigen::VectorXf>& observation) {
  if (observation.size() != dim()) throw std::invalid_argument("AppearanceModel::add: wrong observation length");
  block_.col(pending_++) = observation.cast<double>();
  if (pending_ < block_size_) return false;
  pca_.update(block_.leftCols(pending_));
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
