#pragma once
// A MEMS IMU: gyroscope and accelerometer with white noise and random-walk biases
// (the continuous-time model of Kalibr / EuRoC's sensor.yaml), sampled at a fixed rate,
// plus the autopilot's attitude estimate (an AHRS with a slowly wandering error).
// Defaults: ADIS16448 as in EuRoC's sensor.yaml.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <random>

namespace aerie::sim {

struct ImuParams {
  double rate_hz = 200.0;
  double gyro_noise_density = 1.6968e-4;    // rad/s/sqrt(Hz)
  double gyro_random_walk = 1.9393e-5;      // rad/s^2/sqrt(Hz)
  double accel_noise_density = 2.0e-3;      // m/s^2/sqrt(Hz)
  double accel_random_walk = 3.0e-3;        // m/s^3/sqrt(Hz)
  double gyro_initial_bias = 0.003;         // rad/s, std of each axis' bias at start
  double accel_initial_bias = 0.05;         // m/s^2
  double attitude_error_deg = 0.3;          // AHRS roll/pitch error (std, slowly varying)
  double heading_error_deg = 2.0;           // AHRS yaw error (std, slowly varying)
  double attitude_error_time_constant_s = 20.0;
  void validate() const;  // throws std::invalid_argument naming the field
};

struct ImuSample {
  double t = 0.0;
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();   // rad/s, body
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();  // m/s^2, specific force, body
  Eigen::Quaterniond attitude = Eigen::Quaterniond::Identity();  // AHRS estimate, body -> world
};

class Imu {
 public:
  Imu(const ImuParams& params, uint64_t seed);
  // One sample from the true body motion at time t: rotation body -> world, angular
  // velocity (body) and acceleration (world, without gravity).
  ImuSample sample(double t, const Eigen::Quaterniond& q_world_body, const Eigen::Vector3d& omega_body,
                   const Eigen::Vector3d& accel_world);
  const Eigen::Vector3d& gyro_bias() const { return bg_; }
  const Eigen::Vector3d& accel_bias() const { return ba_; }
  const ImuParams& params() const { return p_; }

 private:
  Eigen::Vector3d gauss3(double sigma);
  ImuParams p_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> n01_{0.0, 1.0};
  Eigen::Vector3d bg_, ba_, att_err_;  // biases; AHRS error (roll, pitch, yaw, rad)
};

}  // namespace aerie::sim
