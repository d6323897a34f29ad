#pragma once
// Aerie's side of the link to a PX4 or ArduPilot autopilot (docs/mavlink.md): everything the
// bridge node does but the I/O. Bytes from the autopilot go in (receive), Aerie's commands,
// estimates and targets go in (on_*), and poll(now) says what to write to the autopilot now.
// Every time is passed in (the node's clock: the wall clock live, simulation time in lock-step),
// so a lock-step flight through MAVLink is as deterministic as one without it.
//
// What it does on the wire:
//  * HEARTBEAT at 1 Hz as MAV_TYPE_ONBOARD_CONTROLLER; the autopilot's heartbeat followed: the
//    first autopilot heard (or the configured system id) is ours, another one is refused and
//    counted; no heartbeat for link_timeout_s = link LOST.
//  * The autopilot's streams asked for at the configured rates (MAV_CMD_SET_MESSAGE_INTERVAL)
//    when the link comes up; TIMESYNC for the clock offset.
//  * Commands acknowledged (command_client.hpp); a refusal shown with the autopilot's reason.
//  * Aerie flies (landing_path Aerie): control_cmd_t's TAKEOFF arms and takes off (ArduCopter:
//    GUIDED first), ACTIVE/HOVER are streamed as velocity setpoints (conversions.hpp) at
//    setpoint_rate_hz and the companion mode (PX4 OFFBOARD, ArduCopter GUIDED) is asked for once
//    the stream has run offboard_warmup_s (PX4 refuses OFFBOARD before); LAND asks the autopilot
//    to land. A control_cmd_t older than control_timeout_s stops the stream: the autopilot's
//    own failsafe takes over (PX4 COM_OF_LOSS_T then COM_OBL_RC_ACT; ArduCopter GUID_TIMEOUT).
//  * The autopilot flies the landing (landing_path Autopilot): as above until the pilot starts
//    its descent (pilot_state_t DESCEND); then the precision landing is asked for (PX4
//    MAV_CMD_NAV_LAND with param2 = 2, required: AUTO.PRECLAND; ArduCopter LAND with PLND_*),
//    LANDING_TARGET streamed on every target, and when the pilot leaves the descent (target
//    lost: HOLD, ABORT) the companion mode is asked for again, so the pilot's commands fly.
//  * Vision to the autopilot's estimator: ODOMETRY at odometry_rate_hz while the navigation
//    filter is OK.
#include <Eigen/Core>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "air/mavlink/command_client.hpp"
#include "air/mavlink/conversions.hpp"
#include "common/mavlink/frame.hpp"
#include "common/mavlink/modes.hpp"
#include "common/mavlink/parser.hpp"
#include "common/mavlink/signing.hpp"
#include "common/util/config.hpp"

namespace aerie::bridge {

enum class LandingPath { Aerie, Autopilot };

// MAVLink's signing time (10 µs ticks since 2015-01-01) of a microsecond time: Unix time, or
// a simulation's time (which starts near 0) taken as it is.
uint64_t signing_ticks(int64_t now_us);

// Lets through one event per period on average, whatever the rate it is offered at (an event
// is due at the period's grid, so 30 Hz out of a 200 Hz input is 30 Hz, not 200/7).
class RateLimiter {
 public:
  explicit RateLimiter(double rate_hz) : period_us_(static_cast<int64_t>(1e6 / rate_hz)) {}
  bool due(int64_t now_us) {
    if (started_ && now_us < next_us_) return false;
    next_us_ = started_ ? next_us_ + period_us_ : now_us + period_us_;
    if (next_us_ <= now_us) next_us_ = now_us + period_us_;  // after a pause: no burst to catch up
    started_ = true;
    return true;
  }

