#include "air/track/eco/joint_filter.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace aerie::track {
namespace {

using Spectra = std::vector<cv::Mat>;  // one CV_32FC2 spectrum per channel

Spectra zeros_like(const Spectra& s) {
  Spectra out;
  for (const auto& m : s) out.emplace_back(m.size(), CV_32FC2, cv::Scalar::all(0));
  return out;
}

// Re <u, v> summed over channels and frequencies.
double inner(const Spectra& u, const Spectra& v) {
  double sum = 0;
  for (size_t c = 0; c < u.size(); ++c) sum += u[c].dot(v[c]);  // sum of re re + im im
  return sum;
}

// The regulariser's part of A G: DFT(w2 . IDFT(G)) per channel.
void add_regularisation(const cv::Mat& w2, const Spectra& g, Spectra& out) {
  cv::Mat spatial, back;
  for (size_t c = 0; c < g.size(); ++c) {
    cv::dft(g[c], spatial, cv::DFT_INVERSE | cv::DFT_REAL_OUTPUT | cv::DFT_SCALE);
    cv::dft(spatial.mul(w2), back, cv::DFT_COMPLEX_OUTPUT);
    out[c] += back;
  }
}

// The data part of A G: sum_j a_j conj(X_j^c) sum_c' X_j^c' G^c', written out in reals so that
// the loops vectorise.
void add_data(const std::vector<Sample>& comps, const std::vector<double>& weights, const Spectra& g, Spectra& out) {
  const size_t channels = g.size(), n = g[0].total();
  std::vector<float> s(2 * n);
  for (size_t j = 0; j < comps.size(); ++j) {
    std::fill(s.begin(), s.end(), 0.f);
    for (size_t c = 0; c < channels; ++c) {
      const float* x = comps[j].xf[c].ptr<float>();
      const float* f = g[c].ptr<float>();
      for (size_t k = 0; k < n; ++k) {
        s[2 * k] += x[2 * k] * f[2 * k] - x[2 * k + 1] * f[2 * k + 1];
        s[2 * k + 1] += x[2 * k] * f[2 * k + 1] + x[2 * k + 1] * f[2 * k];
      }
    }
    const float a = static_cast<float>(weights[j]);
    for (size_t c = 0; c < channels; ++c) {
      const float* x = comps[j].xf[c].ptr<float>();
      float* o = out[c].ptr<float>();
      for (size_t k = 0; k < n; ++k) {  // a conj(x) s
        o[2 * k] += a * (x[2 * k] * s[2 * k] + x[2 * k + 1] * s[2 * k + 1]);
        o[2 * k + 1] += a * (x[2 * k] * s[2 * k + 1] - x[2 * k + 1] * s[2 * k]);
      }
    }
  }
}

void check(const std::vector<Sample>& comps, const std::vector<double>& weights, const cv::Mat& w2,
           const TemporalPrior& prior = {}) {
  if (comps.empty() || comps.size() != weights.size() || comps[0].xf.empty())
    throw std::invalid_argument("joint filter: no samples, or not one weight per sample");
  if (comps[0].xf[0].size() != w2.size() || w2.type() != CV_32F)
    throw std::invalid_argument("joint filter: the regulariser is not one CV_32F value per frequency");
  if (!(prior.theta >= 0 && std::isfinite(prior.theta)))
    throw std::invalid_argument("joint filter: the temporal prior's theta must be finite and >= 0");
  if (!prior.reference.empty() &&
      (prior.reference.size() != comps[0].xf.size() || prior.reference[0].size() != w2.size()))
    throw std::invalid_argument("joint filter: the temporal prior's reference is not one spectrum per channel");
}

bool active(const TemporalPrior& prior) { return prior.theta > 0 && !prior.reference.empty(); }

// The Jacobi preconditioner of the normal equations: sum_j a_j |X_j^c|^2 + mean(w2) + theta per channel,
// in both parts of a CV_32FC2 mat so that a residual spectrum is divided by it directly.
Spectra jacobi_diagonal(const std::vector<Sample>& comps, const std::vector<double>& weights, const cv::Mat& w2,
                        double theta = 0) {
  const size_t n = w2.total();
  const float reg_mean = static_cast<float>(cv::mean(w2)[0] + theta);
  Spectra diag;
  for (size_t c = 0; c < comps[0].xf.size(); ++c) {
    cv::Mat d(w2.size(), CV_32F, cv::Scalar(reg_mean));
    float* e = d.ptr<float>();
    for (size_t j = 0; j < comps.size(); ++j) {
      const float* x = comps[j].xf[c].ptr<float>();
      const float a = static_cast<float>(weights[j]);
      for (size_t k = 0; k < n; ++k) e[k] += a * (x[2 * k] * x[2 * k] + x[2 * k + 1] * x[2 * k + 1]);
    }
    cv::merge(std::vector<cv::Mat>{d, d}, diag.emplace_back());
  }
  return diag;
}

Spectra divided(const Spectra& r, const Spectra& diag) {
  Spectra z(r.size());
  for (size_t c = 0; c < r.size(); ++c) cv::divide(r[c], diag[c], z[c]);
  return z;
}

Spectra clones(const Spectra& s) {
  Spectra out;
  for (const auto& m : s) out.push_back(m.clone());
  return out;
}

// Preconditioned conjugate gradient (Shewchuk 1994, B3) on vectors of type V, from x with
// residual r = b - A x: `iterations` steps at most, fewer once the preconditioned residual has
// fallen by 1e-5 (single precision: further steps only add rounding). axpy(y, a, x) adds a x to
// y in place. Returns the last residual.
template <typename V, typename Apply, typename Precondition, typename Dot, typename Axpy>
V conjugate_gradient(V& x, V r, int iterations, Apply apply, Precondition precondition, Dot dot, Axpy axpy) {
  V p = precondition(r);
  double rz = dot(r, p);
  const double converged = 1e-10 * rz;
  for (int it = 0; it < iterations && rz > converged; ++it) {
    const V q = apply(p);
    const double pq = dot(p, q);
    if (!(pq > 0)) break;
    axpy(x, rz / pq, p);
    axpy(r, -rz / pq, q);
    V z = precondition(r);
    const double rz_next = dot(r, z);
    axpy(z, rz_next / rz, p);  // the next direction
    p = std::move(z);
    rz = rz_next;
  }
  return r;
}

void axpy_spectra(Spectra& y, double a, const Spectra& x) {
  for (size_t c = 0; c < y.size(); ++c) y[c] += a * x[c];
}

}  // namespace

