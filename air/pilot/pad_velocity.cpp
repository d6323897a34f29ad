#include "air/pilot/pad_velocity.hpp"

#include <cmath>
#include <stdexcept>

namespace aerie::pilot {

void PadVelocityConfig::validate() const {
  auto need = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("pilot config: feedforward.") + what);
  };
  need(alpha > 0 && alpha < 1, "alpha must be in (0, 1)");
  need(vehicle_time_constant_s > 0 && std::isfinite(vehicle_time_constant_s), "vehicle_time_constant_s must be > 0");
  need(max_gap_s > 0 && std::isfinite(max_gap_s), "max_gap_s must be > 0");
  need(min_updates >= 2, "min_updates must be >= 2");
}

PadVelocityEstimator::PadVelocityEstimator(PadVelocityConfig config) : cfg_(config) { cfg_.validate(); }

void PadVelocityEstimator::reset() {
  updates_ = 0;
  x_.setZero();
  v_.setZero();
}

void PadVelocityEstimator::advance(double t) {
  if (!dr_started_) {
    dr_started_ = true;
    t_dr_ = t;
    return;
  }
  const double dt = t - t_dr_;
  if (!(dt > 0)) return;
  // Exact solution of the first-order response over dt for a constant command.
  const double a = std::exp(-dt / cfg_.vehicle_time_constant_s);
  xv_ += cmd_ * dt + (vv_ - cmd_) * cfg_.vehicle_time_constant_s * (1.0 - a);
  vv_ = cmd_ + (vv_ - cmd_) * a;
  t_dr_ = t;
}

void PadVelocityEstimator::command(double t_s, const Eigen::Vector2d& v) {
  if (!std::isfinite(t_s) || !v.allFinite()) throw std::invalid_argument("pad velocity: command not finite");
  advance(t_s);
  cmd_ = v;
}

void PadVelocityEstimator::observe(double t_s, const Eigen::Vector2d& rel) {
  if (!std::isfinite(t_s) || !rel.allFinite()) throw std::invalid_argument("pad velocity: pose not finite");
  advance(t_s);
  const Eigen::Vector2d m = xv_ + rel;
  const double dt = t_s - t_obs_;
  if (updates_ > 0 && !(dt > 0)) return;  // the same instant twice
  if (updates_ == 0 || dt > cfg_.max_gap_s) {
    x_ = m;
    v_.setZero();
    updates_ = 1;
  } else {
    const Eigen::Vector2d predicted = x_ + v_ * dt;
    const Eigen::Vector2d e = m - predicted;
    x_ = predicted + cfg_.alpha * e;
    v_ += cfg_.beta() / dt * e;
    ++updates_;
  }
  t_obs_ = t_s;
}

}  // namespace aerie::pilot
