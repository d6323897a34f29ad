#include "air/control/control_loop.hpp"

#include <cmath>
#include <string>
#include <stdexcept>

#include "common/flc/pid_inputs.hpp"

namespace aerie::control {

void ControlConfig::validate() const {
  if (!std::isfinite(reference_deg)) throw std::invalid_argument("control: reference_deg must be finite");
  if (!(forward_speed_m_s >= 0.0 && forward_speed_m_s < 20.0)) throw std::invalid_argument("control: forward_speed_m_s must be in [0, 20)");
  if (!(activation_distance_m >= 0.0 && activation_distance_m <= 1000.0))
    throw std::invalid_argument("control: activation_distance_m must be in [0, 1000] m, got " +
                                std::to_string(activation_distance_m));
  if (!(stale_timeout_s > 0.0 && stale_timeout_s <= 60.0))
    throw std::invalid_argument("control: stale_timeout_s must be in (0, 60] s, got " + std::to_string(stale_timeout_s));
  if (!(max_input_age_s >= 0.0 && max_input_age_s <= 60.0))
    throw std::invalid_argument("control: max_input_age_s must be in [0, 60] s (0 = off), got " +
                                std::to_string(max_input_age_s));
  if (!(limits.max_yaw_rate_deg_s > 0.0 && limits.max_yaw_rate_deg_s <= 720.0))
    throw std::invalid_argument("control: limits.max_yaw_rate_deg_s must be in (0, 720] deg/s, got " +
                                std::to_string(limits.max_yaw_rate_deg_s));
  if (!(limits.max_yaw_accel_deg_s2 >= 0.0 && limits.max_yaw_accel_deg_s2 <= 10000.0))
    throw std::invalid_argument("control: limits.max_yaw_accel_deg_s2 must be in [0, 10000] deg/s^2, got " +
                                std::to_string(limits.max_yaw_accel_deg_s2));
}

ControlLoop::ControlLoop(flc::FlcSpec controller, ControlConfig config)
    : cfg_((config.validate(), config)), loop_(flc::Flc(std::move(controller)), cfg_.limits) {}

bool ControlLoop::stale(int64_t now_us) const {
  return !have_input_ || static_cast<double>(now_us - last_receive_) > cfg_.stale_timeout_s * 1e6;
}

bool ControlLoop::on_heading(int64_t utime, double heading_deg, int64_t receive_wall_us,
                             const std::optional<Eigen::Vector3d>& position, std::optional<double> age_s) {
  if (!std::isfinite(heading_deg) || (position && !position->allFinite())) return false;
  if (have_time_ && utime <= last_utime_) return false;
  have_time_ = true;
  last_utime_ = utime;
  if (!have_reference_) {
    reference_ = cfg_.reference_relative ? flc::wrap_deg(heading_deg + cfg_.reference_deg) : cfg_.reference_deg;
    have_reference_ = true;
    start_ = position;
    anchor_utime_ = utime;
  }
  // The turn starts at the end of the normal flight area; until then the FLC is not run
  // (as in aerie-ceopt's scenario) and the vehicle flies straight.
  if (!turning_)
    turning_ = cfg_.activation_distance_m <= 0.0 ||
               (position && start_ && (*position - *start_).norm() >= cfg_.activation_distance_m);
  // Too old to fly on: the FLC does not see it and the commands hover; the staleness clock
  // keeps running from the last fresh heading.
  aged_ = cfg_.max_input_age_s > 0 && age_s && *age_s > cfg_.max_input_age_s;
  if (aged_) return true;
  // Fresh input after none for stale_timeout_s: the derivative and integral start afresh.
  if (have_input_ && stale(receive_wall_us)) loop_.reset();
  const double u = turning_ ? loop_.update(static_cast<double>(utime) * 1e-6, heading_deg, reference_) : 0.0;
  have_input_ = true;
  last_receive_ = receive_wall_us;
  active_.mode = Mode::kActive;
  active_.yaw_rate_deg_s = u;
  active_.forward_speed_m_s = cfg_.forward_speed_m_s;
  active_.heading_deg = heading_deg;
  active_.reference_deg = reference_;
  active_.error_deg = turning_ ? loop_.inputs()[0] : flc::wrap_deg(reference_ - heading_deg);
  active_.source_utime = utime;
  return true;
}

std::optional<Anchor> ControlLoop::anchor() const {
  if (!have_reference_ || !start_) return std::nullopt;
  return Anchor{anchor_utime_, *start_, reference_};
}

void ControlLoop::resume(const Anchor& a) {
  if (!a.start.allFinite() || !std::isfinite(a.reference_deg))
    throw std::invalid_argument("control: an anchor must be finite");
  have_reference_ = true;
  start_ = a.start;
  reference_ = flc::wrap_deg(a.reference_deg);
  anchor_utime_ = a.utime;
  turning_ = false;  // from the next position
}

void ControlLoop::resync() {
  have_time_ = false;
  loop_.reset();
}

std::optional<std::string> ControlLoop::set_controller(const flc::FlcSpec& spec) {
  try {
    loop_.set_controller(flc::Flc(spec));
  } catch (const std::exception& e) {
    return std::string(e.what());
  }
  return std::nullopt;
}

Command ControlLoop::command(int64_t now_us) const {
  Command c = active_;
  c.controller_id = controller().id;
  if (!have_input_ && !aged_) {
    c = Command{};
    c.controller_id = controller().id;
    c.mode = Mode::kHover;
  } else if (!have_input_ || stale(now_us) || aged_) {
    c.mode = Mode::kFallbackHover;
    c.yaw_rate_deg_s = 0.0;
    c.forward_speed_m_s = 0.0;
  }
  return c;
}

}  // namespace aerie::control
