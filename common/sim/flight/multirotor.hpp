#pragma once
// A multirotor in 3D as a companion computer sees it through its autopilot: the autopilot
// takes velocity commands in the heading frame (x forward, y left, z up) and a yaw rate,
// and follows them with first-order responses (thesis 5.1.5, "UAV Model", extended to the
// vertical axis), after a command latency. Wind acts through linear rotor drag on the
// air-relative velocity; the autopilot's velocity loops have integral action (as PX4's
// and ArduPilot's do), so a steady wind is rejected within seconds and gusts push the
// vehicle until the loops, and the pilot's outer loop, correct them. TAKEOFF, HOVER and LAND hold
// the position where they began on the autopilot's own odometry (the AR.Drone's optical
// flow), which drifts as a random walk.
// Roll and pitch follow the horizontal thrust the motion needs (small-angle multirotor
// kinematics, with the attitude loop's own lag), which tilts the cameras and shows in
// the IMU.
//
// World frame: x east, y north, z up (the World's). Yaw is counter-clockwise from +x
// (ENU); the commands' yaw rate follows control_cmd_t: positive = clockwise seen from
// above (turn right).
#include <Eigen/Core>

#include <cstdint>
#include <deque>
#include <limits>
#include <random>
#include <string>

#include "common/geometry/se3.hpp"
#include "common/sim/vehicle/vehicle.hpp"

namespace aerie::sim {

struct MultirotorParams {
  VehicleParams base;                 // yaw loop, horizontal velocity loop, command latency
  double vertical_time_constant_s = 0.5;  // vertical velocity -> commanded, first order
  double max_horizontal_speed_m_s = 2.0;  // the autopilot saturates commands to these
  double max_vertical_speed_m_s = 1.0;
  double max_tilt_deg = 25.0;         // horizontal acceleration limit = g tan(max tilt)
  double drag_per_s = 0.3;            // linear rotor drag: a = drag * (wind - v)
  double velocity_integral_per_s2 = 1.0;  // integral action of the autopilot's velocity loops (rejects steady wind)
  double position_hold_per_s = 1.0;   // TAKEOFF, HOVER and LAND hold the position where they began (gain, 1/s) ...
  double hold_drift_m_per_sqrt_s = 0.01;  // ... on the autopilot's own odometry (optical flow), which drifts
  double attitude_time_constant_s = 0.08;  // roll/pitch follow the thrust direction
  double takeoff_height_m = 2.5;      // TAKEOFF climbs to this height above the take-off point
  double takeoff_speed_m_s = 0.6;
  double land_speed_m_s = 0.4;        // LAND descends at this speed
  double radius_m = 0.25;             // rotor tips from the centre: collision sphere
  double max_touchdown_speed_m_s = 1.0;  // faster vertical contact is a crash
  // Offboard-loss failsafe: a VELOCITY command not renewed for this long is replaced by a
  // position hold (PX4's COM_OF_LOSS_T, default 1 s), so a dead flight manager does not fly
  // the vehicle on its last command. 0 = never.
  double command_timeout_s = 1.0;
  // The autopilot's height fence above the ground it started from (ArduPilot's FENCE_ALT_MAX,
  // PX4's GF_MAX_VER_DIST): a climb slows to a stop there. 0 = none; in a room FlightSim
  // caps it below the ceiling whatever it is.
  double max_height_m = 0;

  // The two vehicle classes of docs/control.md, with the vertical loop and frame sizes.
  static MultirotorParams by_name(const std::string& name);  // "ardrone" | "pelican"; throws
  void validate() const;  // throws std::invalid_argument naming the field
};

// What the autopilot is asked to do (decoded and validated from control_cmd_t).
struct AutopilotCommand {
  enum class Mode { Hover, Velocity, Takeoff, Land };
  Mode mode = Mode::Hover;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // heading frame, m/s
  double yaw_rate_deg_s = 0.0;                         // clockwise positive
};

struct MultirotorState {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();      // body origin, world
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();      // world
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();  // world, of the last step
  double yaw = 0.0;              // rad, ENU
  double yaw_rate = 0.0;         // rad/s, ENU (counter-clockwise)
  double roll = 0.0, pitch = 0.0;  // rad (body x forward, y left, z up; ZYX Euler)
  bool armed = false;            // motors running
  bool on_ground = true;

  // Body -> world.
  geometry::SE3 pose() const;
};

class Multirotor {
 public:
  Multirotor(const MultirotorParams& params, const MultirotorState& initial, uint64_t seed = 1);

  // Queues a command issued at time t_s; it acts from t_s + command latency on.
  void command(double t_s, const AutopilotCommand& cmd);
  // Advances by dt (s) to time t_s + dt with the given wind (world, m/s). Ground contact
  // is handled by the caller through set_contact() (it owns the world's geometry). An
  // external yaw-rate disturbance (deg/s, clockwise positive, e.g. gusts) adds to the
  // yaw loop's rate, as in the heading model (vehicle.hpp).
  void step(double t_s, double dt, const Eigen::Vector3d& wind, double yaw_disturbance_deg_s = 0.0);
  // The vehicle rests on a surface at height z_surface: vertical motion stops, and
  // horizontal motion and tilt too when disarmed.
  void set_contact(double z_surface);
  // Moves the vehicle with the surface it rests on (the moving platform carrying it).
  void carry(const Eigen::Vector3d& displacement) { s_.position += displacement; }
  // The highest world z the autopilot lets its feet climb to (the height fence); +inf = none.
  void set_ceiling(double z) { ceiling_z_ = z; }
  double ceiling() const { return ceiling_z_; }

  const MultirotorState& state() const { return s_; }
  const MultirotorParams& params() const { return p_; }
  const AutopilotCommand& active_command() const { return active_; }
  double takeoff_z() const { return takeoff_z_; }
  int64_t command_timeouts() const { return command_timeouts_; }  // offboard-loss holds

 private:
  MultirotorParams p_;
  MultirotorState s_;
  std::deque<std::pair<double, AutopilotCommand>> pending_;  // (time it acts, command)
  AutopilotCommand active_;
  double takeoff_z_ = 0.0;
  double ceiling_z_ = std::numeric_limits<double>::infinity();
  double active_since_s_ = 0.0;  // when the active command began to act
  int64_t command_timeouts_ = 0;
  Eigen::Vector3d velocity_integral_ = Eigen::Vector3d::Zero();  // m/s^2
  Eigen::Vector2d hold_ = Eigen::Vector2d::Zero();                // HOVER/LAND position to hold
  Eigen::Vector2d odometry_error_ = Eigen::Vector2d::Zero();      // the autopilot's position estimate - truth
  std::mt19937_64 rng_;
};

}  // namespace aerie::sim
