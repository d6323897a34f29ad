#pragma once
// ECO's factorised convolution (Danelljan et al., CVPR 2017, sec. 3.1): the filter acts on C
// linear combinations of the D feature channels, x -> P^T x with P of size D x C, so that
// detection and training handle C instead of D channels. As in ECO, P is learned on the first
// frame by principal component analysis of its feature vectors and then kept fixed.
#include <opencv2/core.hpp>

namespace aerie::track {

// features: one row per channel, one column per cell (D x N, CV_32F). Returns P (D x C,
// CV_32F) with orthonormal columns: the C leading principal directions of the mean-centred
// cells, largest variance first. Throws std::invalid_argument unless 1 <= C <= D and N >= 2.
cv::Mat pca_projection(const cv::Mat& features, int dims);

// P^T features: C x N, row c the projected channel c over the cells.
cv::Mat project(const cv::Mat& features, const cv::Mat& P);

}  // namespace aerie::track
