#include "air/pilot/landing_control.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace aerie::pilot {

bool AxisGains::valid() const {
  for (double v : {kp, ki, kd, ku, integral_limit, output_limit})
    if (!std::isfinite(v)) return false;
  return kp >= 0 && ki >= 0 && kd >= 0 && ku > 0 && integral_limit > 0 && output_limit > 0;
}

AxisController::AxisController(const AxisGains& g) : g_(g) {
  if (!g.valid())
    throw std::invalid_argument("axis gains: finite; kp, ki, kd >= 0; ku, integral_limit, output_limit > 0");
}

double AxisController::update(double t_s, double error) {
  if (!std::isfinite(error) || !std::isfinite(t_s)) throw std::invalid_argument("axis controller: error or time not finite");
  if (!started_) {
    started_ = true;
    derivative_ = 0;
    t_ = t_s;
    error_ = error;
  } else if (t_s > t_) {
    const double dt = t_s - t_;
    derivative_ = (error - error_) / dt;                                                   // backward difference
    integral_ = std::clamp(integral_ + error * dt, -g_.integral_limit, g_.integral_limit);  // rectangle rule
    t_ = t_s;
    error_ = error;
  }
  return std::clamp(law(error, derivative_, integral_), -g_.output_limit, g_.output_limit);
}

FuzzyAxis::FuzzyAxis(const flc::FlcSpec& base, const AxisGains& g) : AxisController(g), flc_(scaled(base, g)) {}

flc::FlcSpec FuzzyAxis::scaled(flc::FlcSpec spec, const AxisGains& g) {
  spec.set_parameter("Kp", g.kp);
  spec.set_parameter("Kd", g.kd);
  spec.set_parameter("Ki", g.ki);
  spec.set_parameter("Ku", g.ku);
  return spec;
}

std::unique_ptr<AxisController> make_axis(const std::string& kind, const flc::FlcSpec& fuzzy_base, const AxisGains& g) {
  if (kind == "fuzzy") return std::make_unique<FuzzyAxis>(fuzzy_base, g);
  if (kind == "pid") return std::make_unique<PidAxis>(g);
  throw std::invalid_argument("controller '" + kind + "' is unknown (expected fuzzy or pid)");
}

}  // namespace aerie::pilot
