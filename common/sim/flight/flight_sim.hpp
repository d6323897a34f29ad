#pragma once
// The closed-loop flight simulator (ARCHITECTURE.md, "Closing the loop"): a multirotor in
// the World that moves only by the commands it is given, and sensors rendered from its
// actual state — a down-looking mono camera (the thesis' landing camera, 376x240), an
// optional forward stereo pair, a 200 Hz IMU — plus the ground truth an evaluation needs.
// It knows nothing of LCM: a node (aerie-flightsim) or a bench steps it.
//
// Time: frame k is at t_k = k / frame_rate_hz; the physics and the IMU run at the IMU rate
// in between. Everything random (placement, wind, vibration, IMU, image noise) derives
// from the seed, so a run is a function of (config, seed, commands).
#include <Eigen/Core>

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "common/geometry/se3.hpp"
#include "common/sim/camera/camera_effects.hpp"
#include "common/sim/flight/dryden.hpp"
#include "common/sim/flight/imu.hpp"
#include "common/sim/flight/multirotor.hpp"
#include "common/sim/flight/platform.hpp"
#include "common/sim/stereo_renderer.hpp"
#include "common/sim/world.hpp"

namespace aerie::sim {

struct WindParams {
  double mean_m_s = 0.0;             // steady wind speed (direction drawn from the seed)
  // gauss_markov: the historical gusts (below; every earlier figure reproduces with it);
  // dryden: MIL-F-8785C / MIL-HDBK-1797 low-altitude Dryden turbulence (dryden.hpp), u, v, w.
  std::string model = "gauss_markov";
  double gust_std_m_s = -1.0;        // gauss_markov: gust standard deviation per horizontal axis; < 0: 0.3 * mean
  double gust_time_constant_s = 2.0; // gauss_markov: first-order Gauss-Markov time constant
  double w20_m_s = -1.0;             // dryden: wind speed at 20 ft (sigma_w = 0.1 W20); < 0: mean_m_s
  // Yaw-rate gusts in forward flight (thesis 5.1.5, as aerie-ceopt's scenario): first-order
  // Gauss-Markov, standard deviation growing with the horizontal speed; 0 = none.
  double yaw_gust_std_per_speed = 0.0;    // (deg/s) per (m/s)
  double yaw_gust_time_constant_s = 0.5;
  double gust_std() const { return gust_std_m_s < 0 ? 0.3 * mean_m_s : gust_std_m_s; }
};

struct VibrationParams {
  bool enabled = false;
  double amplitude_deg = 0.5;   // RMS jitter of the camera mount's attitude, per axis
  double frequency_hz = 15.0;   // centre frequency (two tones per axis at +-15 %)
};

struct PlacementParams {
  double pad_yaw_deg = -1;         // < 0: drawn from the seed in [0, 180)
  double start_distance_min_m = 1.0;  // take-off point's horizontal distance from the pad
  double start_distance_max_m = 2.5;
  double start_yaw_deg = 1e9;      // >= 1e9: drawn from the seed
  // A given start instead of a drawn one (both finite: x, y of the world); the column must be free.
  double start_x_m = std::nan(""), start_y_m = std::nan("");
  double start_height_m = 0.0;     // > 0: start armed, hovering this high above the ground (no take-off)
  bool given_start() const { return !std::isnan(start_x_m); }
  double clearance_radius_m = 2.0; // nothing within this of the take-off column at take-off height (room to search)
  double exposure_jitter = 0.15;   // lighting: camera exposure drawn in [1 - j, 1 + j]
};

// The calibration the down camera's images carry differs from the true intrinsics by a
// seeded error, as a real calibration does (1 sigma values).
struct CalibrationError {
  double focal_rel = 0.005;     // relative error of fx and fy (0.5 %)
  double principal_px = 1.0;    // error of cx and cy (px)
};

struct FlightSimConfig {
  WorldConfig world;
  MultirotorParams vehicle = MultirotorParams::by_name("ardrone");
  ImuParams imu;
  RigConfig down_camera = down_rig();
  CalibrationError calibration_error;  // of the intrinsics published with CAM_DOWN
  bool stereo = false;             // also render the forward stereo pair
  RigConfig stereo_rig;
  // Real camera effects on the rendered frames (common/sim/camera); default ideal (off): the
  // frames are today's, byte for byte. The stereo section applies to both forward cameras.
  CameraEffectsConfig down_effects, stereo_effects;
  double frame_rate_hz = 20.0;
  WindParams wind;
  VibrationParams vibration;
  PlacementParams placement;
  PlatformParams platform;         // the field's car driving (default still: today's world)
  double max_time_s = 120.0;       // the flight ends (timed out) after this
  uint64_t seed = 1;
  int64_t start_utime = 0;         // utime of frame 0

