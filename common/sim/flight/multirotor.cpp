#include "common/sim/flight/multirotor.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace aerie::sim {

namespace {
constexpr double kG = 9.81;
constexpr double kDeg = std::numbers::pi / 180.0;

// First-order step towards `target` over dt with time constant tau (exact for a held target).
double lag(double value, double target, double dt, double tau) {
  return target + (value - target) * std::exp(-dt / tau);
}
}  // namespace

MultirotorParams MultirotorParams::by_name(const std::string& name) {
  MultirotorParams p;
  p.base = VehicleParams::by_name(name);
  if (p.base.name == "pelican") {
    // 1.6 kg, 0.65 m across: slower vertical and attitude loops, lower drag per mass.
    p.vertical_time_constant_s = 0.7;
    p.max_horizontal_speed_m_s = 3.0;
    p.max_tilt_deg = 30.0;
    p.drag_per_s = 0.2;
    p.attitude_time_constant_s = 0.12;
    p.radius_m = 0.33;
  } else {
    // AR.Drone-class: 0.4 kg, 0.52 m across with the indoor hull.
    p.vertical_time_constant_s = 0.5;
    p.max_horizontal_speed_m_s = 2.0;
    p.max_tilt_deg = 25.0;
    p.drag_per_s = 0.35;
    p.attitude_time_constant_s = 0.08;
    p.radius_m = 0.26;
  }
  return p;
}

void MultirotorParams::validate() const {
  auto need = [&](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument("vehicle '" + base.name + "': " + what);
  };
  need(base.yaw_time_constant_s > 0 && base.velocity_time_constant_s > 0 && vertical_time_constant_s > 0 &&
           attitude_time_constant_s > 0,
       "time constants must be > 0");
  need(base.max_yaw_rate_deg_s > 0 && max_horizontal_speed_m_s > 0 && max_vertical_speed_m_s > 0,
       "speed and yaw-rate limits must be > 0");
  need(max_tilt_deg > 0 && max_tilt_deg < 60, "max_tilt_deg must be in (0, 60)");
  need(drag_per_s >= 0 && base.command_delay_s >= 0 && velocity_integral_per_s2 >= 0 && position_hold_per_s >= 0 &&
           hold_drift_m_per_sqrt_s >= 0,
       "drag_per_s, velocity_integral_per_s2, position_hold_per_s, hold_drift_m_per_sqrt_s and command_delay_s "
       "must be >= 0");
  need(takeoff_height_m > 0 && takeoff_speed_m_s > 0 && land_speed_m_s > 0, "take-off and landing figures must be > 0");
  need(radius_m > 0 && max_touchdown_speed_m_s > 0, "radius_m and max_touchdown_speed_m_s must be > 0");
  need(command_timeout_s >= 0, "command_timeout_s must be >= 0 (0 = never)");
  need(max_height_m >= 0, "max_height_m must be >= 0 (0 = no height fence)");
}

geometry::SE3 MultirotorState::pose() const {
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  return {R, position};
}

Multirotor::Multirotor(const MultirotorParams& params, const MultirotorState& initial, uint64_t seed)
    : p_(params), s_(initial), rng_(seed) {
  p_.validate();
  takeoff_z_ = s_.position.z();
  hold_ = s_.position.head<2>();
}

void Multirotor::command(double t_s, const AutopilotCommand& cmd) {
  pending_.emplace_back(t_s + p_.base.command_delay_s, cmd);
}

