#pragma once
// ECO's filter training (Danelljan et al., CVPR 2017, eq. 4 with the projection fixed) with
// SRDCF's spatial regularisation (Danelljan et al., ICCV 2015): one filter G = (G^1 .. G^C)
// over all projected channels, the minimiser of
//   E(G) = sum_j a_j || sum_c X_j^c G^c - Y_j ||^2 + sum_c || DFT(w . IDFT(G^c)) ||^2
// over the sample space's components j (spectra X_j, labels Y_j, weights a_j). The second term
// is N sum_c || w . g^c ||^2 (Parseval, N cells): a filter coefficient far from the target
// costs w^2 there. The normal equations
//   sum_j a_j conj(X_j^c) sum_c' X_j^c' G^c' + DFT(w^2 . IDFT(G^c)) = sum_j a_j conj(X_j^c) Y_j
// are solved by conjugate gradient with a diagonal (Jacobi) preconditioner, warm-started from
// the last filter, as ECO does between its sparse updates. With a temporal prior (STRCF, Li et
// al., CVPR 2018; AutoTrack's theta, Li, Fu et al., CVPR 2020) E gains theta ||G - G_ref||^2,
// which keeps the filter near a reference (the last filter): theta G joins the left side and
// theta G_ref the right.
#include <opencv2/core.hpp>
#include <vector>

#include "air/track/eco/sample_space.hpp"

namespace aerie::track {

// SRDCF's regulariser w^2 (CV_32F, `cells`), w = a + (b - a) r^2 with r the elliptic distance
// from the grid's centre in units of the target's half size (target_cells: its size in cells),
// a^2 = floor and b^2 = at_edge: w^2 is `floor` at the centre and `at_edge` on the target's
// border, and grows with r^4 beyond (the filter is kept on the target, softly, unlike a mask).
cv::Mat spatial_regulariser(cv::Size cells, cv::Size2d target_cells, double floor, double at_edge);

// The samples' mean energy sum_j a_j |X_j^c(k)|^2 per channel and frequency: times it, the
// regulariser's floor and edge are relative to the features' scale.
double mean_energy(const std::vector<Sample>& components, const std::vector<double>& weights);

// theta ||G - reference||^2 (off while theta is 0 or the reference empty).
struct TemporalPrior {
  double theta = 0;
  std::vector<cv::Mat> reference;  // one CV_32FC2 spectrum per channel, like the filter
};

// `iterations` steps of preconditioned conjugate gradient on the normal equations above, from
// `filter` (one CV_32FC2 spectrum per channel; empty: from the preconditioner's solution).
// Returns the relative residual ||b - A G|| / ||b|| after the last step.
double train_joint_filter(const std::vector<Sample>& components, const std::vector<double>& weights,
                          const cv::Mat& w2, int iterations, std::vector<cv::Mat>& filter,
                          const TemporalPrior& prior = {});

// E(G) (tests).
double joint_objective(const std::vector<Sample>& components, const std::vector<double>& weights,
                       const cv::Mat& w2, const std::vector<cv::Mat>& filter, const TemporalPrior& prior = {});

// ECO's first frame (CVPR 2017, sec. 3.1, eqs. 6-7): the projection learned with the filter.
// Gauss-Newton on E(G, P) = || sum_c (P^T X)^c G^c - Y ||^2 + reg(G) + mu ||P||_F^2 for one
// sample X (the spectra of the D raw channels, windowed), each step linearised around
// (G_i, P_i) as (P_i + dP)^T X G ~ (P_i^T X) G + (dP^T X) G_i and solved in (G, dP) by
// preconditioned conjugate gradient. P is block-diagonal: block b maps the raw channels
// [first, first + P.rows) to the next P.cols projected channels. mu = projection_reg x the mean
// diagonal of the dP part of the normal equations at the start (relative to the data).
struct ProjectionBlock {
  int first = 0;  // first raw channel
  cv::Mat P;      // raw channels x projected channels, CV_32F (in: the start, e.g. PCA; out: learned)
};
// The projected spectra P^T X of the blocks, in order.
std::vector<cv::Mat> project_spectra(const std::vector<cv::Mat>& raw_xf, const std::vector<ProjectionBlock>& blocks);
// Returns E(G, P) without the mu term (joint_objective's) after the last step; `filter` is the
// filter of the learned projection.
double learn_projection(const std::vector<cv::Mat>& raw_xf, const cv::Mat& yf, const cv::Mat& w2,
                        double projection_reg, int gauss_newton_iterations, int cg_iterations,
                        std::vector<ProjectionBlock>& blocks, std::vector<cv::Mat>& filter);

}  // namespace aerie::track