double mean_energy(const std::vector<Sample>& comps, const std::vector<double>& weights) {
  if (comps.empty() || comps[0].xf.empty()) return 0;
  double e = 0;
  for (size_t j = 0; j < comps.size(); ++j)
    for (const auto& x : comps[j].xf) e += weights[j] * x.dot(x);
  return e / static_cast<double>(comps[0].xf.size() * comps[0].xf[0].total());
}

cv::Mat spatial_regulariser(cv::Size cells, cv::Size2d target_cells, double floor, double at_edge) {
  if (floor < 0 || at_edge < floor || target_cells.width <= 0 || target_cells.height <= 0)
    throw std::invalid_argument("spatial regulariser: needs 0 <= floor <= at_edge and a target of positive size");
  const double a = std::sqrt(floor), b = std::sqrt(at_edge);
  const double cx = (cells.width - 1) / 2.0, cy = (cells.height - 1) / 2.0;
  cv::Mat w2(cells, CV_32F);
  for (int i = 0; i < cells.height; ++i)
    for (int j = 0; j < cells.width; ++j) {
      const double u = (j - cx) / (target_cells.width / 2), v = (i - cy) / (target_cells.height / 2);
      const double w = a + (b - a) * (u * u + v * v);
      w2.at<float>(i, j) = static_cast<float>(w * w);
    }
  return w2;
}

double train_joint_filter(const std::vector<Sample>& comps, const std::vector<double>& weights, const cv::Mat& w2,
                          int iterations, std::vector<cv::Mat>& filter, const TemporalPrior& prior) {
  check(comps, weights, w2, prior);
  const double theta = active(prior) ? prior.theta : 0.0;
  const size_t channels = comps[0].xf.size(), n = w2.total();
  // b = sum_j a_j conj(X_j) Y_j.
  Spectra b = zeros_like(comps[0].xf);
  for (size_t c = 0; c < channels; ++c) {
    float* o = b[c].ptr<float>();
    for (size_t j = 0; j < comps.size(); ++j) {
      const float* x = comps[j].xf[c].ptr<float>();
      const float* y = comps[j].yf.ptr<float>();
      const float a = static_cast<float>(weights[j]);
      for (size_t k = 0; k < n; ++k) {
        o[2 * k] += a * (x[2 * k] * y[2 * k] + x[2 * k + 1] * y[2 * k + 1]);
        o[2 * k + 1] += a * (x[2 * k] * y[2 * k + 1] - x[2 * k + 1] * y[2 * k]);
      }
    }
  }
  if (theta > 0) axpy_spectra(b, theta, prior.reference);  // + theta G_ref
  const Spectra diag = jacobi_diagonal(comps, weights, w2, theta);
  auto precondition = [&](const Spectra& r) { return divided(r, diag); };
  auto apply = [&](const Spectra& g) {
    Spectra out = zeros_like(g);
    add_data(comps, weights, g, out);
    add_regularisation(w2, g, out);
    if (theta > 0) axpy_spectra(out, theta, g);
    return out;
  };
  if (filter.size() != channels || filter[0].size() != w2.size()) filter = precondition(b);

  Spectra r = apply(filter);
  for (size_t c = 0; c < channels; ++c) r[c] = b[c] - r[c];
  r = conjugate_gradient(filter, r, iterations, apply, precondition, inner, axpy_spectra);
  return std::sqrt(inner(r, r) / std::max(1e-300, inner(b, b)));
}