void Multirotor::step(double t_s, double dt, const Eigen::Vector3d& wind, double yaw_disturbance_deg_s) {
  if (!(dt > 0)) throw std::invalid_argument("Multirotor::step: dt must be > 0");
  while (!pending_.empty() && pending_.front().first <= t_s + 1e-9) {
    const bool holds = active_.mode != AutopilotCommand::Mode::Velocity;
    const auto next = pending_.front().second;
    pending_.pop_front();
    // A holding mode keeps the point where it began (a repeated one keeps the first).
    if (next.mode != active_.mode || !holds) hold_ = s_.position.head<2>() + odometry_error_;
    active_ = next;
    active_since_s_ = t_s;
  }
  if (active_.mode == AutopilotCommand::Mode::Velocity && p_.command_timeout_s > 0 &&
      t_s - active_since_s_ > p_.command_timeout_s + 1e-9) {
    active_ = AutopilotCommand{};  // hover where it is
    hold_ = s_.position.head<2>() + odometry_error_;
    ++command_timeouts_;
  }
  std::normal_distribution<double> n01(0.0, 1.0);
  // One draw per statement: a call's arguments are evaluated in an unspecified order (x86-64
  // GCC right to left, arm64 left to right); this is x86's order, now on every architecture.
  const double drift_y = n01(rng_), drift_x = n01(rng_);
  odometry_error_ += p_.hold_drift_m_per_sqrt_s * std::sqrt(dt) * Eigen::Vector2d(drift_x, drift_y);
  using Mode = AutopilotCommand::Mode;
  if (active_.mode == Mode::Takeoff && !s_.armed) {
    s_.armed = true;
    takeoff_z_ = s_.position.z();
  }
  if (!s_.armed) {  // resting, motors off
    velocity_integral_.setZero();
    s_.velocity.setZero();
    s_.acceleration.setZero();
    s_.yaw_rate = 0;
    s_.roll = s_.pitch = 0;
    return;
  }

  // Commanded world velocity and yaw rate for the active mode.
  const double c = std::cos(s_.yaw), s = std::sin(s_.yaw);
  auto to_world = [&](const Eigen::Vector3d& v) { return Eigen::Vector3d(c * v.x() - s * v.y(), s * v.x() + c * v.y(), v.z()); };
  Eigen::Vector3d v_cmd = Eigen::Vector3d::Zero();
  double yaw_rate_cmd = 0;  // rad/s, ENU
  const Eigen::Vector2d hold_velocity = p_.position_hold_per_s * (hold_ - (s_.position.head<2>() + odometry_error_));
  switch (active_.mode) {
    case Mode::Hover:
      v_cmd.head<2>() = hold_velocity;
      break;
    case Mode::Velocity:
      v_cmd = to_world(active_.velocity);
      yaw_rate_cmd = -active_.yaw_rate_deg_s * kDeg;
      break;
    case Mode::Takeoff: {
      v_cmd.head<2>() = hold_velocity;
      const double target_z = takeoff_z_ + p_.takeoff_height_m;
      v_cmd.z() = std::clamp(1.5 * (target_z - s_.position.z()), -p_.takeoff_speed_m_s, p_.takeoff_speed_m_s);
      break;
    }
    case Mode::Land:
      v_cmd = to_world({active_.velocity.x(), active_.velocity.y(), 0.0});
      v_cmd.head<2>() += hold_velocity;
      v_cmd.z() = -p_.land_speed_m_s;
      break;
  }
  // The autopilot's limits: the height fence (climbs slow to a stop at it, 1/s), the speeds.
  v_cmd.z() = std::min(v_cmd.z(), ceiling_z_ - s_.position.z());
  const double h = v_cmd.head<2>().norm();
  if (h > p_.max_horizontal_speed_m_s) v_cmd.head<2>() *= p_.max_horizontal_speed_m_s / h;
  v_cmd.z() = std::clamp(v_cmd.z(), -p_.max_vertical_speed_m_s, p_.max_vertical_speed_m_s);
  const double max_rate = p_.base.max_yaw_rate_deg_s * kDeg;
  yaw_rate_cmd = std::clamp(yaw_rate_cmd, -max_rate, max_rate);

  // Translational dynamics: the autopilot's first-order velocity loops plus rotor drag
  // on the air-relative velocity; the horizontal acceleration is bounded by the tilt limit.
  const double a_max = kG * std::tan(p_.max_tilt_deg * kDeg);
  const Eigen::Vector3d drag = p_.drag_per_s * (wind - s_.velocity);
  const Eigen::Vector3d v_err = v_cmd - s_.velocity;
  velocity_integral_ = (velocity_integral_ + p_.velocity_integral_per_s2 * v_err * dt).cwiseMax(-a_max).cwiseMin(a_max);
  Eigen::Vector3d a;
  a.head<2>() = v_err.head<2>() / p_.base.velocity_time_constant_s + drag.head<2>();
  a.z() = v_err.z() / p_.vertical_time_constant_s + drag.z();
  a += velocity_integral_;
  const double ah = a.head<2>().norm();
  if (ah > a_max) a.head<2>() *= a_max / ah;
  s_.acceleration = a;
  s_.velocity += a * dt;
  s_.position += s_.velocity * dt;

  s_.yaw_rate = lag(s_.yaw_rate, yaw_rate_cmd, dt, p_.base.yaw_time_constant_s);
  s_.yaw = std::remainder(s_.yaw + (s_.yaw_rate - yaw_disturbance_deg_s * kDeg) * dt, 2 * std::numbers::pi);

  // Attitude: body z along the thrust's specific force f = a - g - drag, expressed in the
  // heading frame: f ~ (cos(roll) sin(pitch), -sin(roll), cos(roll) cos(pitch)) for ZYX Euler.
  const Eigen::Vector3d f = a + Eigen::Vector3d(0, 0, kG) - drag;
  const Eigen::Vector3d fh(c * f.x() + s * f.y(), -s * f.x() + c * f.y(), f.z());
  const double roll_des = std::asin(std::clamp(-fh.y() / fh.norm(), -1.0, 1.0));
  const double pitch_des = std::atan2(fh.x(), fh.z());
  s_.roll = lag(s_.roll, roll_des, dt, p_.attitude_time_constant_s);
  s_.pitch = lag(s_.pitch, pitch_des, dt, p_.attitude_time_constant_s);
  if (s_.on_ground && s_.position.z() > takeoff_z_ + 1e-3 && s_.velocity.z() > 0) s_.on_ground = false;
}

void Multirotor::set_contact(double z_surface) {
  s_.position.z() = z_surface;
  if (s_.velocity.z() < 0) s_.velocity.z() = 0;
  s_.on_ground = true;
  if (active_.mode == AutopilotCommand::Mode::Land || !s_.armed) {
    s_.armed = false;  // the land detector disarms
    s_.velocity.setZero();
    s_.yaw_rate = 0;
    s_.roll = s_.pitch = 0;
    takeoff_z_ = z_surface;
  }
}

}  // namespace aerie::sim
