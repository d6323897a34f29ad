#include "common/sim/flight/dryden.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace aerie::sim {

namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kFt = 0.3048;  // m per ft

// The second-order filter (1 + sqrt(3) T s) / (1 + T s)^2 with gain K = sigma sqrt(T / pi), in
// controllable canonical form: A = [0 1; -1/T^2 -2/T], B = [0 1]^T, C = K/T^2 [1 sqrt(3) T].
// Noise intensity pi (see the header); stationary P = diag(pi T^3 / 4, pi T / 4).
struct Second {
  Eigen::Matrix2d Phi, P;
  Eigen::RowVector2d C;
};

Second second_order(double T, double sigma, double dt) {
  Second m;
  const Eigen::Matrix2d A{{0.0, 1.0}, {-1.0 / (T * T), -2.0 / T}};
  // A + I/T is nilpotent (double pole at -1/T): e^{A dt} = e^{-dt/T} (I + dt (A + I/T)).
  m.Phi = std::exp(-dt / T) * (Eigen::Matrix2d::Identity() + dt * (A + Eigen::Matrix2d::Identity() / T));
  m.P = Eigen::Matrix2d{{kPi * T * T * T / 4.0, 0.0}, {0.0, kPi * T / 4.0}};
  const double K = sigma * std::sqrt(T / kPi);
  m.C = K / (T * T) * Eigen::RowVector2d(1.0, std::sqrt(3.0) * T);
  return m;
}

Eigen::Vector2d gauss2(std::mt19937_64& rng, const Eigen::Matrix2d& cov) {
  std::normal_distribution<double> n01(0.0, 1.0);
  const double a = n01(rng);
  const double b = n01(rng);
  const Eigen::LLT<Eigen::Matrix2d> llt(cov);
  if (llt.info() != Eigen::Success) return Eigen::Vector2d::Zero();  // dt = 0: no noise
  return llt.matrixL() * Eigen::Vector2d(a, b);
}

double airspeed_floor(double v) { return std::max(v, 0.1); }
}  // namespace

DrydenScales dryden_low_altitude(double height_m, double w20_m_s) {
  const double h = std::clamp(height_m / kFt, 10.0, 1000.0);  // ft
  const double d = 0.177 + 0.000823 * h;
  DrydenScales s;
  s.sigma_w = 0.1 * w20_m_s;
  s.sigma_u = s.sigma_v = s.sigma_w / std::pow(d, 0.4);
  s.L_w = h * kFt;
  s.L_u = s.L_v = h / std::pow(d, 1.2) * kFt;
  return s;
}

double dryden_autocorrelation_u(const DrydenScales& s, double V, double tau) {
  return s.sigma_u * s.sigma_u * std::exp(-V * std::abs(tau) / s.L_u);
}

double dryden_autocorrelation_v(const DrydenScales& s, double V, double tau) {
  const double x = V * std::abs(tau) / s.L_v;
  return s.sigma_v * s.sigma_v * (1.0 - 0.5 * x) * std::exp(-x);
}

DrydenGusts::DrydenGusts(uint64_t seed) : rng_(seed) {}

void DrydenGusts::start(const DrydenScales& s, double airspeed_m_s) {
  const double V = airspeed_floor(airspeed_m_s);
  std::normal_distribution<double> n01(0.0, 1.0);
  u_ = s.sigma_u * n01(rng_);
  const Second v = second_order(s.L_v / V, s.sigma_v, 0.0), w = second_order(s.L_w / V, s.sigma_w, 0.0);
  xv_ = gauss2(rng_, v.P);
  xw_ = gauss2(rng_, w.P);
  value_ = {u_, v.C * xv_, w.C * xw_};
}

Eigen::Vector3d DrydenGusts::step(double dt, const DrydenScales& s, double airspeed_m_s) {
  const double V = airspeed_floor(airspeed_m_s);
  std::normal_distribution<double> n01(0.0, 1.0);
  const double a = std::exp(-dt * V / s.L_u);
  u_ = a * u_ + s.sigma_u * std::sqrt(1.0 - a * a) * n01(rng_);
  const Second v = second_order(s.L_v / V, s.sigma_v, dt), w = second_order(s.L_w / V, s.sigma_w, dt);
  xv_ = v.Phi * xv_ + gauss2(rng_, v.P - v.Phi * v.P * v.Phi.transpose());
  xw_ = w.Phi * xw_ + gauss2(rng_, w.P - w.Phi * w.P * w.Phi.transpose());
  value_ = {u_, v.C * xv_, w.C * xw_};
  return value_;
}

}  // namespace aerie::sim
