#pragma once
// The heading control loop around the FLC: the three inputs from the heading stream
// (ErrorSignals), the FLC's yaw-rate command, and the command limits. The same code
// flies in aerie-control and is optimised in simulation by aerie-ceopt.
#include <array>

#include "common/flc/flc.hpp"
#include "common/flc/pid_inputs.hpp"

namespace aerie::flc {

struct CommandLimits {
  double max_yaw_rate_deg_s = 90.0;     // |command| <= this
  double max_yaw_accel_deg_s2 = 0.0;    // |change| <= this * dt between updates; 0 = no limit
};

class HeadingLoop {
 public:
  HeadingLoop(Flc flc, CommandLimits limits = {});

  // One control step at measurement time t_s: returns the limited yaw-rate command.
  // Throws std::invalid_argument (state unchanged) on a non-finite input.
  double update(double t_s, double heading_deg, double reference_deg);
  // A new controller; the error signals (derivative, integral) carry over.
  void set_controller(Flc flc) { flc_ = std::move(flc); }
  void reset();

  const Flc& flc() const { return flc_; }
  const std::array<double, 3>& inputs() const { return signals_.last(); }  // error, derivative, integral
  double command() const { return command_; }

 private:
  Flc flc_;
  CommandLimits limits_;
  ErrorSignals signals_;
  bool started_ = false;
  double t_ = 0.0, command_ = 0.0;
};

}  // namespace aerie::flc
