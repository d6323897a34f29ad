#include "common/sim/autopilot/mavlink_face.hpp"

#include <stdexcept>

#include "common/mavlink/frame.hpp"

namespace aerie::sim::autopilot {

CommandInput command_input(const AutopilotCommand& c) {
  using Mode = AutopilotCommand::Mode;
  CommandInput in;
  in.mode = c.mode == Mode::Velocity ? 1 : c.mode == Mode::Takeoff ? 3 : c.mode == Mode::Land ? 4 : 0;
  in.velocity = {c.velocity.x(), c.velocity.y(), c.velocity.z()};
  in.yaw_rate_deg_s = c.yaw_rate_deg_s;
  return in;
}

MavlinkFace::MavlinkFace(Personality personality, const Params& params) : ap_(personality, params) {}

void MavlinkFace::enable_signing(const mavlink::Key& key, mavlink::SigningClock clock) {
  signer_.emplace(key, /*link_id=*/0, 0, clock);
  parser_.set_signing(key, /*require=*/true, clock);
}

void MavlinkFace::receive(std::span<const uint8_t> bytes, double t_s) {
  parser_.feed(bytes, [&](const mavlink::Frame& f) {
    std::optional<mavlink::Message> msg;
    try {
      msg = mavlink::decode_message(f);
    } catch (const std::invalid_argument&) {
    }
    if (!msg) {
      ++unknown_;
      return;
    }
    ap_.receive(*msg, f.sysid, f.compid, t_s);
  });
}

MavlinkFace::Output MavlinkFace::step(double t_s, const MultirotorState& truth) {
  StepOutput s = ap_.step(t_s, truth);
  Output out;
  out.command = s.command;
  for (const Outbound& m : s.messages) {
    std::visit(
        [&](const auto& msg) {
          const mavlink::Header h{SimAutopilot::kSystemId, SimAutopilot::kComponentId, seq_++};
          const auto frame = signer_ ? mavlink::encode(msg, h, *signer_) : mavlink::encode(msg, h);
          out.bytes.insert(out.bytes.end(), frame.begin(), frame.end());
        },
        m.msg);
  }
  return out;
}

}  // namespace aerie::sim::autopilot
