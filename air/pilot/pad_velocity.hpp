#pragma once
// The landing pad's horizontal velocity from the tracked pad's successive poses (issue 50 §2:
// the pilot follows a moving platform). The pilot sees the pad relative to itself; its own
// motion it knows only as what it commanded, so the vehicle's velocity is modelled as the
// autopilot's first-order response to the commands (multirotor.hpp: tau = the horizontal
// velocity loop's time constant) and dead-reckoned in the AHRS's level frame (x, y of the
// world up to the AHRS's heading offset, which a velocity estimate does not mind):
//   x_v(t) = integral of v_v,  dv_v/dt = (R(yaw) v_cmd - v_v) / tau
// The pad's position in that frame, m_k = x_v(t_k) + R(yaw_k) r_k (r_k the pad relative to the
// vehicle, heading frame), is smoothed per axis by an alpha-beta filter (a steady-state
// constant-velocity Kalman filter):
//   predict  x- = x + v dt;   residual e = m - x-;   x = x- + alpha e;   v = v + beta e / dt
// with beta = alpha^2 / (2 - alpha) (critically damped, Kalata 1984). A gap longer than
// max_gap_s restarts it; the estimate is valid after min_updates updates.
#include <Eigen/Core>

#include <cstdint>

namespace aerie::pilot {

struct PadVelocityConfig {
  double alpha = 0.15;                 // position gain of the alpha-beta filter, (0, 1)
  double vehicle_time_constant_s = 0.7;  // the autopilot's horizontal velocity response (ardrone's)
  double max_gap_s = 0.5;              // no pose for this long: start again
  int min_updates = 10;                // updates before the estimate counts
  double beta() const { return alpha * alpha / (2.0 - alpha); }
  void validate() const;               // throws std::invalid_argument naming the field
};

class PadVelocityEstimator {
 public:
  explicit PadVelocityEstimator(PadVelocityConfig config = {});

  // The vehicle's commanded horizontal velocity (level frame, m/s) from time t_s on.
  void command(double t_s, const Eigen::Vector2d& v_cmd_level);
  // A pose of the pad at t_s: relative to the vehicle, level frame (m).
  void observe(double t_s, const Eigen::Vector2d& pad_rel_level);
  void reset();

  bool valid() const { return updates_ >= cfg_.min_updates; }
  Eigen::Vector2d velocity() const { return valid() ? v_ : Eigen::Vector2d::Zero(); }  // level frame, m/s
  int updates() const { return updates_; }
  const PadVelocityConfig& config() const { return cfg_; }

 private:
  void advance(double t_s);  // the vehicle's dead reckoning to t_s

  PadVelocityConfig cfg_;
  double t_dr_ = 0;          // time of the dead reckoning
  bool dr_started_ = false;
  Eigen::Vector2d cmd_ = Eigen::Vector2d::Zero(), vv_ = Eigen::Vector2d::Zero(), xv_ = Eigen::Vector2d::Zero();
  double t_obs_ = 0;
  int updates_ = 0;          // 0: no pose yet
  Eigen::Vector2d x_ = Eigen::Vector2d::Zero(), v_ = Eigen::Vector2d::Zero();
};

}  // namespace aerie::pilot