double joint_objective(const std::vector<Sample>& comps, const std::vector<double>& weights, const cv::Mat& w2,
                       const std::vector<cv::Mat>& filter, const TemporalPrior& prior) {
  check(comps, weights, w2, prior);
  double e = 0;
  for (size_t j = 0; j < comps.size(); ++j) {
    cv::Mat s = -comps[j].yf;
    for (size_t c = 0; c < filter.size(); ++c) {
      cv::Mat prod;
      cv::mulSpectrums(comps[j].xf[c], filter[c], prod, 0);
      s += prod;
    }
    e += weights[j] * s.dot(s);
  }
  for (const auto& g : filter) {  // N sum_x w^2 g^2 (Parseval)
    cv::Mat spatial;
    cv::dft(g, spatial, cv::DFT_INVERSE | cv::DFT_REAL_OUTPUT | cv::DFT_SCALE);
    e += static_cast<double>(w2.total()) * spatial.mul(spatial).dot(w2);
  }
  if (active(prior))
    for (size_t c = 0; c < filter.size(); ++c) {
      const cv::Mat d = filter[c] - prior.reference[c];
      e += prior.theta * d.dot(d);
    }
  return e;
}

std::vector<cv::Mat> project_spectra(const std::vector<cv::Mat>& raw_xf, const std::vector<ProjectionBlock>& blocks) {
  std::vector<cv::Mat> z;
  for (const auto& b : blocks) {
    if (b.first < 0 || b.first + b.P.rows > static_cast<int>(raw_xf.size()) || b.P.type() != CV_32F)
      throw std::invalid_argument("projection: a block beyond the raw channels, or not CV_32F");
    for (int c = 0; c < b.P.cols; ++c) {
      cv::Mat zc(raw_xf[0].size(), CV_32FC2, cv::Scalar::all(0));
      for (int d = 0; d < b.P.rows; ++d) cv::scaleAdd(raw_xf[b.first + d], b.P.at<float>(d, c), zc, zc);
      z.push_back(zc);
    }
  }
  return z;
}

