#pragma once
// The moving landing platform of the field (issue 50 §2): the car carrying the helipad drives
// on flat ground, its displacement from where the World placed it a closed-form function of
// simulation time:
//   still:    d(t) = 0
//   straight: d(t) = v s(t) (cos psi, sin psi),  s = time driven since start_time_s
//   turning:  an arc of constant path rate omega: d(t) = v/omega (sin(psi + omega s) - sin psi,
//             cos psi - cos(psi + omega s)); the box stays axis-aligned (the World's obstacles are
//             axis-aligned boxes), so the car crabs round the arc without turning its body
//   braking:  straight at v until brake_time_s, then v - a (t - brake_time_s) down to a stop.
// psi is drawn from the seed along the car's length (either way) unless heading_deg is given.
#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <string>

namespace aerie::sim {

struct PlatformParams {
  std::string motion = "still";     // still | straight | turning | braking
  double speed_m_s = 0.0;           // speed at the start of the drive, [0, 5]
  double heading_deg = std::nan("");  // direction of travel, from +x towards +y; NaN: seeded along the car
  double start_time_s = 0.0;        // the car stands until this time
  double turn_rate_deg_s = 10.0;    // turning: rate of the path's direction (counter-clockwise > 0)
  double brake_time_s = 8.0;        // braking: brakes from this time on ...
  double deceleration_m_s2 = 1.5;   // ... at this rate, to a stop
  bool moving() const { return motion != "still" && speed_m_s > 0; }
  void validate() const;            // throws std::invalid_argument naming the field
};

class PlatformMotion {
 public:
  PlatformMotion() = default;
  // heading_rad: the direction of travel resolved (given or drawn).
  PlatformMotion(const PlatformParams& params, double heading_rad);
  // Horizontal displacement (m) and velocity (m/s) at time t (s).
  Eigen::Vector2d offset(double t) const;
  Eigen::Vector2d velocity(double t) const;
  double heading() const { return psi_; }

 private:
  double driven(double t) const;  // time driven since the start, braking: the distance / v
  PlatformParams p_;
  double psi_ = 0.0;
};

}  // namespace aerie::sim
