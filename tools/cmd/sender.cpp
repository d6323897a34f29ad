#include "tools/cmd/sender.hpp"

#include <algorithm>
#include <stdexcept>

#include "air/track/node/track_node.hpp"
#include "common/bus/channels.hpp"
#include "common/util/time.hpp"

namespace aerie::cmd {

void send(bus::Bus& bus, const Command& c) {
  std::visit(
      [&](const auto& m) {
        using M = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<M, aerie::track_cmd_t>) {
          if (const std::string why = track::refuse_command(m, nullptr); !why.empty())
            throw std::invalid_argument(c.channel + ": " + why + " (aerie-track would refuse it)");
        }
        bus.publish(c.channel, m);
      },
      c.message);
}

std::string answer_channel(const Command& c) {
  if (const auto* t = std::get_if<aerie::track_cmd_t>(&c.message)) {
    if (t->command == aerie::track_cmd_t::INIT || t->command == aerie::track_cmd_t::STOP) return channels::kTrack;
  } else if (std::holds_alternative<aerie::pilot_cmd_t>(c.message)) {
    return channels::kPilotState;
  }
  throw std::invalid_argument("--wait-ack: " + describe(c) + " has no answer to wait for (only track INIT / stop and pilot)");
}

Ack send_and_wait(bus::Bus& bus, const Command& c, double timeout_s, const std::function<void()>& idle) {
  Ack ack;
  const std::string channel = answer_channel(c);
  bus::Subscription* sub = nullptr;
  auto note = [&](bool effect, std::string text) {
    if (ack.took_effect) return;  // the first answer that showed it stays
    ++ack.seen;
    ack.message = std::move(text);
    ack.took_effect = effect;
  };
  if (const auto* t = std::get_if<aerie::track_cmd_t>(&c.message)) {
    sub = &bus.subscribe<aerie::track_t>(channel, [&, sent = *t](const aerie::track_t& m, const bus::ReceiveInfo&) {
      note(track_took_effect(sent, m), describe(m));
    });
  } else {
    const int8_t command = std::get<aerie::pilot_cmd_t>(c.message).command;
    sub = &bus.subscribe<aerie::pilot_state_t>(channel, [&, command](const aerie::pilot_state_t& m,
                                                                      const bus::ReceiveInfo&) {
      note(pilot_took_effect(command, m), describe(m));
    });
  }
  try {
    send(bus, c);
    const int64_t deadline = util::wall_utime() + static_cast<int64_t>(timeout_s * 1e6);
    while (!ack.took_effect) {
      const int64_t left_us = deadline - util::wall_utime();
      if (left_us <= 0) break;
      bus.handle(static_cast<int>(std::min<int64_t>((left_us + 999) / 1000, 50)));
      if (idle && !ack.took_effect) idle();
    }
  } catch (...) {
    bus.unsubscribe(*sub);
    throw;
  }
  bus.unsubscribe(*sub);
  return ack;
}

}  // namespace aerie::cmd
