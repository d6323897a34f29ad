#pragma once
// Dryden turbulence at low altitude (MIL-F-8785C §3.7.2.3 and MIL-HDBK-1797 App. A, h < 1000 ft):
// the gust velocities u (along the mean wind), v (across it, horizontal) and w (vertical) as
// white noise through the Dryden forming filters, with the low-altitude scales
//   sigma_w = 0.1 W20,  sigma_u / sigma_w = sigma_v / sigma_w = 1 / (0.177 + 0.000823 h)^0.4,
//   L_w = h,  L_u = L_v = h / (0.177 + 0.000823 h)^1.2          (h, L in ft; W20 = wind at 20 ft)
// and the forming filters (T = L / V, V the airspeed):
//   H_u(s) = sigma_u sqrt(2 L_u / (pi V)) / (1 + T_u s)
//   H_v(s) = sigma_v sqrt(L_v / (pi V)) (1 + sqrt(3) T_v s) / (1 + T_v s)^2   (H_w likewise)
// so that the one-sided PSDs Phi(omega) = |H(j omega)|^2 integrate over omega in [0, inf) to
// sigma^2. Discretised exactly at the step for a constant T: u as a first-order Gauss-Markov
// process, v and w as the second-order state x' = A x + B n with x_{k+1} = e^{A dt} x_k + q_k,
// q_k ~ N(0, P - e^{A dt} P e^{A dt}^T), P the stationary covariance (A P + P A^T + B pi B^T = 0).
// T follows the airspeed step by step (the frozen field advected past the vehicle, Taylor's
// hypothesis); the spec's altitude range is enforced by clamping h to [10, 1000] ft.
#include <Eigen/Core>

#include <cstdint>
#include <random>

namespace aerie::sim {

struct DrydenScales {
  double sigma_u = 0, sigma_v = 0, sigma_w = 0;  // m/s
  double L_u = 0, L_v = 0, L_w = 0;              // m
};

// The low-altitude scales at height_m (clamped to [10, 1000] ft) for a wind of w20_m_s at 20 ft.
DrydenScales dryden_low_altitude(double height_m, double w20_m_s);

// Autocorrelations of the model (m^2/s^2) at lag tau_s for airspeed V (m/s):
//   R_u(tau) = sigma_u^2 e^{-V tau / L_u},  R_v(tau) = sigma_v^2 (1 - V tau / (2 L_v)) e^{-V tau / L_v}.
double dryden_autocorrelation_u(const DrydenScales& s, double airspeed_m_s, double tau_s);
double dryden_autocorrelation_v(const DrydenScales& s, double airspeed_m_s, double tau_s);

class DrydenGusts {
 public:
  explicit DrydenGusts(uint64_t seed);
  // Draws the state from the stationary distribution for these scales and airspeed.
  void start(const DrydenScales& s, double airspeed_m_s);
  // Advances by dt (s); returns (u, v, w) in m/s.
  Eigen::Vector3d step(double dt, const DrydenScales& s, double airspeed_m_s);
  Eigen::Vector3d value() const { return value_; }

 private:
  std::mt19937_64 rng_;
  double u_ = 0;
  Eigen::Vector2d xv_ = Eigen::Vector2d::Zero(), xw_ = Eigen::Vector2d::Zero();
  Eigen::Vector3d value_ = Eigen::Vector3d::Zero();
};

}  // namespace aerie::sim
