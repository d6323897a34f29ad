#pragma once
// A multirotor for heading and forward flight (thesis 5.1.5, "UAV Model"): the
// autopilot's yaw-rate and horizontal-velocity loops as first-order responses, with
// parameters for an AR.Drone-class and a Pelican-class vehicle.
//
// Frame: x right, y forward (toward the wall), in metres, seen from above. Heading is
// in degrees, 0 along +y, positive clockwise (turning right), as compasses and the
// thesis' "Right" sets; yaw rate is the rate of that heading.
#include <string>

namespace aerie::sim {

struct VehicleParams {
  std::string name;
  double yaw_time_constant_s = 0.25;       // yaw rate -> commanded yaw rate, first order
  double max_yaw_rate_deg_s = 100.0;       // the autopilot saturates commands to this
  double velocity_time_constant_s = 0.7;   // horizontal velocity -> commanded, first order (attitude + drag)
  double command_delay_s = 0.06;           // link + autopilot latency before a command acts

  // Representative values for the two vehicle classes the thesis flies/simulates
  // (docs/control.md); first-order approximations, not identified here.
  static VehicleParams ar_drone();
  static VehicleParams pelican();
  static VehicleParams by_name(const std::string& name);  // "ardrone" | "pelican"; throws
};

struct VehicleState {
  double x = 0.0, y = 0.0;            // m
  double vx = 0.0, vy = 0.0;          // m/s, world frame
  double heading_deg = 0.0;
  double yaw_rate_deg_s = 0.0;
};

class Vehicle {
 public:
  Vehicle(const VehicleParams& params, double dt_s, const VehicleState& initial = {});

  // One step of dt with a yaw-rate command (deg/s, saturated to the vehicle's limit), a
  // forward-speed command (m/s along the heading) and an external yaw-rate disturbance
  // (deg/s, e.g. gusts). The first-order lags are discretised exactly for a command
  // held over the step (heading included); positions by the trapezoidal rule.
  void step(double yaw_rate_cmd_deg_s, double forward_speed_cmd_m_s, double yaw_disturbance_deg_s = 0.0);

  const VehicleState& state() const { return s_; }
  const VehicleParams& params() const { return p_; }
  double dt() const { return dt_; }

 private:
  VehicleParams p_;
  double dt_;
  double yaw_decay_, vel_decay_;  // exp(-dt / tau)
  VehicleState s_;
};

}  // namespace aerie::sim
