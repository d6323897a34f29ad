#include "common/flc/heading_loop.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace aerie::flc {

HeadingLoop::HeadingLoop(Flc flc, CommandLimits limits) : flc_(std::move(flc)), limits_(limits) {
  if (!(limits_.max_yaw_rate_deg_s > 0.0) || !(limits_.max_yaw_accel_deg_s2 >= 0.0))
    throw std::invalid_argument("heading loop: max_yaw_rate_deg_s must be > 0 and max_yaw_accel_deg_s2 >= 0");
}

void HeadingLoop::reset() {
  signals_.reset();
  started_ = false;
  command_ = 0.0;
}

double HeadingLoop::update(double t_s, double heading_deg, double reference_deg) {
  if (!std::isfinite(t_s) || !std::isfinite(heading_deg) || !std::isfinite(reference_deg))
    throw std::invalid_argument("heading loop: time, heading and reference must be finite");
  const auto x = signals_.update(t_s, heading_deg, reference_deg);
  double u = flc_.evaluate(x[0], x[1], x[2]);
  u = std::clamp(u, -limits_.max_yaw_rate_deg_s, limits_.max_yaw_rate_deg_s);
  if (limits_.max_yaw_accel_deg_s2 > 0.0 && started_ && t_s > t_) {
    const double step = limits_.max_yaw_accel_deg_s2 * (t_s - t_);
    u = std::clamp(u, command_ - step, command_ + step);
  }
  started_ = true;
  t_ = t_s;
  command_ = u;
  return u;
}

}  // namespace aerie::flc
