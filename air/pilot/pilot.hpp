#pragma once
// The flight manager (aerie-pilot): the mission state machine that decides *what* the
// vehicle does — take off, survey, acquire the target, approach, descend on the target's
// 3D pose, touch down — and hands *how* to the landing controllers (landing_control.hpp).
// It never estimates: it reads the tracker's target pose (TARGET_POSE, camera frame), the
// tracker's status (TRACK) and the autopilot's attitude (IMU), all on message time.
//
//   IDLE -> TAKEOFF -> [SURVEY] -> ACQUIRE -> APPROACH -> DESCEND -> TOUCHDOWN -> LANDED
//   APPROACH/DESCEND --target lost / inputs stale--> HOLD --re-acquired--> back
//   HOLD --hold timeout--> ABORT (climb) -> ABORTED;  ACQUIRE --timeout--> ABORT
//   operator: ABORT (any airborne state), LAND (land in place), RESUME (HOLD/ABORTED -> ACQUIRE)
//
// Frames: the camera's optical frame (x right, y down, z forward) is turned into the body
// frame (x forward, y left, z up) by the camera mount, then levelled with the AHRS roll
// and pitch into the heading frame the autopilot takes velocity commands in.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "air/pilot/landing_control.hpp"
#include "air/pilot/pad_velocity.hpp"
#include "common/flc/flc.hpp"
#include "common/util/message_clock.hpp"

namespace aerie::pilot {

enum class State { Idle, Takeoff, Survey, Acquire, Approach, Descend, Touchdown, Landed, Hold, Abort, Aborted };
const char* state_name(State s);  // "IDLE", "TAKEOFF", ... (pilot_state_t's constants)

struct PilotConfig {
  std::string controller = "fuzzy";  // fuzzy | pid
  flc::FlcSpec fuzzy_base;           // normalised PID-type FLC (config/flc/landing.yaml)
  AxisGains forward, left, up, yaw;  // per kind: gains in config/pilot.yaml
  double camera_pitch_deg = 90;      // mount of the landing camera: tilt of its optical axis below body x
  bool wait_for_start = false;       // stay IDLE until an operator START
  double takeoff_time_s = 12.0;      // TAKEOFF lasts at most this long (the autopilot climbs to its take-off height) ...
  double takeoff_min_s = 2.0;        // ... and ends after this long when the target is tracked (-> APPROACH)
  std::vector<Eigen::Vector2d> survey_legs{{-1.5, 0.0}, {3.0, 0.0}};  // heading-frame legs (forward, left), m, flown in turn
  double survey_speed_m_s = 0.5;
  double acquire_timeout_s = 20.0;   // ACQUIRE without a target for this long -> ABORT
  double approach_height_m = 2.0;    // height above the target held while centring
  double approach_tolerance_m = 0.15;   // centred within this ...
  double yaw_tolerance_deg = 5.0;       // ... and aligned within this ...
  double height_tolerance_m = 0.25;     // ... at the approach height within this ...
  int settle_frames = 10;               // ... for this many frames in a row -> DESCEND
  double descent_speed_m_s = 0.35;
  double descent_gate_m = 0.3;       // the descent slows linearly to 0 at this horizontal error
  double touchdown_height_m = 1.4;   // below this height vision hands over to the autopilot LAND ...
  double handover_tolerance_m = 0.05;  // ... once centred within this ...
  int handover_frames = 3;             // ... for this many frames in a row (the LAND below is blind)
  double touchdown_time_s = 3.0;     // TOUCHDOWN -> LANDED after this long
  double stale_timeout_s = 0.5;      // no tracker result for this long -> HOLD
  // A tracker result whose frame is older than this on the pilot's clock (the link's delay
  // from the camera to the pilot) is not flown on: APPROACH/DESCEND -> HOLD. The pilot sees
  // one way of the round trip; 0.4 s each way is where the landing's error passed 10 cm
  // (docs/results/linkstudy.md, the delay edge). 0 = off.
  double max_input_age_s = 0.4;
  int loss_frames = 3;               // tracker lost this many frames in a row -> HOLD
  double hold_timeout_s = 8.0;       // HOLD for this long -> ABORT
  double hold_climb_m_s = 0.15;      // HOLD climbs slowly (a wider view helps re-acquisition) ...
  double hold_climb_max_s = 4.0;     // ... for at most this long
  double abort_climb_m_s = 0.5;
  double abort_climb_s = 1.5;
  double control_period_s = 0.05;    // ticks from the IMU clock while the tracker is silent
  // The node's message-time policy per source (the tracker: TRACK and TARGET_POSE; the IMU):
  // a message whose utime jumps by more than 1 s is held, so one bogus stamp never moves the
  // state machine's clock (docs/architecture.md "Message time").
  util::MessageClockConfig message_time{1'000'000, 3, 2'000'000};
  // Velocity feed-forward for a moving pad (pad_velocity.hpp): the pad's estimated velocity
  // is added to the horizontal command in APPROACH, DESCEND and HOLD, and TOUCHDOWN descends
  // with it (blind, at touchdown_speed_m_s) instead of the autopilot's LAND, which would
  // hold the ground point where it began; LAND follows once the feet must be down. A pad
  // slower than min_speed_m_s gets none: a still pad flies exactly as without it.
  struct FeedForward {
    bool enabled = false;
    PadVelocityConfig estimator;
    double min_speed_m_s = 0.3;      // below this estimated speed: no feed-forward
    double max_speed_m_s = 3.0;      // the feed-forward is clamped to this
    double touchdown_speed_m_s = 0.5;  // the blind descent onto a moving pad ...
    double touchdown_margin_s = 1.0;   // ... lasts height / speed + this, then LAND
  } feedforward;
  void validate() const;             // throws std::invalid_argument naming the field
};

struct Command {
  enum class Mode { Hover, Velocity, Takeoff, Land };
  int64_t utime = 0;
  Mode mode = Mode::Hover;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // heading frame, m/s
  double yaw_rate_deg_s = 0;                           // clockwise positive
};

// The tracker's status on a frame (track_t's constants).
enum class TrackStatus { Idle = 0, Tracking = 1, Lost = 2, Redetected = 3 };

struct TargetObservation {
  int64_t utime = 0;
  Eigen::Vector3d position_cam = Eigen::Vector3d::Zero();  // camera optical frame, m
  double yaw_cam = 0;  // the pad's axis from image x towards image y, rad
  bool fitted = true;  // the target's geometry fitted in the image; false: from the tracker's box only
};

struct PilotStatus {
  State state = State::Idle;
  std::string reason;
  double time_in_state_s = 0;
  bool target_valid = false;
  Eigen::Vector3d target_level = Eigen::Vector3d::Constant(std::nan(""));  // heading frame
  double yaw_error_deg = std::nan("");
  double height_m = std::nan("");
  int losses = 0, reacquisitions = 0;
  int stale_holds = 0;  // HOLDs entered because the tracker fell silent (inputs stale)
  int age_holds = 0;    // HOLDs entered because its results were older than max_input_age_s
  int aged_results = 0; // tracker results not flown on because of their age
  int link_holds = 0;   // HOLDs entered because the autopilot's link was lost
  // The pad's estimated velocity (AHRS level frame, m/s; zero until valid) and the
  // feed-forward added to the last command (heading frame; zero when none).
  Eigen::Vector2d pad_velocity = Eigen::Vector2d::Zero();
  Eigen::Vector2d feedforward = Eigen::Vector2d::Zero();
};

class Pilot {
 public:
  explicit Pilot(PilotConfig config);