double learn_projection(const std::vector<cv::Mat>& raw_xf, const cv::Mat& yf, const cv::Mat& w2,
                        double projection_reg, int gauss_newton_iterations, int cg_iterations,
                        std::vector<ProjectionBlock>& blocks, std::vector<cv::Mat>& filter) {
  // The variable of each linearised problem: the filter G and the projection's change dP.
  struct Step {
    Spectra g;
    std::vector<cv::Mat> dp;  // per block, CV_32F like its P
  };
  auto inner_step = [](const Step& a, const Step& b) {
    double s = inner(a.g, b.g);
    for (size_t i = 0; i < a.dp.size(); ++i) s += a.dp[i].dot(b.dp[i]);
    return s;
  };
  auto axpy = [](Step& y, double a, const Step& x) {  // y += a x
    for (size_t c = 0; c < y.g.size(); ++c) y.g[c] += a * x.g[c];
    for (size_t i = 0; i < y.dp.size(); ++i) y.dp[i] += a * x.dp[i];
  };
  const std::vector<double> one{1.0};
  double mu = -1;
  for (int gn = 0; gn < gauss_newton_iterations; ++gn) {
    const Spectra z = project_spectra(raw_xf, blocks);
    const std::vector<Sample> sample{Sample{z, yf}};
    check(sample, one, w2);
    if (filter.size() != z.size()) {  // the start: the filter of the starting projection
      filter.clear();
      train_joint_filter(sample, one, w2, cg_iterations, filter);
    }
    const Spectra fi = clones(filter);  // the linearisation point, fixed while x moves
    // The Jacobi preconditioner: |z^c|^2 + mean(w2) for G, sum_k |x^d G_i^c|^2 (+ mu) for dP.
    const Spectra diag_g = jacobi_diagonal(sample, one, w2);
    std::vector<cv::Mat> diag_dp;
    double dp_mean = 0;
    int dp_count = 0;
    for (size_t b = 0, c = 0; b < blocks.size(); ++b) {
      cv::Mat d(blocks[b].P.size(), CV_32F);
      for (int col = 0; col < blocks[b].P.cols; ++col, ++c) {
        cv::Mat f2, x2;
        cv::mulSpectrums(fi[c], fi[c], f2, 0, true);
        for (int r = 0; r < blocks[b].P.rows; ++r) {
          cv::mulSpectrums(raw_xf[blocks[b].first + r], raw_xf[blocks[b].first + r], x2, 0, true);
          d.at<float>(r, col) = static_cast<float>(x2.dot(f2));  // sum_k |x|^2 |G_i|^2 (real parts)
        }
      }
      dp_mean += cv::sum(d)[0];
      dp_count += static_cast<int>(d.total());
      diag_dp.push_back(d);
    }
    if (mu < 0) mu = projection_reg * dp_mean / std::max(1, dp_count);  // fixed at the start
    for (auto& d : diag_dp) d += mu;

    // A^H A (g, dp) and A^H y, A(g, dp) = sum_c z^c g^c + sum_c G_i^c (dP^T X)^c.
    auto forward = [&](const Step& v) {
      cv::Mat s(yf.size(), CV_32FC2, cv::Scalar::all(0)), prod;
      for (size_t c = 0; c < z.size(); ++c) {
        cv::mulSpectrums(z[c], v.g[c], prod, 0);
        s += prod;
      }
      std::vector<ProjectionBlock> moves;
      for (size_t b = 0; b < blocks.size(); ++b) moves.push_back({blocks[b].first, v.dp[b]});
      const Spectra u = project_spectra(raw_xf, moves);
      for (size_t c = 0; c < z.size(); ++c) {
        cv::mulSpectrums(fi[c], u[c], prod, 0);
        s += prod;
      }
      return s;
    };
    auto adjoint = [&](const cv::Mat& s, const Step* v) {  // A^H s (+ the regularisers of v)
      Step out{zeros_like(z), {}};
      for (size_t c = 0; c < z.size(); ++c) cv::mulSpectrums(s, z[c], out.g[c], 0, true);  // conj(z) s
      for (size_t b = 0, c = 0; b < blocks.size(); ++b) {
        cv::Mat d(blocks[b].P.size(), CV_32F);
        for (int col = 0; col < blocks[b].P.cols; ++col, ++c) {
          cv::Mat t;
          cv::mulSpectrums(s, fi[c], t, 0, true);  // conj(G_i) s
          for (int r = 0; r < blocks[b].P.rows; ++r)
            d.at<float>(r, col) = static_cast<float>(raw_xf[blocks[b].first + r].dot(t));  // Re <x, t>
        }
        out.dp.push_back(d);
      }
      if (v) {
        add_regularisation(w2, v->g, out.g);
        for (size_t b = 0; b < blocks.size(); ++b) out.dp[b] += mu * v->dp[b];
      }
      return out;
    };
    auto apply = [&](const Step& v) { return adjoint(forward(v), &v); };
    auto precondition = [&](const Step& r) {
      Step out{divided(r.g, diag_g), {}};
      for (size_t b = 0; b < blocks.size(); ++b) out.dp.push_back(r.dp[b] / diag_dp[b]);
      return out;
    };

    // From (G_i, 0): r = A^H y - mu P_i - A^H A (G_i, 0).
    Step x{clones(fi), {}};
    for (const auto& b : blocks) x.dp.push_back(cv::Mat::zeros(b.P.size(), CV_32F));
    Step r = adjoint(yf, nullptr);
    for (size_t b = 0; b < blocks.size(); ++b) r.dp[b] -= mu * blocks[b].P;
    axpy(r, -1, apply(x));
    conjugate_gradient(x, r, cg_iterations, apply, precondition, inner_step, axpy);
    filter = x.g;
    for (size_t b = 0; b < blocks.size(); ++b) blocks[b].P += x.dp[b];
  }
  return joint_objective(std::vector<Sample>{Sample{project_spectra(raw_xf, blocks), yf}}, one, w2, filter);
}

}  // namespace aerie::track
