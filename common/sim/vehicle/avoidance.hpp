#pragma once
// The collision-avoidance task of thesis 5.1.2/5.1.6 (Fig. 5.2): the vehicle flies at a
// constant forward speed toward a wall 5 m ahead; zones along the way: normal flight
// area (0-1 m), safe avoiding area (1-4 m, 3 m by default) and dangerous alarm area
// (4-5 m). On entering the safe avoiding area the virtual forward camera gives the
// angle reference (90 deg: parallel to the wall) and the heading controller turns the
// vehicle; the run ends when it has moved 5 m sideways (the thesis' X threshold).
//
// The controller sees the heading as the visual pipeline would deliver it: at the
// camera rate, late by the pipeline latency, with noise (and optionally drift).
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "common/sim/vehicle/vehicle.hpp"

namespace aerie::sim {

struct HeadingSensorParams {
  double rate_hz = 30.0;            // pose rate of the visual pipeline (thesis: PTAM at 30 Hz)
  double delay_s = 0.1;             // latency from frame to estimate at the controller
  double noise_std_deg = 0.5;       // white noise of each estimate
  double drift_deg_per_sqrt_s = 0.0;  // random-walk drift of the estimate (VO yaw drift)
};

struct CameraParams {
  double fov_deg = 92.0;            // horizontal field of view of the forward camera
  double range_m = 10.0;            // the wall is detected up to this distance along the axis
  double angle_noise_std_deg = 0.0; // noise of the measured wall angle (the reference)
};

struct Scene {
  double wall_y_m = 5.0;            // wall: the line y = wall_y, normal along y
  double normal_area_m = 1.0;       // normal flight area [0, normal_area)
  double safe_area_m = 3.0;         // safe avoiding area [normal_area, normal_area + safe_area)
  double lateral_limit_m = 5.0;     // the run ends after this sideways displacement
  double dangerous_from() const { return normal_area_m + safe_area_m; }
};

// What the virtual forward camera reports about the wall (thesis Fig. 5.12).
struct CameraView {
  bool wall_visible = false;
  double distance_m = 0.0;              // along the optical axis
  double reference_heading_deg = 0.0;   // heading parallel to the wall (the 90 deg reference)
};

// The wall seen from a pose: visible when its intersection with the optical axis is in
// range and the wall's normal is within half the field of view. The reference turns to
// the side the vehicle already points to (right when square on).
CameraView look_at_wall(const Scene& scene, const CameraParams& camera, double x, double y, double heading_deg);

struct AvoidanceConfig {
  VehicleParams vehicle = VehicleParams::ar_drone();
  Scene scene;
  HeadingSensorParams sensor;
  CameraParams camera;
  double speed_m_s = 0.6;                // constant forward speed
  int physics_substeps = 10;             // physics steps per sensor sample
  double max_time_s = 60.0;              // a run that has not ended by then times out
  // Gusts in forward flight: a yaw-rate disturbance (first-order Gauss-Markov) whose
  // standard deviation grows with the airspeed.
  double yaw_gust_std_per_speed = 3.0;   // (deg/s) per (m/s)
  double yaw_gust_time_constant_s = 0.5;
  double settle_band_deg = 4.5;          // steady state: after the error has entered this band for good (5 % of 90 deg)
  bool record = false;                   // keep the trajectory
};

// One control period's record.
struct AvoidanceSample {
  double t = 0.0, x = 0.0, y = 0.0;
  double heading_deg = 0.0;          // true
  double measured_heading_deg = 0.0; // what the controller saw
  double reference_deg = 0.0;
  double command_deg_s = 0.0;
  bool active = false;
};

struct AvoidanceResult {
  bool activated = false;      // the camera gave a reference in the safe avoiding area
  bool completed = false;      // reached the lateral limit
  bool collided = false;       // reached the wall
  bool entered_dangerous = false;
  bool timed_out = false;
  double activation_time_s = 0.0;
  double duration_s = 0.0;
  double reference_deg = 0.0;
  double itse = 0.0;           // integral of (t - t_activation) * error^2 dt, deg^2 s^2 (true heading)
  double iae = 0.0;            // integral of |error| dt
  double settle_time_s = -1.0; // from activation to the last time |error| > band; -1 if it never settled
  double steady_rmse_deg = -1.0;  // RMSE of the true heading from settling to the end; -1 if never settled
  double max_y_m = 0.0;
  double min_wall_distance_m = 0.0;
  std::vector<AvoidanceSample> trajectory;
};

// Settling and steady-state error of a heading response (thesis 5.1.6), from samples of the
// true heading error after the avoidance started: the settling time is the last time |error|
// is outside the band; the steady state is what follows it. Also the ITSE and IAE integrals.
class SettlingStats {
 public:
  explicit SettlingStats(double band_deg) : band_(band_deg) {}
  // The error (deg) at t_since_activation (s), held over the next dt (s).
  void add(double t_since_activation, double error_deg, double dt);
  double itse() const { return itse_; }
  double iae() const { return iae_; }
  // -1 when the error never entered the band for good, or only at the very end.
  double settle_time_s() const;
  double steady_rmse_deg() const;

 private:
  double band_;
  double itse_ = 0.0, iae_ = 0.0;
  double sq_sum_ = 0.0, time_ = 0.0, sq_settle_ = 0.0, t_settle_ = 0.0, settle_time_ = -1.0;
};

// The heading controller under test: called at each heading estimate with its time
// (s), the estimate (deg) and the reference (deg); returns a yaw-rate command (deg/s).
// Called only once the avoidance is active; a fresh controller per run.
using HeadingControl = std::function<double(double t_s, double heading_deg, double reference_deg)>;

// Runs one avoidance manoeuvre. Noise comes from `seed` alone, so a run is reproducible.
AvoidanceResult run_avoidance(const AvoidanceConfig& config, const HeadingControl& control, uint64_t seed);

}  // namespace aerie::sim
