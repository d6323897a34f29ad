#include "common/sim/vehicle/avoidance.hpp"

#include <cmath>
#include <deque>
#include <numbers>
#include <random>
#include <stdexcept>

namespace aerie::sim {
namespace {
constexpr double kRad = std::numbers::pi / 180.0;

inline double wrap180(double a) {
  while (a >= 180.0) a -= 360.0;
  while (a < -180.0) a += 360.0;
  return a;
}
}  // namespace

CameraView look_at_wall(const Scene& scene, const CameraParams& camera, double /*x*/, double y, double heading_deg) {
  CameraView v;
  // Angle between the optical axis and the wall's normal (+y, into the wall).
  const double off = std::remainder(heading_deg, 360.0);
  const double c = std::cos(off * kRad);
  if (std::abs(off) > 0.5 * camera.fov_deg || c <= 0.0) return v;
  const double d = (scene.wall_y_m - y) / c;
  if (d < 0.0 || d > camera.range_m) return v;
  v.wall_visible = true;
  v.distance_m = d;
  v.reference_heading_deg = off >= 0.0 ? 90.0 : -90.0;
  return v;
}

void SettlingStats::add(double ta, double e, double dt) {
  itse_ += ta * e * e * dt;
  iae_ += std::abs(e) * dt;
  sq_sum_ += e * e * dt;
  time_ += dt;
  if (std::abs(e) > band_) {
    settle_time_ = ta + dt;
    sq_settle_ = sq_sum_;
    t_settle_ = time_;
  }
}

double SettlingStats::settle_time_s() const { return time_ - t_settle_ > 1e-9 && settle_time_ >= 0.0 ? settle_time_ : -1.0; }

double SettlingStats::steady_rmse_deg() const {
  return settle_time_s() >= 0.0 ? std::sqrt((sq_sum_ - sq_settle_) / (time_ - t_settle_)) : -1.0;
}

AvoidanceResult run_avoidance(const AvoidanceConfig& cfg, const HeadingControl& control, uint64_t seed) {
  if (!(cfg.speed_m_s > 0.0)) throw std::invalid_argument("avoidance: speed must be positive");
  if (!(cfg.sensor.rate_hz > 0.0) || cfg.physics_substeps < 1 || cfg.sensor.delay_s < 0.0)
    throw std::invalid_argument("avoidance: sensor rate must be positive, substeps >= 1, delay >= 0");
  const double dt = 1.0 / (cfg.sensor.rate_hz * cfg.physics_substeps);
  VehicleState start;
  start.vy = cfg.speed_m_s;  // already cruising at the start point
  Vehicle vehicle(cfg.vehicle, dt, start);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);

  // Heading history for the sensor latency (one entry per physics step).
  const auto delay_steps = static_cast<size_t>(std::lround(cfg.sensor.delay_s / dt));
  std::deque<double> history;
  // Commands in flight (time they act, value).
  std::deque<std::pair<double, double>> commands;
  const auto cmd_delay_steps = std::lround(cfg.vehicle.command_delay_s / dt);

  // The gust process is sampled at the sensor rate and held over the physics steps.
  const double gust_std = cfg.yaw_gust_std_per_speed * cfg.speed_m_s;
  const double gust_a = std::exp(-1.0 / (cfg.sensor.rate_hz * cfg.yaw_gust_time_constant_s));
  const double gust_b = gust_std * std::sqrt(1.0 - gust_a * gust_a);
  double gust = gust_std * gauss(rng);  // stationary from the start
  double drift = 0.0;
  const double drift_step = cfg.sensor.drift_deg_per_sqrt_s * std::sqrt(1.0 / cfg.sensor.rate_hz);

  AvoidanceResult res;
  double applied = 0.0, last_command = 0.0, measured = 0.0;
  SettlingStats settling(cfg.settle_band_deg);  // over the active phase
  const long max_steps = std::lround(cfg.max_time_s / dt);
  for (long k = 0;; ++k) {
    const double t = k * dt;
    const VehicleState& s = vehicle.state();
    history.push_back(s.heading_deg);
    if (history.size() > delay_steps + 1) history.pop_front();
    res.max_y_m = std::max(res.max_y_m, s.y);
    if (s.y >= cfg.scene.dangerous_from()) res.entered_dangerous = true;

    // Heading error and its integrals over the active phase (true heading).
    if (res.activated) settling.add(t - res.activation_time_s, wrap180(res.reference_deg - s.heading_deg), dt);
    // End of the run.
    if (s.y >= cfg.scene.wall_y_m) res.collided = true;
    if (std::abs(s.x) >= cfg.scene.lateral_limit_m) res.completed = true;
    if (k >= max_steps) res.timed_out = true;
    if (res.collided || res.completed || res.timed_out) {
      res.duration_s = t;
      break;
    }

    // A heading estimate (and a control period) every `physics_substeps` steps.
    if (k % cfg.physics_substeps == 0) {
      gust = gust_a * gust + gust_b * gauss(rng);
      drift += drift_step * gauss(rng);
      measured = history.front() + drift + cfg.sensor.noise_std_deg * gauss(rng);
      if (!res.activated && s.y >= cfg.scene.normal_area_m) {
        const CameraView view = look_at_wall(cfg.scene, cfg.camera, s.x, s.y, s.heading_deg);
        if (view.wall_visible) {
          res.activated = true;
          res.activation_time_s = t;
          res.reference_deg = view.reference_heading_deg + cfg.camera.angle_noise_std_deg * gauss(rng);
        }
      }
      if (res.activated) {
        last_command = control(t, measured, res.reference_deg);
        commands.emplace_back(t + static_cast<double>(cmd_delay_steps) * dt - 0.5 * dt, last_command);
      }
      if (cfg.record)
        res.trajectory.push_back({t, s.x, s.y, s.heading_deg, measured, res.reference_deg, last_command, res.activated});
    }
    while (!commands.empty() && commands.front().first <= t) {
      applied = commands.front().second;
      commands.pop_front();
    }
    vehicle.step(applied, cfg.speed_m_s, gust);
  }
  res.min_wall_distance_m = cfg.scene.wall_y_m - res.max_y_m;
  res.itse = settling.itse();
  res.iae = settling.iae();
  res.settle_time_s = settling.settle_time_s();
  res.steady_rmse_deg = settling.steady_rmse_deg();
  return res;
}

}  // namespace aerie::sim