  // The autopilot's attitude estimate (body -> world); only roll and pitch are used.
  void on_attitude(int64_t utime, const Eigen::Quaterniond& q_world_body);
  // A target pose; used by the tick of the frame with the same utime. Throws
  // std::invalid_argument for non-finite values (the node counts and drops them).
  void on_target(const TargetObservation& target);
  // The tick of a processed frame: the tracker's status on it, and the age of the frame on
  // the pilot's clock (the node's clock minus the frame's capture time; nullopt when the two
  // clocks are not comparable). A result older than max_input_age_s ticks without a target.
  Command on_track(int64_t utime, TrackStatus status, std::optional<double> age_s = std::nullopt);
  // The IMU clock: a tick (hover in HOLD, or the state's command) when the tracker has
  // been silent for stale_timeout_s; nullopt while it is not.
  std::optional<Command> on_clock(int64_t utime);
  // The autopilot's link (AUTOPILOT_STATE from aerie-mavlink). While it is lost the pilot's
  // commands reach nothing: it reacts as to stale inputs (APPROACH/DESCEND -> HOLD), and no
  // tracker result resumes them until the link is back.
  void on_autopilot_link(bool ok, int64_t utime);
  enum class Operator { Start, Abort, Land, Resume };
  // Returns false (and says why) when the command does not apply in the current state.
  bool on_operator(Operator cmd, int64_t utime, std::string* why = nullptr);

  const PilotStatus& status() const { return status_; }
  State state() const { return status_.state; }
  const PilotConfig& config() const { return cfg_; }
  const Command& last_command() const { return last_; }

 private:
  Command tick(int64_t utime, bool fresh_track, TrackStatus status);
  void enter(State s, int64_t utime, const std::string& reason);
  Command hover(int64_t utime) const;
  Command steer(int64_t utime, double t, const Eigen::Vector3d& target, double yaw_error_deg, double vz) ;
  void reset_controllers();
  Eigen::Vector2d to_heading(const Eigen::Vector2d& level) const;  // by the AHRS yaw
  Eigen::Vector2d estimated_feedforward() const;                    // level frame; zero below min_speed_m_s

  PilotConfig cfg_;
  std::unique_ptr<AxisController> forward_, left_, up_, yaw_;
  Eigen::Matrix3d R_body_cam_;
  Eigen::Quaterniond attitude_ = Eigen::Quaterniond::Identity();
  std::optional<TargetObservation> target_;
  PilotStatus status_;
  State resume_state_ = State::Approach;  // where HOLD returns to
  int64_t state_since_ = 0, last_track_ = -1, last_tick_ = -1;
  int lost_run_ = 0, settled_run_ = 0;
  bool started_ = false;
  bool autopilot_link_ok_ = true;
  Command last_;
  PadVelocityEstimator pad_velocity_;
  double ahrs_yaw_ = 0;            // the AHRS yaw of this tick (rad)
  Eigen::Vector2d ff_ = Eigen::Vector2d::Zero();  // this tick's feed-forward, heading frame
  bool ff_on_ = false;
  Eigen::Vector2d hold_ff_level_ = Eigen::Vector2d::Zero(), touchdown_ff_level_ = Eigen::Vector2d::Zero();
  double blind_s_ = 0;             // TOUCHDOWN onto a moving pad: the blind descent's duration
};

}  // namespace aerie::pilot
