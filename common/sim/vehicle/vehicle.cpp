#include "common/sim/vehicle/vehicle.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace aerie::sim {

VehicleParams VehicleParams::ar_drone() {
  // Light (0.4 kg) quadrotor flown over WiFi: quick yaw loop, firmware yaw-speed limit
  // 100 deg/s, velocity follows the commanded tilt within about a second.
  return {"ardrone", 0.25, 100.0, 0.7, 0.06};
}

VehicleParams VehicleParams::pelican() {
  // Heavier (1.6 kg) Asctec Pelican with an onboard computer: slower yaw and velocity
  // responses, lower yaw-rate limit, little command latency.
  return {"pelican", 0.4, 60.0, 1.2, 0.02};
}

VehicleParams VehicleParams::by_name(const std::string& name) {
  if (name == "ardrone" || name == "ar_drone" || name == "ar.drone") return ar_drone();
  if (name == "pelican") return pelican();
  throw std::invalid_argument("vehicle '" + name + "' is unknown (expected ardrone or pelican)");
}

Vehicle::Vehicle(const VehicleParams& params, double dt_s, const VehicleState& initial)
    : p_(params), dt_(dt_s), s_(initial) {
  if (!(dt_s > 0.0)) throw std::invalid_argument("vehicle time step must be positive");
  if (!(p_.yaw_time_constant_s > 0.0) || !(p_.velocity_time_constant_s > 0.0) || !(p_.max_yaw_rate_deg_s > 0.0) ||
      !(p_.command_delay_s >= 0.0))
    throw std::invalid_argument("vehicle '" + p_.name + "': time constants and yaw-rate limit must be positive, delay >= 0");
  yaw_decay_ = std::exp(-dt_ / p_.yaw_time_constant_s);
  vel_decay_ = std::exp(-dt_ / p_.velocity_time_constant_s);
}

void Vehicle::step(double yaw_rate_cmd_deg_s, double forward_speed_cmd_m_s, double yaw_disturbance_deg_s) {
  constexpr double kRad = std::numbers::pi / 180.0;
  const double cmd = std::clamp(yaw_rate_cmd_deg_s, -p_.max_yaw_rate_deg_s, p_.max_yaw_rate_deg_s);
  const double r0 = s_.yaw_rate_deg_s;
  const double r1 = cmd + (r0 - cmd) * yaw_decay_;
  // Exact integral of the first-order response over the step.
  const double turned = cmd * dt_ + (r0 - cmd) * p_.yaw_time_constant_s * (1.0 - yaw_decay_);
  s_.yaw_rate_deg_s = r1;
  s_.heading_deg += turned + yaw_disturbance_deg_s * dt_;

  const double h = s_.heading_deg * kRad;
  const double tx = forward_speed_cmd_m_s * std::sin(h), ty = forward_speed_cmd_m_s * std::cos(h);
  const double vx1 = tx + (s_.vx - tx) * vel_decay_, vy1 = ty + (s_.vy - ty) * vel_decay_;
  s_.x += 0.5 * (s_.vx + vx1) * dt_;
  s_.y += 0.5 * (s_.vy + vy1) * dt_;
  s_.vx = vx1;
  s_.vy = vy1;
}

}  // namespace aerie::sim
