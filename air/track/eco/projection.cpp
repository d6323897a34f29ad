#include "air/track/eco/projection.hpp"

#include <stdexcept>
#include <string>

namespace aerie::track {

cv::Mat pca_projection(const cv::Mat& features, int dims) {
  if (features.type() != CV_32F || features.cols < 2)
    throw std::invalid_argument("pca_projection: need an D x N CV_32F matrix with N >= 2");
  if (dims < 1 || dims > features.rows)
    throw std::invalid_argument("pca_projection: " + std::to_string(dims) + " dimensions of " +
                                std::to_string(features.rows) + " channels");
  cv::Mat covariance, mean;
  cv::calcCovarMatrix(features, covariance, mean, cv::COVAR_NORMAL | cv::COVAR_COLS | cv::COVAR_SCALE, CV_64F);
  cv::Mat values, vectors;  // eigenvectors as rows, eigenvalues descending
  cv::eigen(covariance, values, vectors);
  cv::Mat P;
  vectors.rowRange(0, dims).convertTo(P, CV_32F);
  return P.t();
}

cv::Mat project(const cv::Mat& features, const cv::Mat& P) {
  cv::Mat out;
  cv::gemm(P, features, 1.0, cv::noArray(), 0.0, out, cv::GEMM_1_T);
  return out;
}

}  // namespace aerie::track
