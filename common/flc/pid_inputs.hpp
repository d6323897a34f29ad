#pragma once
// The three FLC inputs from a stream of heading measurements (thesis 5.1.3): the
// heading error against the reference, its derivative (backward difference) and its
// integral (rectangle rule), over message time.
#include <array>

namespace aerie::flc {

// Wraps an angle in degrees to [-180, 180).
double wrap_deg(double a);

class ErrorSignals {
 public:
  // t_s: measurement time (s, any origin, increasing). Returns {error, derivative,
  // integral}; the first call after reset() has derivative 0 and integral 0. A
  // repeated or older time stamp changes neither the derivative nor the integral.
  std::array<double, 3> update(double t_s, double heading_deg, double reference_deg);
  void reset() { started_ = false; }
  const std::array<double, 3>& last() const { return last_; }

 private:
  bool started_ = false;
  double t_ = 0.0;
  std::array<double, 3> last_{};
};

}  // namespace aerie::flc
