#pragma once
// Sends an operator's command (tools/cmd/command.hpp) on the bus and, when asked, waits for
// the message that shows it took effect (docs/cmd.md "Waiting for the effect").
#include <functional>
#include <string>

#include "common/bus/bus.hpp"
#include "tools/cmd/command.hpp"

namespace aerie::cmd {

// Publishes the command on its channel. A TRACK_CMD that aerie-track would refuse on arrival
// (track::refuse_command: sizes, box bounds) throws std::invalid_argument with the node's reason.
void send(bus::Bus& bus, const Command& c);

struct Ack {
  bool took_effect = false;
  int64_t seen = 0;     // answers received while waiting
  std::string message;  // the answer that showed the effect, else the last one seen ("" = none)
};

// The channel that answers a command: TRACK for TRACK_CMD INIT / STOP, PILOT_STATE for
// PILOT_CMD. Throws std::invalid_argument for a command that has no answer to wait for.
std::string answer_channel(const Command& c);

// Subscribes to the answer channel, sends, and handles the bus until an answer shows the
// effect (track_took_effect / pilot_took_effect) or `timeout_s` passed on the wall clock.
// `idle` runs between waits of at most 50 ms (tests feed the node there).
Ack send_and_wait(bus::Bus& bus, const Command& c, double timeout_s, const std::function<void()>& idle = {});

}  // namespace aerie::cmd
