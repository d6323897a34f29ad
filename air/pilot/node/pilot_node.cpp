#include "air/pilot/node/pilot_node.hpp"

#include <aerie/autopilot_state_t.hpp>
#include <aerie/imu_t.hpp>
#include <aerie/pilot_cmd_t.hpp>
#include <aerie/pilot_state_t.hpp>
#include <aerie/target_pose_t.hpp>
#include <aerie/track_t.hpp>
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>

namespace aerie::pilot {

PilotNode::PilotNode(bus::Bus& bus, PilotConfig config, PilotNodeOptions options, util::NodeClock now)
    : bus_(bus),
      pilot_(std::move(config)),
      opt_(std::move(options)),
      now_(std::move(now)),
      track_time_("tracker", pilot_.config().message_time),
      imu_time_(opt_.imu_channel, pilot_.config().message_time) {
  if (opt_.message_clock)
    now_ = [this] { return input_time(0); };
  // Every handler turns a refused input into a counted error; the pilot keeps its state.
  auto guarded = [this](const std::string& what, auto&& fn) {
    try {
      fn();
    } catch (const std::exception& e) {
      count(what + "_refused");
      last_error_ = what + ": " + e.what();
      spdlog::warn("{}", last_error_);
    }
  };
  bus_.subscribe<aerie::target_pose_t>(opt_.target_channel, [this, guarded](const aerie::target_pose_t& m, const bus::ReceiveInfo&) {
    guarded(opt_.target_channel, [&] {
      if (m.source < aerie::target_pose_t::SOURCE_BOX || m.source > aerie::target_pose_t::SOURCE_ARUCO)
        throw std::invalid_argument("unknown target pose source " + std::to_string(m.source));
      if (!on_time(track_time_, opt_.target_channel, m.utime)) return;
      // Every source but the box fits the target's own geometry (a pad's corners, a fiducial's).
      pilot_.on_target({m.utime, {m.position[0], m.position[1], m.position[2]}, m.yaw,
                        m.source != aerie::target_pose_t::SOURCE_BOX});
      count("targets");
    });
  });
  bus_.subscribe<aerie::track_t>(opt_.track_channel, [this, guarded](const aerie::track_t& m, const bus::ReceiveInfo&) {
    guarded(opt_.track_channel, [&] {
      if (m.status < 0 || m.status > aerie::track_t::REDETECTED)
        throw std::invalid_argument("unknown track status " + std::to_string(m.status));
      if (!on_time(track_time_, opt_.track_channel, m.utime)) return;
      count("tracks");
      publish(pilot_.on_track(m.utime, static_cast<TrackStatus>(m.status), input_age(m.utime)));
    });
  });
  bus_.subscribe<aerie::imu_t>(opt_.imu_channel, [this, guarded](const aerie::imu_t& m, const bus::ReceiveInfo&) {
    guarded(opt_.imu_channel, [&] {
      if (!on_time(imu_time_, opt_.imu_channel, m.utime)) return;
      if (m.orientation_valid)
        pilot_.on_attitude(m.utime, Eigen::Quaterniond(m.orientation[0], m.orientation[1], m.orientation[2], m.orientation[3]));
      if (const auto c = pilot_.on_clock(m.utime)) publish(*c);
    });
  }, 1000);  // 200 Hz: a deep queue so that a burst is not dropped
  bus_.subscribe<aerie::autopilot_state_t>(opt_.autopilot_channel, [this](const aerie::autopilot_state_t& m,
                                                                           const bus::ReceiveInfo&) {
    const bool ok = m.link != aerie::autopilot_state_t::LINK_LOST;
    if (ok == link_ok_) return;
    link_ok_ = ok;
    if (!ok) spdlog::warn("{}: the autopilot's link is lost: holding", opt_.autopilot_channel);
    pilot_.on_autopilot_link(ok, now_());
  });
  bus_.subscribe<aerie::pilot_cmd_t>(opt_.operator_channel, [this](const aerie::pilot_cmd_t& m, const bus::ReceiveInfo&) {
    // `source` is whatever the sender wrote: nothing authenticates it yet (issue 46), so the log
    // says so, and shows it quoted, at most 64 characters, control characters escaped.
    std::string source;
    for (const char ch : m.source.substr(0, 64)) {
      const auto c = static_cast<unsigned char>(ch);
      if (c == '"' || c == '\\') source += '\\';
      if (c >= 0x20 && c < 0x7f) {
        source += ch;
      } else {
        char hex[8];
        std::snprintf(hex, sizeof(hex), "\\x%02x", c);
        source += hex;
      }
    }
    if (m.source.size() > 64) source += "...";
    static const char* const kNames[] = {"START", "ABORT", "LAND", "RESUME"};
    const bool known = m.command >= aerie::pilot_cmd_t::START && m.command <= aerie::pilot_cmd_t::RESUME;
    const std::string what = opt_.operator_channel + " " + (known ? kNames[m.command] : std::to_string(m.command)) +
                             " (source \"" + source + "\", unauthenticated)";
    if (!known) {
      count("operator_refused");
      last_error_ = what + ": unknown command";
      spdlog::warn("{}", last_error_);
      return;
    }
    // On the pilot's own time: the operator's stamp (another host's clock) never moves its clock.
    const int64_t utime = input_time(m.utime);
    std::string why;
    if (pilot_.on_operator(static_cast<Pilot::Operator>(m.command), utime, &why)) {
      count("operator_accepted");
      spdlog::info("{} accepted: {} ({})", what, state_name(pilot_.state()), pilot_.status().reason);
    } else {
      count("operator_refused");
      last_error_ = what + " refused: " + why;
      spdlog::warn("{}", last_error_);
    }
  });
}

bool PilotNode::on_time(util::MessageClock& clock, const std::string& channel, int64_t utime) {
  const util::MessageClock::Result r = clock.observe(utime, now_());
  if (r.verdict == util::MessageClock::Verdict::kResynced) spdlog::info("{}: {}", channel, r.reason);
  if (r.accepted()) return true;
  count(channel + "_time_held");
  last_error_ = channel + ": " + r.reason;
  spdlog::warn("{}", last_error_);
  return false;
}

int64_t PilotNode::input_time(int64_t otherwise) const {
  return imu_time_.synced() ? imu_time_.newest() : track_time_.synced() ? track_time_.newest() : otherwise;
}

std::optional<double> PilotNode::input_age(int64_t utime) {
  // Replayed, a result is late only behind a newer one of its own source: how far the replayed
  // tracker lags the log's IMU depends on the replaying machine, not on the flight.
  return last_age_s_ = util::message_age_s(utime, opt_.message_clock ? track_time_.newest() : now_());
}

void PilotNode::publish(const Command& c) {
  const PilotStatus& s = pilot_.status();
  if (s.state != last_state_) {
    spdlog::info("{} -> {}: {}", state_name(last_state_), state_name(s.state), s.reason);
    last_state_ = s.state;
    count("transitions");
  }
  spdlog::debug("{} t {:.2f}: target ({:+.3f}, {:+.3f}) h {:.3f} yaw {:+.1f} -> v ({:+.2f}, {:+.2f}, {:+.2f}) r {:+.1f}",
                state_name(s.state), c.utime * 1e-6, s.target_level.x(), s.target_level.y(), s.height_m, s.yaw_error_deg,
                c.velocity.x(), c.velocity.y(), c.velocity.z(), c.yaw_rate_deg_s);
  aerie::control_cmd_t m{};
  m.utime = c.utime;
  m.seq = cmd_seq_++;
  switch (c.mode) {
    case Command::Mode::Hover: m.mode = aerie::control_cmd_t::HOVER; break;
    case Command::Mode::Velocity: m.mode = aerie::control_cmd_t::ACTIVE; break;
    case Command::Mode::Takeoff: m.mode = aerie::control_cmd_t::TAKEOFF; break;
    case Command::Mode::Land: m.mode = aerie::control_cmd_t::LAND; break;
  }
  m.controller_id = "pilot-" + pilot_.config().controller;
  for (int i = 0; i < 3; ++i) m.velocity_body[i] = static_cast<float>(c.velocity[i]);
  m.yaw_rate_deg_s = static_cast<float>(c.yaw_rate_deg_s);
  m.heading_error_deg = std::isfinite(s.yaw_error_deg) ? static_cast<float>(s.yaw_error_deg) : 0.f;
  bus_.publish(opt_.command_channel, m);
  count("commands");

  aerie::pilot_state_t p{};
  p.utime = c.utime;
  p.seq = state_seq_++;
  p.state = static_cast<int8_t>(s.state);
  p.state_name = state_name(s.state);
  p.reason = s.reason;
  p.time_in_state_s = s.time_in_state_s;
  p.target_valid = s.target_valid;
  for (int i = 0; i < 3; ++i) {
    p.target_body[i] = s.target_level[i];
    p.command_velocity[i] = m.velocity_body[i];
  }
  p.target_yaw_error_deg = s.yaw_error_deg;
  p.height_m = s.height_m;
  p.command_yaw_rate_deg_s = m.yaw_rate_deg_s;
  p.losses = s.losses;
  p.reacquisitions = s.reacquisitions;
  p.controller = pilot_.config().controller;
  bus_.publish(opt_.state_channel, p);
}

int64_t PilotNode::counter(const std::string& name) const {
  const auto it = counters_.find(name);
  return it == counters_.end() ? 0 : it->second;
}

void PilotNode::report(bus::StatusReporter& status) const {
  for (const auto& [k, v] : counters_) status.set(k, v);
  const PilotStatus& s = pilot_.status();
  status.set("losses", s.losses);
  status.set("stale_holds", s.stale_holds);
  status.set("link_holds", s.link_holds);
  status.set("age_holds", s.age_holds);
  status.set("aged_results", s.aged_results);
  // The newest TRACK's age on this node's clock; -1 when the clocks are not comparable.
  status.set("input_age_ms", last_age_s_ ? std::llround(*last_age_s_ * 1e3) : -1);
  status.set("reacquisitions", s.reacquisitions);
  const std::string msg = std::string(state_name(s.state)) + ": " + s.reason;
  if (s.state == State::Hold || s.state == State::Abort || s.state == State::Aborted)
    status.warn(msg);
  else if (!last_error_.empty())
    status.warn(msg + " (last refused input: " + last_error_ + ")");
  else
    status.ok(msg);
}

}  // namespace aerie::pilot
