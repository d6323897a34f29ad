#pragma once
// A smooth synthetic flight for the ESKF tests: sinusoids in position and in roll, pitch and
// yaw, with the IMU derived analytically (body rates from the ZYX Euler rates, specific force
// R^T (p'' - g)), optionally with white noise and random-walk biases as the filter models them,
// and the left camera's VO pose with a left SE(3) perturbation of a given covariance.
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <random>

#include "air/nav/eskf.hpp"

namespace aerie::nav::test {

struct TruthSample {
  double t = 0;
  Vec3 p, v, a;  // a: acceleration in the world (without gravity)
  Eigen::Quaterniond q;
  Vec3 omega_body;
};

// p(t) = (1.5 sin 0.8t, 1.0 cos 0.6t, 1.5 + 0.3 sin 1.1t); roll = 0.15 sin 0.9t,
// pitch = 0.12 sin 0.7t + 0.05, yaw = 0.6 sin 0.35t + 0.4 t (keeps turning).
inline TruthSample truth_at(double t) {
  TruthSample s;
  s.t = t;
  s.p = Vec3(1.5 * std::sin(0.8 * t), 1.0 * std::cos(0.6 * t), 1.5 + 0.3 * std::sin(1.1 * t));
  s.v = Vec3(1.2 * std::cos(0.8 * t), -0.6 * std::sin(0.6 * t), 0.33 * std::cos(1.1 * t));
  s.a = Vec3(-0.96 * std::sin(0.8 * t), -0.36 * std::cos(0.6 * t), -0.363 * std::sin(1.1 * t));
  const double phi = 0.15 * std::sin(0.9 * t), dphi = 0.135 * std::cos(0.9 * t);
  const double th = 0.12 * std::sin(0.7 * t) + 0.05, dth = 0.084 * std::cos(0.7 * t);
  const double psi = 0.6 * std::sin(0.35 * t) + 0.4 * t, dpsi = 0.21 * std::cos(0.35 * t) + 0.4;
  s.q = Eigen::Quaterniond(Eigen::AngleAxisd(psi, Vec3::UnitZ()) * Eigen::AngleAxisd(th, Vec3::UnitY()) *
                           Eigen::AngleAxisd(phi, Vec3::UnitX()));
  // Body rates of R = Rz(psi) Ry(theta) Rx(phi).
  s.omega_body = Vec3(dphi - dpsi * std::sin(th), dth * std::cos(phi) + dpsi * std::cos(th) * std::sin(phi),
                      -dth * std::sin(phi) + dpsi * std::cos(th) * std::cos(phi));
  return s;
}

inline NominalState truth_state(double t, int64_t utime) {
  const TruthSample s = truth_at(t);
  NominalState x;
  x.utime = utime;
  x.p = s.p;
  x.v = s.v;
  x.q = s.q;
  return x;
}

// Exact IMU sample (no noise, no bias) at time t.
inline ImuSample exact_imu(double t, int64_t utime, double g = 9.81) {
  const TruthSample s = truth_at(t);
  ImuSample m;
  m.utime = utime;
  m.gyro = s.omega_body;
  m.accel = s.q.toRotationMatrix().transpose() * (s.a + Vec3(0, 0, g));
  return m;
}

// Simulated IMU with the filter's own noise model: white noise of density sigma (per-sample
// std sigma / sqrt(dt)) and random-walk biases (std sigma_w sqrt(dt) per step).
class NoisyImu {
 public:
  NoisyImu(const EskfParams& p, const Vec3& bg0, const Vec3& ba0, uint64_t seed)
      : p_(p), bg_(bg0), ba_(ba0), rng_(seed) {}
  ImuSample sample(double t, int64_t utime, double dt) {
    if (dt > 0) {
      bg_ += p_.gyro_random_walk * std::sqrt(dt) * gauss3();
      ba_ += p_.accel_random_walk * std::sqrt(dt) * gauss3();
    }
    ImuSample m = exact_imu(t, utime, p_.gravity_m_s2);
    const double rate_dt = dt > 0 ? dt : 0.005;
    m.gyro += bg_ + p_.gyro_noise_density / std::sqrt(rate_dt) * gauss3();
    m.accel += ba_ + p_.accel_noise_density / std::sqrt(rate_dt) * gauss3();
    return m;
  }
  const Vec3& bg() const { return bg_; }
  const Vec3& ba() const { return ba_; }
  Vec3 gauss3() { return Vec3(n_(rng_), n_(rng_), n_(rng_)); }
  std::mt19937_64& rng() { return rng_; }

 private:
  EskfParams p_;
  Vec3 bg_, ba_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> n_{0.0, 1.0};
};

// The left camera's true pose in the VO frame.
inline geometry::SE3 true_vo_pose(double t, const EskfParams& p) {
  const TruthSample s = truth_at(t);
  return p.T_world_vo.inverse() * geometry::SE3(s.q, s.p) * p.T_body_cam;
}

// A VO pose with xi ~ N(0, cov): T_measured = Exp(xi) T_true (pose_t's convention).
inline geometry::SE3 perturb(const geometry::SE3& T, const Mat6& cov, std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Matrix<double, 6, 1> z;
  for (int i = 0; i < 6; ++i) z[i] = n(rng);
  const Mat6 L = cov.llt().matrixL();
  return geometry::SE3::exp(L * z) * T;
}

// The 15-dof error of an estimate against the truth, attitude local: q_true = q (x) Exp(dtheta).
inline Eigen::Matrix<double, 15, 1> error_state(const NominalState& est, const Vec3& p, const Vec3& v,
                                                const Eigen::Quaterniond& q, const Vec3& bg, const Vec3& ba) {
  Eigen::Matrix<double, 15, 1> e;
  e.segment<3>(kP) = p - est.p;
  e.segment<3>(kV) = v - est.v;
  const Eigen::AngleAxisd aa(est.q.conjugate() * q);
  e.segment<3>(kTheta) = aa.angle() * aa.axis();
  e.segment<3>(kBg) = bg - est.bg;
  e.segment<3>(kBa) = ba - est.ba;
  return e;
}

// Quantile of chi-square with k dof (Wilson-Hilferty; within 0.1 % for k >= 100), z = normal quantile.
inline double chi2_quantile(double k, double z) {
  const double c = 2.0 / (9.0 * k);
  return k * std::pow(1.0 - c + z * std::sqrt(c), 3);
}

}  // namespace aerie::nav::test
