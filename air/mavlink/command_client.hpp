#pragma once
// Commands to the autopilot with acknowledgement (MAVLink "Command Protocol"): a COMMAND_LONG is
// sent, and sent again with `confirmation` + 1 each time `timeout` passes without a COMMAND_ACK,
// `attempts` times in all; MAV_RESULT_IN_PROGRESS restarts the wait. One command of each id is in
// flight at a time (a new one replaces it, as MAVSDK does). Every end — accepted, refused with
// its reason, or no answer — is a Result the caller shows to the user.
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/mavlink/catalogue.hpp"

namespace aerie::bridge {

// "MAV_CMD_COMPONENT_ARM_DISARM" for the commands Aerie sends, "MAV_CMD 1234" otherwise.
std::string command_name(uint16_t command);

class CommandClient {
 public:
  struct Result {
    uint16_t command = 0;
    bool accepted = false;
    uint8_t result = 0;   // MAV_RESULT; meaningless when timed_out
    bool timed_out = false;
    std::string reason;   // the autopilot's STATUSTEXT that came with a refusal, if any
    std::string describe() const;  // "MAV_CMD_DO_SET_MODE: DENIED (Switching to Offboard rejected)"
  };

  CommandClient(int64_t timeout_us = 1'000'000, int attempts = 3);

  void send(mavlink::CommandLong cmd, int64_t now_us);
  // The COMMAND_LONGs to put on the wire now: new ones and retransmissions that are due.
  std::vector<mavlink::CommandLong> due(int64_t now_us);
  // An ACK for one of our commands ends it (nullopt for an ACK of nothing in flight).
  std::optional<Result> on_ack(const mavlink::CommandAck& ack, int64_t now_us);
  // A STATUSTEXT that arrives while commands are in flight is kept as the reason of the next refusal.
  void on_statustext(const std::string& text) { last_text_ = text; }
  // Commands that ran out of attempts since the last call.
  std::vector<Result> expired(int64_t now_us);
  bool pending(uint16_t command) const { return inflight_.count(command) != 0; }

 private:
  struct InFlight {
    mavlink::CommandLong cmd;
    int sent = 0;
    int64_t next_at = 0;  // when it is (re)sent
  };
  int64_t timeout_us_;
  int attempts_;
  std::map<uint16_t, InFlight> inflight_;
  std::string last_text_;
};

}  // namespace aerie::bridge
