#include "air/mavlink/command_client.hpp"

#include <stdexcept>

namespace aerie::bridge {

namespace mav = aerie::mavlink;

std::string command_name(uint16_t command) {
  switch (command) {
    case mav::mav_cmd::kNavLand: return "MAV_CMD_NAV_LAND";
    case mav::mav_cmd::kNavTakeoff: return "MAV_CMD_NAV_TAKEOFF";
    case mav::mav_cmd::kDoSetMode: return "MAV_CMD_DO_SET_MODE";
    case mav::mav_cmd::kComponentArmDisarm: return "MAV_CMD_COMPONENT_ARM_DISARM";
    case mav::mav_cmd::kSetMessageInterval: return "MAV_CMD_SET_MESSAGE_INTERVAL";
    case mav::mav_cmd::kRequestMessage: return "MAV_CMD_REQUEST_MESSAGE";
    case mav::mav_cmd::kRequestAutopilotCapabilities: return "MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES";
    default: return "MAV_CMD " + std::to_string(command);
  }
}

std::string CommandClient::Result::describe() const {
  std::string s = command_name(command) + ": ";
  if (timed_out) return s + "no COMMAND_ACK (timed out)";
  s += mav::mav_result::to_string(result);
  if (!accepted && !reason.empty()) s += " (" + reason + ")";
  return s;
}

CommandClient::CommandClient(int64_t timeout_us, int attempts) : timeout_us_(timeout_us), attempts_(attempts) {
  if (timeout_us <= 0 || attempts < 1)
    throw std::invalid_argument("command client: timeout must be > 0 and attempts >= 1");
}

void CommandClient::send(mav::CommandLong cmd, int64_t now_us) {
  cmd.confirmation = 0;
  inflight_[cmd.command] = InFlight{cmd, 0, now_us};
}

std::vector<mav::CommandLong> CommandClient::due(int64_t now_us) {
  std::vector<mav::CommandLong> out;
  for (auto& [id, f] : inflight_) {
    if (f.sent >= attempts_ || now_us < f.next_at) continue;
    f.cmd.confirmation = static_cast<uint8_t>(f.sent);  // 0 first, then 1, 2, ... on retransmissions
    out.push_back(f.cmd);
    ++f.sent;
    f.next_at = now_us + timeout_us_;
  }
  return out;
}

std::optional<CommandClient::Result> CommandClient::on_ack(const mav::CommandAck& ack, int64_t now_us) {
  const auto it = inflight_.find(ack.command);
  if (it == inflight_.end()) return std::nullopt;
  if (ack.result == mav::mav_result::kInProgress) {  // the autopilot is working on it: wait again
    it->second.next_at = now_us + timeout_us_;
    return std::nullopt;
  }
  Result r;
  r.command = ack.command;
  r.result = ack.result;
  r.accepted = ack.result == mav::mav_result::kAccepted;
  if (!r.accepted) r.reason = last_text_;
  last_text_.clear();
  inflight_.erase(it);
  return r;
}

std::vector<CommandClient::Result> CommandClient::expired(int64_t now_us) {
  std::vector<Result> out;
  for (auto it = inflight_.begin(); it != inflight_.end();) {
    if (it->second.sent >= attempts_ && now_us >= it->second.next_at) {
      Result r;
      r.command = it->first;
      r.timed_out = true;
      out.push_back(r);
      it = inflight_.erase(it);
    } else {
      ++it;
    }
  }
  return out;
}

}  // namespace aerie::bridge