  static RigConfig down_rig();     // 376x240, 90 x 65 deg FOV, looking straight down
  void validate() const;           // throws std::invalid_argument naming the field
};

// A command as the autopilot receives it (control_cmd_t fields). Refused when a value is
// not finite, a velocity exceeds the vehicle's limits by more than 50 %, or the mode is
// unknown; the vehicle then holds (hovers) and the refusal is counted with its reason.
struct CommandInput {
  int mode = 0;                    // control_cmd_t: HOVER 0, ACTIVE 1, FALLBACK_HOVER 2, TAKEOFF 3, LAND 4
  std::array<double, 3> velocity{};  // heading frame, m/s
  double yaw_rate_deg_s = 0;       // clockwise positive
};

// How the flight ended (so far).
struct FlightOutcome {
  bool landed = false;             // disarmed on a surface after a touchdown
  bool collided = false;
  bool timed_out = false;
  std::string collision;           // what was hit and how
  double touchdown_time_s = -1;
  Eigen::Vector3d touchdown_position = Eigen::Vector3d::Zero();
  double touchdown_yaw = 0;        // rad, ENU
  double touchdown_vertical_speed = 0;  // m/s, positive down
  Eigen::Vector3d touchdown_pad_center = Eigen::Vector3d::Zero();  // the pad's centre at the touchdown (it may move)
  Eigen::Vector2d touchdown_pad_velocity = Eigen::Vector2d::Zero(); // the platform's velocity then, m/s
  bool ended() const { return landed || collided || timed_out; }
};

// A landing judged as the landing issue defines success: landed (disarmed after a
// touchdown) within the time limit, no collision, the pad centre within max_error_m of
// the touchdown point (horizontally) and the yaw within max_yaw_deg of the pad's (modulo
// the H's half turn).
struct LandingScore {
  bool success = false;
  double touchdown_error_m = std::nan("");
  double yaw_error_deg = std::nan("");
  double time_s = std::nan("");
};

// The target's true pose in a camera's optical frame (what TARGET_POSE estimates).
struct TargetTruth {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // pad centre, m
  double yaw = 0;  // pad x axis from image x towards image y, rad, in (-pi/2, pi/2] (the H is symmetric)
};

struct FlightFrame {
  int64_t seq = 0;
  double t = 0;
  int64_t utime = 0;
  std::vector<ImuSample> imu;      // samples in (t_{k-1}, t_k]
  StereoFrame down;                // left = the down camera image; target_* = GT of the pad
  std::optional<StereoFrame> stereo;
  geometry::SE3 T_world_down;      // with vibration
  geometry::SE3 T_world_left;      // forward left camera (with vibration; rendered when stereo)
  MultirotorState vehicle;
  Eigen::Vector3d wind = Eigen::Vector3d::Zero();
  Eigen::Vector2d platform_velocity = Eigen::Vector2d::Zero();  // of the landing object, world, m/s
  TargetTruth target;              // in the down camera
};

class FlightSim {
 public:
  explicit FlightSim(const FlightSimConfig& config);

  // Advances to the next frame (frame 0 first, at t = 0) and renders it.
  FlightFrame step();
  // A command received now (it acts after the vehicle's command latency). Returns the
  // reason when refused ("" when applied).
  std::string command(const CommandInput& cmd);