 private:
  int64_t period_us_;
  int64_t next_us_ = 0;
  bool started_ = false;
};

struct BridgeConfig {
  int system_id = 1;               // Aerie's MAVLink system id (a companion shares its autopilot's)
  int component_id = 191;          // MAV_COMP_ID_ONBOARD_COMPUTER
  int autopilot_system_id = 0;     // 0: the first autopilot heard; else only this one
  double heartbeat_period_s = 1.0;
  double link_timeout_s = 3.0;     // no autopilot heartbeat for this long: link LOST
  double setpoint_rate_hz = 20.0;  // PX4 needs > 2 Hz; 20 Hz follows the pilot's commands
  double offboard_warmup_s = 1.0;  // PX4 accepts OFFBOARD only after about 1 s of setpoints
  double control_timeout_s = 0.5;  // an older control_cmd_t stops the setpoint stream
  double odometry_rate_hz = 30.0;  // PX4 fuses external vision at 30-50 Hz
  double command_timeout_s = 1.0;  // per attempt, before a command is sent again
  int command_attempts = 3;
  double mode_retry_s = 1.5;       // after an answered mode change, wait this long before asking again
  double takeoff_altitude_m = 2.5; // MAV_CMD_NAV_TAKEOFF's altitude (above the take-off point)
  double camera_pitch_deg = 90;    // the landing camera's mount (pilot.yaml's camera_pitch_deg)
  LandingPath landing_path = LandingPath::Aerie;
  bool send_odometry = true;
  // Only poses fitted to the pad's geometry become LANDING_TARGET: a box-only pose (the pad cut
  // by the image border) is coarse, and the autopilot cannot tell the two apart. Its position is
  // absolute (PX4's local frame), so below the last fitted pose the autopilot lands on it, as the
  // pilot's blind LAND does.
  bool landing_target_fitted_only = true;
  // Stream rates asked for on link-up (Hz; 0 = leave the autopilot's default).
  double imu_rate_hz = 100, attitude_rate_hz = 50, local_position_rate_hz = 30, extended_state_rate_hz = 5,
         battery_rate_hz = 1;
  void validate() const;  // throws std::invalid_argument naming the key
};
// From a mavlink.yaml (docs/mavlink.md lists the keys); unknown keys are refused.
BridgeConfig load_bridge(const util::Config& cfg);

// control_cmd_t, as the bridge needs it.
struct ControlInput {
  int64_t utime = 0;
  int mode = 0;  // control_cmd_t: HOVER 0, ACTIVE 1, FALLBACK_HOVER 2, TAKEOFF 3, LAND 4
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // heading frame (x forward, y left, z up), m/s
  double yaw_rate_cw_deg_s = 0;
};

// What Aerie knows of the autopilot (AUTOPILOT_STATE).
struct AutopilotView {
  enum class Link { None, Ok, Lost };
  Link link = Link::None;
  mavlink::Autopilot autopilot = mavlink::Autopilot::Other;
  int system_id = 0, component_id = 0;
  bool armed = false;
  uint32_t custom_mode = 0;
  std::string mode = "unknown";
  uint8_t system_status = 0;
  uint8_t landed_state = 0;
  bool in_companion_mode = false;
  float battery_voltage_v = std::numeric_limits<float>::quiet_NaN();
  float battery_remaining_pct = std::numeric_limits<float>::quiet_NaN();
  float link_quality = std::numeric_limits<float>::quiet_NaN();
  int64_t clock_offset_us = 0;
  std::string last_statustext, last_command, last_result;
  int64_t last_heard_us = 0;  // local time of the newest frame from the autopilot
  std::optional<VehicleNed> pose;  // from LOCAL_POSITION_NED + ATTITUDE_QUATERNION
  Eigen::Vector3d velocity_ned = Eigen::Vector3d::Zero();  // LOCAL_POSITION_NED's
  int estimator_flags = -1;        // ESTIMATOR_STATUS.flags; -1 before the first
};

struct BridgeCounters {
  int64_t frames_in = 0, frames_out = 0;
  int64_t foreign_autopilot = 0;    // frames of a second autopilot system
  int64_t setpoints = 0, odometry = 0, landing_targets = 0;
  int64_t control_stale = 0;        // times the setpoint stream stopped for a stale control_cmd_t
  int64_t commands_accepted = 0, commands_refused = 0, commands_timed_out = 0;
  int64_t link_losses = 0;
  int64_t bad_inputs = 0;           // non-finite or impossible inputs from Aerie, refused
};

// The autopilot's IMU sample, in Aerie's body frame (FLU).
struct AutopilotImu {
  int64_t utime = 0;  // local time it arrived
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();
  std::optional<Eigen::Quaterniond> orientation;  // body FLU -> world z-up (NED's z flipped)
};

class AutopilotLink {
 public:
  // `clock` dates signed frames (10 µs ticks); by default derived from the times passed in.
  explicit AutopilotLink(BridgeConfig config);

