#include "common/sim/flight/imu.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace aerie::sim {

void ImuParams::validate() const {
  if (!(rate_hz > 0)) throw std::invalid_argument("imu.rate_hz must be > 0");
  for (double v : {gyro_noise_density, gyro_random_walk, accel_noise_density, accel_random_walk, gyro_initial_bias,
                   accel_initial_bias, attitude_error_deg, heading_error_deg})
    if (!(v >= 0)) throw std::invalid_argument("imu: noise densities, random walks and errors must be >= 0");
  if (!(attitude_error_time_constant_s > 0)) throw std::invalid_argument("imu.attitude_error_time_constant_s must be > 0");
}

Imu::Imu(const ImuParams& params, uint64_t seed) : p_(params), rng_(seed) {
  p_.validate();
  bg_ = gauss3(p_.gyro_initial_bias);
  ba_ = gauss3(p_.accel_initial_bias);
  constexpr double kDeg = std::numbers::pi / 180.0;
  att_err_ = Eigen::Vector3d(p_.attitude_error_deg, p_.attitude_error_deg, p_.heading_error_deg).cwiseProduct(gauss3(kDeg));
}

// One draw per statement: a call's arguments are evaluated in an unspecified order (x86-64
// GCC right to left, arm64 left to right); this is x86's order, now on every architecture.
Eigen::Vector3d Imu::gauss3(double sigma) {
  const double z = n01_(rng_), y = n01_(rng_), x = n01_(rng_);
  return sigma * Eigen::Vector3d(x, y, z);
}

ImuSample Imu::sample(double t, const Eigen::Quaterniond& q_wb, const Eigen::Vector3d& omega_body,
                      const Eigen::Vector3d& accel_world) {
  const double dt = 1.0 / p_.rate_hz;
  // Discrete white noise sigma_d = sigma_c / sqrt(dt); bias random walk sigma_c * sqrt(dt).
  bg_ += gauss3(p_.gyro_random_walk * std::sqrt(dt));
  ba_ += gauss3(p_.accel_random_walk * std::sqrt(dt));
  ImuSample s;
  s.t = t;
  s.gyro = omega_body + bg_ + gauss3(p_.gyro_noise_density / std::sqrt(dt));
  const Eigen::Vector3d specific_force_world = accel_world + Eigen::Vector3d(0, 0, 9.81);
  s.accel = q_wb.conjugate() * specific_force_world + ba_ + gauss3(p_.accel_noise_density / std::sqrt(dt));
  // AHRS error: first-order Gauss-Markov per axis with the configured stationary std.
  constexpr double kDeg = std::numbers::pi / 180.0;
  const double a = std::exp(-dt / p_.attitude_error_time_constant_s), k = std::sqrt(1 - a * a);
  const Eigen::Vector3d sigma(p_.attitude_error_deg * kDeg, p_.attitude_error_deg * kDeg, p_.heading_error_deg * kDeg);
  att_err_ = a * att_err_ + k * sigma.cwiseProduct(gauss3(1.0));
  const Eigen::Quaterniond err = Eigen::AngleAxisd(att_err_.z(), Eigen::Vector3d::UnitZ()) *
                                 Eigen::AngleAxisd(att_err_.y(), Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(att_err_.x(), Eigen::Vector3d::UnitX());
  s.attitude = (err * q_wb).normalized();
  return s;
}

}  // namespace aerie::sim
