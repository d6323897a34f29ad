#pragma once
// The simulator's autopilot on the wire: SimAutopilot behind MAVLink 2 bytes, as a flight
// controller's TELEM port is (docs/mavlink.md). Bytes from the companion go in, are parsed
// (signed frames verified when a key is set: unsigned ones refused but HEARTBEAT and
// RADIO_STATUS, as PX4 does once a key exists), and reach SimAutopilot as typed messages; its
// replies leave as frames of system 1, component 1, signed when a key is set. Simulation time
// only, so a lock-step flight through it is deterministic.
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "common/mavlink/parser.hpp"
#include "common/mavlink/signing.hpp"
#include "common/sim/autopilot/sim_autopilot.hpp"
#include "common/sim/flight/flight_sim.hpp"

namespace aerie::sim::autopilot {

// The autopilot's command as FlightSim::command takes it (control_cmd_t's modes).
CommandInput command_input(const AutopilotCommand& c);

class MavlinkFace {
 public:
  struct Output {
    AutopilotCommand command;    // for the vehicle
    std::vector<uint8_t> bytes;  // frames to the companion, back to back
  };

  explicit MavlinkFace(Personality personality, const Params& params = {});
  // Signs and verifies with `key` from now on; `clock` gives the signing time (10 µs ticks).
  void enable_signing(const mavlink::Key& key, mavlink::SigningClock clock);

  void receive(std::span<const uint8_t> bytes, double t_s);
  Output step(double t_s, const MultirotorState& truth);

  SimAutopilot& autopilot() { return ap_; }
  const SimAutopilot& autopilot() const { return ap_; }
  const mavlink::ParserCounters& parser_counters() const { return parser_.counters(); }
  const std::string& parser_error() const { return parser_.last_error(); }
  int64_t unknown_messages() const { return unknown_; }

 private:
  SimAutopilot ap_;
  mavlink::Parser parser_;
  std::optional<mavlink::Signer> signer_;
  uint8_t seq_ = 0;
  int64_t unknown_ = 0;
};

}  // namespace aerie::sim::autopilot