  // The utime of frame 0; only before the first step (real time: the wall clock at start).
  void set_start_utime(int64_t utime);
  double time() const { return t_; }
  int64_t frame() const { return frame_; }
  int64_t utime_of(double t) const;
  // The world now (with the moving platform where it is at time()).
  const World& world() const { return world_; }
  // The landing object's displacement from its place at t = 0 and its velocity, now (m, m/s).
  const Eigen::Vector2d& platform_offset() const { return platform_offset_; }
  Eigen::Vector2d platform_velocity() const;
  const Multirotor& vehicle() const { return vehicle_; }
  const FlightOutcome& outcome() const { return outcome_; }
  const FlightSimConfig& config() const { return cfg_; }
  Intrinsics down_intrinsics() const { return down_.intrinsics(); }
  // What the down camera's calibration says (the true intrinsics plus the seeded error).
  const Intrinsics& down_calibration() const { return down_calibration_; }
  Intrinsics stereo_intrinsics() const { return forward_.intrinsics(); }
  int64_t commands_applied() const { return applied_; }
  int64_t commands_refused() const { return refused_; }
  const std::string& last_refusal() const { return last_refusal_; }
  // Down camera -> body (static mount, without vibration).
  const geometry::SE3& T_body_down() const { return T_body_down_; }

  TargetTruth target_in(const geometry::SE3& T_world_cam) const;

 private:
  World draw_world(int layout);
  std::optional<Eigen::Vector3d> takeoff_point();
  bool column_free(const Eigen::Vector3d& p) const;
  void physics_step(double dt);
  Eigen::Vector3d wind_step(double dt);
  double yaw_gust_step(double dt);
  geometry::SE3 vibration(double t) const;
  double support_height(const Eigen::Vector3d& p) const;
  void move_platform(double t);
  DrydenScales dryden_scales() const;
  Eigen::Vector3d dryden_world(const Eigen::Vector3d& uvw) const;

  FlightSimConfig cfg_;
  World world_;
  StereoRenderer down_, forward_;
  Intrinsics down_calibration_;
  Multirotor vehicle_;
  Imu imu_;
  std::mt19937_64 rng_;
  geometry::SE3 T_body_down_, T_body_left_;
  Eigen::Vector3d wind_mean_ = Eigen::Vector3d::Zero(), gust_ = Eigen::Vector3d::Zero();
  DrydenGusts dryden_{0};          // its own stream (wind.model dryden)
  PlatformMotion platform_;
  World base_world_;               // the world at t = 0 (the platform where it was built)
  Eigen::Vector2d platform_offset_ = Eigen::Vector2d::Zero();
  bool platform_stopped_ = false;  // at the field's edge
  double wind_theta_ = 0;          // direction of the mean wind (the Dryden u axis)
  std::mt19937_64 yaw_gust_rng_;   // its own stream: enabling yaw gusts leaves every other draw as it was
  double yaw_gust_deg_s_ = 0.0;
  std::array<std::array<double, 4>, 3> vib_phase_{};  // per axis: two phases, two frequency factors
  double t_ = 0;
  int64_t frame_ = -1;
  bool airborne_ = false;
  FlightOutcome outcome_;
  int64_t applied_ = 0, refused_ = 0;
  std::string last_refusal_;
  Eigen::Quaterniond q_prev_ = Eigen::Quaterniond::Identity();
  Eigen::Vector3d omega_body_ = Eigen::Vector3d::Zero();  // of the last physics step, rad/s
  // The camera-effects stages (only when their config has an effect on) and the real
  // cameras' models (their projection places the ground truth in the distorted image).
  struct Effects {
    CameraEffects stage;
    camera::CameraModel real;
  };
  std::optional<Effects> down_fx_, left_fx_, right_fx_;
  CameraMotion camera_motion(const geometry::SE3& T_world_cam, const geometry::SE3& T_body_cam) const;
};

LandingScore score_landing(const FlightSim& sim, double max_error_m = 0.25, double max_yaw_deg = 10.0);

}  // namespace aerie::sim
