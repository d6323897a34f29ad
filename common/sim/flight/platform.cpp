#include "common/sim/flight/platform.hpp"

#include <algorithm>
#include <numbers>
#include <stdexcept>

namespace aerie::sim {

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;
}

void PlatformParams::validate() const {
  auto need = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("flight simulator: platform." + what);
  };
  need(motion == "still" || motion == "straight" || motion == "turning" || motion == "braking",
       "motion must be still, straight, turning or braking (got '" + motion + "')");
  need(speed_m_s >= 0 && speed_m_s <= 5, "speed_m_s must be in [0, 5]");
  need(std::isnan(heading_deg) || std::isfinite(heading_deg), "heading_deg must be finite (or unset)");
  need(start_time_s >= 0 && std::isfinite(start_time_s), "start_time_s must be >= 0");
  need(std::isfinite(turn_rate_deg_s) && std::abs(turn_rate_deg_s) <= 90 && (motion != "turning" || turn_rate_deg_s != 0),
       "turn_rate_deg_s must be in [-90, 90] and not 0 when turning");
  need(brake_time_s >= 0 && std::isfinite(brake_time_s), "brake_time_s must be >= 0");
  need(deceleration_m_s2 > 0 && deceleration_m_s2 <= 10, "deceleration_m_s2 must be in (0, 10]");
}

PlatformMotion::PlatformMotion(const PlatformParams& params, double heading_rad) : p_(params), psi_(heading_rad) {
  p_.validate();
}

double PlatformMotion::driven(double t) const {
  const double s = std::max(0.0, t - p_.start_time_s);
  if (p_.motion != "braking" || s <= p_.brake_time_s) return s;
  const double b = std::min(s - p_.brake_time_s, p_.speed_m_s / p_.deceleration_m_s2);  // braking time so far
  return p_.brake_time_s + b - 0.5 * p_.deceleration_m_s2 * b * b / p_.speed_m_s;
}

Eigen::Vector2d PlatformMotion::offset(double t) const {
  if (!p_.moving()) return Eigen::Vector2d::Zero();
  const double s = driven(t), v = p_.speed_m_s;
  if (p_.motion == "turning") {
    const double w = p_.turn_rate_deg_s * kDeg;
    return v / w * Eigen::Vector2d(std::sin(psi_ + w * s) - std::sin(psi_), std::cos(psi_) - std::cos(psi_ + w * s));
  }
  return v * s * Eigen::Vector2d(std::cos(psi_), std::sin(psi_));
}

Eigen::Vector2d PlatformMotion::velocity(double t) const {
  if (!p_.moving() || t < p_.start_time_s) return Eigen::Vector2d::Zero();
  const double s = t - p_.start_time_s;
  double v = p_.speed_m_s, psi = psi_;
  if (p_.motion == "braking" && s > p_.brake_time_s) v = std::max(0.0, v - p_.deceleration_m_s2 * (s - p_.brake_time_s));
  if (p_.motion == "turning") psi += p_.turn_rate_deg_s * kDeg * s;
  return v * Eigen::Vector2d(std::cos(psi), std::sin(psi));
}

}  // namespace aerie::sim
