#include "air/track/dcf/filters.hpp"

#include <algorithm>
#include <complex>

namespace aerie::track {
namespace {

using Complex = std::complex<float>;
Complex* cptr(cv::Mat& m) { return m.ptr<Complex>(); }
const Complex* cptr(const cv::Mat& m) { return m.ptr<Complex>(); }

}  // namespace

void blend(cv::Mat& model, const cv::Mat& sample, double rate) {
  if (model.empty() || rate >= 1)
    model = sample;
  else
    model = (1 - rate) * model + rate * sample;
}

cv::Mat masked_filter(const cv::Mat& yx, const cv::Mat& sxx, const cv::Mat& mask, const AdmmSettings& s) {
  const size_t n = yx.total();
  const float lambda = static_cast<float>(s.lambda);
  const float* e = sxx.ptr<float>();
  auto project = [&](const cv::Mat& spectrum, float divisor) {  // m . IDFT(.) / divisor, back to DFT
    cv::Mat g, gf;
    cv::dft(spectrum, g, cv::DFT_INVERSE | cv::DFT_REAL_OUTPUT | cv::DFT_SCALE);
    cv::dft(g.mul(mask) / divisor, gf, cv::DFT_COMPLEX_OUTPUT);
    return gf;
  };
  cv::Mat g(yx.size(), CV_32FC2), l(yx.size(), CV_32FC2, cv::Scalar::all(0));
  for (size_t k = 0; k < n; ++k) cptr(g)[k] = cptr(yx)[k] / (e[k] + lambda);
  cv::Mat gm = project(g, 1.f);
  float mu = static_cast<float>(s.mu);
  const float d = static_cast<float>(n);
  for (int it = 0; it < s.iterations; ++it) {
    for (size_t k = 0; k < n; ++k) cptr(g)[k] = (cptr(yx)[k] + mu * cptr(gm)[k] - cptr(l)[k]) / (e[k] + mu);
    gm = project(l + mu * g, lambda / (2 * d) + mu);
    l += mu * (g - gm);
    mu = std::min(mu * static_cast<float>(s.beta), static_cast<float>(s.mu_max));
  }
  return gm;
}

void LinearFilter::learn(const cv::Mat& xf, const cv::Mat& yf, double rate) {
  cv::Mat num(xf.size(), CV_32FC2), den = cv::Mat::zeros(1, xf.cols, CV_32F);
  const Complex* y = cptr(yf);
  float* d = den.ptr<float>();
  for (int r = 0; r < xf.rows; ++r) {
    const Complex* x = xf.ptr<Complex>(r);
    Complex* n = num.ptr<Complex>(r);
    for (int k = 0; k < xf.cols; ++k) {
      n[k] = std::conj(y[k]) * x[k];
      d[k] += std::norm(x[k]);
    }
  }
  blend(num_, num, rate);
  blend(den_, den, rate);
}

cv::Mat LinearFilter::respond(const cv::Mat& zf, double lambda) const {
  cv::Mat out(1, zf.cols, CV_32FC2, cv::Scalar::all(0));
  Complex* o = cptr(out);
  for (int r = 0; r < zf.rows; ++r) {
    const Complex* z = zf.ptr<Complex>(r);
    const Complex* a = num_.ptr<Complex>(r);
    for (int k = 0; k < zf.cols; ++k) o[k] += std::conj(a[k]) * z[k];
  }
  const float* b = den_.ptr<float>();
  for (int k = 0; k < zf.cols; ++k) o[k] /= b[k] + static_cast<float>(lambda);
  return out;
}

}  // namespace aerie::track
