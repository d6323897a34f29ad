#pragma once
// aerie-control's LCM side: VO_POSE, NAV_STATE or GT_POSE in, CTRL_CMD out at a fixed rate
// (or one per input message, for lock-step and replay),
// new controllers from FLC_PARAMS (validated; a bad one is refused with its reason
// and the current one stays), status on STATUS_CONTROL.
#include <aerie/control_cmd_t.hpp>
#include <aerie/flc_params_t.hpp>
#include <aerie/gt_pose_t.hpp>
#include <aerie/nav_state_t.hpp>
#include <aerie/pose_t.hpp>

#include <string>

#include "air/control/control_loop.hpp"
#include "air/control/heading_from_pose.hpp"
#include "common/bus/bus.hpp"
#include "common/bus/input_clock.hpp"
#include "common/bus/status.hpp"
#include "common/util/time.hpp"

namespace aerie::control {

struct NodeOptions {
  enum class Input { kVoPose, kNavState, kGtPose };
  Input input = Input::kVoPose;
  std::string pose_channel;           // "" = VO_POSE, NAV_STATE or GT_POSE by input
  std::string params_channel = "FLC_PARAMS";
  std::string command_channel = "CTRL_CMD";
  double rate_hz = 30.0;              // CTRL_CMD rate; 0 = one command per message on the pose channel
  HeadingFrame frame;
  ControlConfig control;
  // Where the manoeuvre's anchor is kept (anchor_file.hpp); "" = nowhere. With it, an
  // aerie-control restarted in flight resumes the manoeuvre in the same estimator frame
  // (an anchor of the same pose channel from the 10 minutes before); without, it refuses.
  std::string anchor_file;
  // message_time.max_jump_s / resync_messages; its stale timeout is control.stale_timeout_s.
  util::MessageClockConfig message_time;
  // true (aerie-control --replay): the node's clock is the input clock, the newest message time
  // seen on the pose channel (any status; a jump is held as on the pose clock), so the age and
  // staleness rules judge a replayed log on its own time, not on the wall clock (docs/control.md).
  bool message_clock = false;
};

// VO_POSE, NAV_STATE or GT_POSE.
std::string default_pose_channel(NodeOptions::Input input);
// How each input's orientation becomes a heading by default (config/control.yaml, heading_frame).
HeadingFrame default_heading_frame(NodeOptions::Input input);

// Ranges of a controller received on FLC_PARAMS (docs/control.md "FLC_PARAMS"), beyond
// FlcSpec::validate() (finite positions, strictly increasing, inside their variable's range):
// Kp and Ku in [kMinGain, kMaxScaling], Kd in (0, kMaxScaling] — a negative factor reverses the
// loop (an FLC_PARAMS with Ku = -50 inverted the yaw command, issue 46); Ki non-zero in
// [-kMaxScaling, kMaxScaling]: the rule base's integral acts with a negative Ki (docs/flc.md,
// thesis CE: Ki = -0.5003). The output range holds 0 inside and is within +/-kMaxOutputRange
// deg/s (the largest limits.max_yaw_rate_deg_s).
inline constexpr double kMinGain = 0.01;
inline constexpr double kMaxScaling = 100.0;
inline constexpr double kMaxOutputRange = 720.0;
// Throws std::invalid_argument naming the field (prefixed by `origin`) when `spec` is outside
// the ranges above, or when it does not turn toward the reference: a heading error of
// +/-10, 45, 90 deg alone (derivative and integral 0) must not give an output of the other
// sign, and +/-90 deg must give one of its sign.
void check_incoming_controller(const flc::FlcSpec& spec, const std::string& origin);

// The controller a FLC_PARAMS message describes: its FLL if it has one, else the
// current controller; then its named parameters; its id; checked by FlcSpec::validate() and
// check_incoming_controller(). Throws with the reason.
flc::FlcSpec controller_from_message(const aerie::flc_params_t& m, const flc::FlcSpec& current);

class ControlNode {
 public:
  // `now` is the node's clock: the receive time of a pose for its age and staleness (wall clock
  // live; tests and lock-step drivers pass theirs, the same one they give tick()). With
  // options.message_clock it is not used: the input clock replaces it.
  ControlNode(bus::Bus& bus, bus::StatusReporter& status, flc::FlcSpec controller, NodeOptions options,
              util::NodeClock now = util::wall_utime);

  // The node's clock now (the one to give tick()).
  int64_t now() const { return now_(); }

  // Publishes a command when a period of the rate has elapsed since the last one (nothing
  // when rate_hz is 0: commands then follow the input).
  void tick(int64_t now_us);
  void publish_command(int64_t now_us);
  const ControlLoop& loop() const { return loop_; }

 private:
  void on_pose(int64_t utime, const double orientation[4], const double position[3]);
  void on_heading(int64_t utime, double heading_deg, const Eigen::Vector3d& position, int64_t receive_us);
  void answer();  // rate_hz 0: the command that follows an input message
  // Every message on the pose channel moves the input clock (options.message_clock).
  void on_input_time(int64_t utime);
  void on_params(const aerie::flc_params_t& m);
  // The manoeuvre is defined from its start pose in the estimator's frame. It is refused for
  // good — FALLBACK_HOVER, health ERROR, until the mission is restarted — when that frame is
  // reset under it (the pose source initialising again: aerie-nav or aerie-vo restarted) or
  // when the first pose is already away from the frame's origin (aerie-control restarted in
  // mid-flight) and no anchor kept in anchor_file can be resumed: a reference re-anchored
  // there could steer into the wall.
  void refuse_mission(const std::string& why);
  // Resumes the manoeuvre from anchor_file; "" when it did, else why not.
  std::string resume_anchor(int64_t utime);
  static constexpr int64_t kMaxAnchorAgeUs = 600'000'000;

  bus::Bus& bus_;
  bus::StatusReporter& status_;
  NodeOptions opt_;
  ControlLoop loop_;
  int64_t seq_ = 0, next_publish_ = 0, period_us_ = 0, last_receive_ = 0;
  util::NodeClock now_;
  bus::InputClock pose_clock_;  // the message-time policy of the pose source
  util::MessageClock input_clock_;  // options.message_clock: the newest message time seen
  int64_t input_now_ = 0;
  int64_t bad_poses_ = 0, aged_poses_ = 0;
  bool source_was_ok_ = false, had_pose_ = false;
  static constexpr int kNavRestartMessages = 3;  // INITIALISING in a row after OK: a restart
  int initialising_run_ = 0;
  std::string mission_refused_;  // why, once refused
};

}  // namespace aerie::control