  // Signs what is sent and refuses unsigned frames from the autopilot (but HEARTBEAT and
  // RADIO_STATUS, as PX4 does); persisted_timestamp: the last one saved (0 = none).
  void enable_signing(const mavlink::Key& key, uint8_t link_id, uint64_t persisted_timestamp);
  bool signing() const { return signer_.has_value(); }

  void receive(std::span<const uint8_t> bytes, int64_t now_us);
  void on_control(const ControlInput& c, int64_t now_us);
  void on_nav(const NavSample& s, int64_t now_us);
  void on_target(const CameraTarget& t, int64_t now_us);
  void on_pilot_state(int state, int64_t now_us);  // pilot_state_t's constants
  // Operator commands (aerie-mavlink --arm etc., tests).
  void request_arm(bool arm, int64_t now_us);
  void request_mode(const std::string& name, int64_t now_us);  // throws for a mode the autopilot has not

  // The frames to write to the autopilot now.
  std::vector<std::vector<uint8_t>> poll(int64_t now_us);

  const BridgeConfig& config() const { return cfg_; }
  const AutopilotView& view() const { return view_; }
  const BridgeCounters& counters() const { return counters_; }
  const mavlink::ParserCounters& parser_counters() const { return parser_.counters(); }
  const std::string& parser_error() const { return parser_.last_error(); }
  // Lines for the node's log since the last call (STATUSTEXT, command results, link changes).
  std::vector<std::string> take_log();
  // True once after every change of link, arming, mode or command result.
  bool take_changed();
  std::optional<AutopilotImu> take_imu();
  // The newest signing timestamp to persist, when it is due (nullopt otherwise).
  std::optional<uint64_t> timestamp_to_persist(int64_t now_us);
  // The newest signing timestamp used (saved on the way out); nullopt when unsigned.
  std::optional<uint64_t> last_signing_timestamp() const {
    return signer_ ? std::optional<uint64_t>(signer_->last_timestamp()) : std::nullopt;
  }

 private:
  void on_frame(const mavlink::Frame& f, int64_t now_us);
  void on_heartbeat(const mavlink::Heartbeat& hb, const mavlink::Frame& f, int64_t now_us);
  void on_ack(const mavlink::CommandAck& ack, int64_t now_us);
  void on_statustext(const mavlink::Statustext& m);
  void link_up();
  void send_command(uint16_t command, std::array<float, 7> params, int64_t now_us);
  void fly(int64_t now_us);  // the flight logic of the two landing paths, once per poll
  template <class Msg>
  void emit(const Msg& msg);
  void log(std::string line);
  void advance(int64_t now_us) { *now_us_ = std::max(*now_us_, now_us); }

  BridgeConfig cfg_;
  mavlink::Parser parser_;
  std::optional<mavlink::Signer> signer_;
  // The newest time passed in, which dates signed frames; shared with the signing clock, so a
  // moved link's clock still reads its own time.
  std::shared_ptr<int64_t> now_us_ = std::make_shared<int64_t>(0);
  uint8_t seq_ = 0;
  std::vector<std::vector<uint8_t>> out_;
  CommandClient commands_;
  AutopilotView view_;
  BridgeCounters counters_;
  std::vector<std::string> log_;
  std::string statustext_;  // chunks of a long STATUSTEXT so far
  uint16_t statustext_id_ = 0;
  bool changed_ = false;
  std::optional<AutopilotImu> imu_;
  int64_t last_heartbeat_sent_ = -1'000'000'000;
  int64_t boot_us_ = -1;
  // The autopilot's sequence numbers, for link quality.
  int last_seq_ = -1;
  int64_t seq_received_ = 0, seq_expected_ = 0;

  std::optional<ControlInput> control_;
  int64_t control_at_us_ = 0;       // when the newest control_cmd_t arrived
  int64_t stream_since_us_ = -1;    // the setpoint stream runs since (-1: not streaming)
  int64_t mode_answered_at_us_ = -1'000'000'000;
  int64_t takeoff_refused_at_us_ = -1;
  bool takeoff_requested_ = false, takeoff_sent_ = false, land_requested_ = false, precland_ = false;
  std::vector<std::pair<uint32_t, double>> pending_intervals_;  // SET_MESSAGE_INTERVALs still to send
  int pilot_state_ = -1;
  OdometryStream odometry_;
  RateLimiter setpoint_rate_, odometry_rate_;
  Eigen::Matrix3d body_from_camera_;
  std::optional<Eigen::Quaterniond> attitude_ned_;
};

}  // namespace aerie::bridge
