#pragma once
// The correlation filters of the DCF-family trackers, on full complex DFTs (CV_32FC2).
#include <opencv2/core.hpp>

namespace aerie::track {

// Running average of a model: model <- (1 - rate) model + rate sample; the sample itself when
// the model is empty or rate >= 1.
void blend(cv::Mat& model, const cv::Mat& sample, double rate);

// A multi-channel linear correlation filter (Danelljan et al. 2014, eqs. 4-5) on spectra
// stacked one feature channel per row (CV_32FC2): running numerator A = conj(Y) X per row and
// denominator B = sum over rows of |X|^2; response spectrum sum over rows of conj(A) Z / (B + lambda).
class LinearFilter {
 public:
  void learn(const cv::Mat& xf, const cv::Mat& yf, double rate);  // yf: one row
  cv::Mat respond(const cv::Mat& zf, double lambda) const;         // one row
 private:
  cv::Mat num_, den_;
};

// The augmented-Lagrangian (ADMM) solver of CSR-DCF's constrained filter (Lukezic et al. 2017).
struct AdmmSettings {
  double lambda = 1e-3;  // filter regularisation
  int iterations = 4;
  double mu = 5, beta = 3, mu_max = 20;  // penalty, its growth per step, its cap
};

// CSR-DCF's constrained filter of one channel (eqs. 6-8) from its sample statistics: the G
// (response IDFT(G Z)) minimising sum_m pi_m |X_m G - Y_m|^2 + lambda / 2 |g|^2 over filters
// g = IDFT(G) that are zero outside `mask`, given yx = sum_m pi_m Y_m conj(X_m) (CV_32FC2) and
// sxx = sum_m pi_m |X_m|^2 (CV_32F). One sample: yx = Y conj(X), sxx = |X|^2.
cv::Mat masked_filter(const cv::Mat& yx, const cv::Mat& sxx, const cv::Mat& mask, const AdmmSettings& s);

}  // namespace aerie::track
