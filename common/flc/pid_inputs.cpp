#include "common/flc/pid_inputs.hpp"

#include <cmath>

namespace aerie::flc {

double wrap_deg(double a) {
  a = std::fmod(a + 180.0, 360.0);
  if (a < 0.0) a += 360.0;
  return a - 180.0;
}

std::array<double, 3> ErrorSignals::update(double t_s, double heading_deg, double reference_deg) {
  const double e = wrap_deg(reference_deg - heading_deg);
  if (!started_) {
    last_ = {e, 0.0, 0.0};
    started_ = true;
  } else if (t_s > t_) {
    const double dt = t_s - t_;
    // The difference of two wrapped errors is wrapped too, so crossing +-180 is no jump.
    last_ = {e, wrap_deg(e - last_[0]) / dt, last_[2] + e * dt};
  } else {
    last_[0] = e;
    return last_;
  }
  t_ = t_s;
  return last_;
}

}  // namespace aerie::flc
