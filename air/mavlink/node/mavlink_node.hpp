#pragma once
// aerie-mavlink as a class (docs/mavlink.md): the bridge between Aerie's LCM and the autopilot's
// MAVLink. In: CTRL_CMD (aerie.control_cmd_t), NAV_STATE (aerie.nav_state_t), TARGET_POSE
// (aerie.target_pose_t), PILOT_STATE (aerie.pilot_state_t). Out: AUTOPILOT_STATE
// (aerie.autopilot_state_t) at 1 Hz and on every change, the autopilot's IMU on IMU
// (aerie.imu_t) when enabled. Frames between the autopilot and the ground stations are routed
// as mavlink-router routes them: the autopilot's bytes to every ground station as they are, a
// ground station's whole frames to the autopilot (a signature travels with its frame; garbage
// does not).
#include <aerie/autopilot_state_t.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "air/mavlink/autopilot_link.hpp"
#include "common/mavlink/transport.hpp"
#include "common/bus/node.hpp"
#include "common/mavlink/parser.hpp"
#include "common/util/message_clock.hpp"
#include "common/util/time.hpp"

namespace aerie::bridge {

struct MavlinkNodeOptions {
  std::string control_channel = "CTRL_CMD";
  std::string nav_channel = "NAV_STATE";
  std::string target_channel = "TARGET_POSE";
  std::string pilot_state_channel = "PILOT_STATE";
  std::string state_channel = "AUTOPILOT_STATE";
  std::string imu_channel = "IMU";
  bool publish_imu = false;          // the autopilot's IMU on IMU (when no other node publishes it)
  std::string timestamp_file;        // where the signing timestamp is persisted ("" = not persisted)
};

class MavlinkNode final : public bus::Node {
 public:
  // `autopilot`: the endpoint of the flight controller; `ground`: ground stations to route to.
  // `now`: the node's clock (wall clock live; simulation time in lock-step flights).
  MavlinkNode(bus::Bus& bus, AutopilotLink link, std::unique_ptr<mavlink::Endpoint> autopilot,
              std::vector<std::unique_ptr<mavlink::Endpoint>> ground = {}, MavlinkNodeOptions options = {},
              util::NodeClock now = util::wall_utime);
  ~MavlinkNode() override;

  // Reads every endpoint, routes, lets the link act and writes what it has to send; publishes
  // AUTOPILOT_STATE when it changed or a second has passed; reports counters in status.
  void tick(int64_t now_us) override;
  // tick() on the node's own clock (lock-step harnesses call this after each settle).
  void step() { tick(now_()); }

  const AutopilotLink& link() const { return link_; }
  // p-th percentile (0..1) of the frame-to-wire latency of the setpoints written so far (µs; -1: none).
  int64_t frame_to_wire_us(double p) const;
  aerie::autopilot_state_t state_message(int64_t now_us) const;

 private:
  void flush(int64_t now_us);
  void report();
  void persist_timestamp(int64_t now_us);

  AutopilotLink link_;
  std::unique_ptr<mavlink::Endpoint> autopilot_;
  std::vector<std::unique_ptr<mavlink::Endpoint>> ground_;
  std::vector<mavlink::Parser> ground_parsers_;  // frame boundaries of what the ground stations send
  MavlinkNodeOptions opt_;
  util::NodeClock now_;
  int64_t last_state_us_ = -1'000'000'000;
  mutable int64_t state_seq_ = 0;
  int64_t imu_seq_ = 0;
  int64_t routed_up_ = 0, routed_down_ = 0, write_failures_ = 0, endpoint_errors_ = 0;
  std::vector<uint8_t> buf_;
  // Frame to wire: the node's time when a setpoint is written minus the utime of the camera
  // frame its CTRL_CMD derives from (meaningful when message time is the wall clock, as live).
  std::vector<int64_t> frame_to_wire_us_;
  int64_t pending_control_utime_ = -1;
  int64_t last_stats_us_ = 0;
};

}  // namespace aerie::bridge
