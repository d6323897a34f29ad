#pragma once
// aerie-pilot as a class: TARGET_POSE (aerie.target_pose_t), TRACK (aerie.track_t), IMU
// (aerie.imu_t) and PILOT_CMD (aerie.pilot_cmd_t) in; CTRL_CMD (aerie.control_cmd_t) and
// PILOT_STATE (aerie.pilot_state_t) out. One command per TRACK message, with its utime
// (the frame's answer in lock-step); while the tracker is silent, the IMU clock ticks
// the pilot (Pilot::on_clock). Bad messages are counted and dropped; the state machine
// never sees them.
#include <aerie/control_cmd_t.hpp>

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "air/pilot/pilot.hpp"
#include "common/bus/bus.hpp"
#include "common/bus/status.hpp"
#include "common/util/message_clock.hpp"
#include "common/util/time.hpp"

namespace aerie::pilot {

struct PilotNodeOptions {
  std::string target_channel = "TARGET_POSE";
  std::string track_channel = "TRACK";
  std::string imu_channel = "IMU";
  std::string operator_channel = "PILOT_CMD";
  std::string command_channel = "CTRL_CMD";
  std::string state_channel = "PILOT_STATE";
  std::string autopilot_channel = "AUTOPILOT_STATE";  // aerie-mavlink's view of the autopilot's link
  // true (aerie-pilot --replay): the node's clock is the input clock, the newest message time
  // seen (IMU, else the tracker's), and a TRACK's age is taken against the newest tracker time
  // seen, so a replayed log is judged on its own time, not on the wall clock (docs/logs.md, replay).
  bool message_clock = false;
};

class PilotNode {
 public:
  // `now` is the node's clock for the message-time policy and the age rule (wall clock live;
  // tests pass theirs); with options.message_clock the input clock replaces it.
  PilotNode(bus::Bus& bus, PilotConfig config, PilotNodeOptions options = {}, util::NodeClock now = util::wall_utime);
  void report(bus::StatusReporter& status) const;
  const Pilot& pilot() const { return pilot_; }
  int64_t counter(const std::string& name) const;

 private:
  void publish(const Command& c);
  void count(const std::string& name) { ++counters_[name]; }
  // The message-time policy: false (counted "<channel>_time_held", logged) for a held stamp.
  bool on_time(util::MessageClock& clock, const std::string& channel, int64_t utime);
  // A frame's age on the node's clock (PilotConfig::max_input_age_s; util::message_age_s).
  std::optional<double> input_age(int64_t utime);
  // The pilot's own time: the newest IMU time, else the newest tracker time, else `otherwise`.
  int64_t input_time(int64_t otherwise) const;

  bus::Bus& bus_;
  Pilot pilot_;
  PilotNodeOptions opt_;
  util::NodeClock now_;
  util::MessageClock track_time_, imu_time_;
  std::map<std::string, int64_t> counters_;
  std::string last_error_;
  State last_state_ = State::Idle;
  std::optional<double> last_age_s_;
  int64_t cmd_seq_ = 0, state_seq_ = 0;
  bool link_ok_ = true;  // the autopilot's link as AUTOPILOT_STATE last said
};

}  // namespace aerie::pilot
