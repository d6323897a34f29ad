#include "tools/landing/landing_run.hpp"

#include <aerie/pilot_state_t.hpp>
#include <aerie/target_pose_t.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <numbers>

#include "air/mavlink/node/mavlink_node.hpp"
#include "air/pilot/node/pilot_node.hpp"
#include "common/sim/autopilot/mavlink_face.hpp"
#include "common/sim/flight/node/flightsim_node.hpp"

namespace aerie::landing {

double RunResult::rmse(int axis, bool fitted_only) const {
  double s = 0;
  size_t n = 0;
  for (const auto& d : descent) {
    if (fitted_only && !d.fitted) continue;
    const double e = axis == 0 ? d.ex : axis == 1 ? d.ey : axis == 2 ? d.ez : d.eyaw_deg;
    s += e * e;
    ++n;
  }
  return n ? std::sqrt(s / static_cast<double>(n)) : std::nan("");
}

int64_t RunResult::box_poses() const {
  return std::count_if(descent.begin(), descent.end(), [](const DescentSample& d) { return !d.fitted; });
}

const char* to_string(Via v) {
  switch (v) {
    case Via::MavlinkOffboard: return "mavlink-offboard";
    case Via::MavlinkPrecland: return "mavlink-precland";
    default: return "direct";
  }
}

Via via_from_string(const std::string& name) {
  for (Via v : {Via::Direct, Via::MavlinkOffboard, Via::MavlinkPrecland})
    if (name == to_string(v)) return v;
  throw std::invalid_argument("via '" + name + "': expected direct, mavlink-offboard or mavlink-precland");
}

namespace {

// The vehicle behind an autopilot (Via::Mavlink*): aerie-mavlink's node on the pilot's bus and
// the simulator's autopilot on the vehicle, joined by a byte pipe, signed with a key made for
// the flight. Each frame, after the buses settled: the autopilot reads what the bridge wrote,
// steps on the vehicle's state and commands the vehicle; the bridge reads its replies and
// writes what is due. All on simulation time.
class MavlinkPath {
 public:
  MavlinkPath(const RunConfig& config, bus::Bus& air, sim::FlightSim& simulator)
      : sim_(simulator), face_(config.autopilot, sim::autopilot::airframe_params(config.sim.vehicle, config.sim.seed)) {
    auto [bridge_end, vehicle_end] = mavlink::memory_pipe("mavlink");
    vehicle_ = std::move(vehicle_end);
    bridge::BridgeConfig bc = config.bridge;
    bc.landing_path = config.via == Via::MavlinkPrecland ? bridge::LandingPath::Autopilot : bridge::LandingPath::Aerie;
    bc.takeoff_altitude_m = simulator.vehicle().params().takeoff_height_m;
    bc.camera_pitch_deg = config.pilot.camera_pitch_deg;
    mavlink::Key key{};
    for (size_t i = 0; i < key.size(); ++i) key[i] = static_cast<uint8_t>(config.sim.seed * 131 + i * 7);
    const util::NodeClock now = [&simulator] { return simulator.utime_of(simulator.time()); };
    bridge::AutopilotLink link(bc);
    link.enable_signing(key, 0, 0);
    face_.enable_signing(key, [now] { return bridge::signing_ticks(now()); });
    bridge::MavlinkNodeOptions opt;
    node_ = std::make_unique<bridge::MavlinkNode>(air, std::move(link), std::move(bridge_end),
                                                  std::vector<std::unique_ptr<mavlink::Endpoint>>{}, opt, now);
  }

  void step() {
    std::vector<uint8_t> in;
    vehicle_->read(in);
    const double t = sim_.time();
    face_.receive(in, t);
    const auto out = face_.step(t, sim_.vehicle().state());
    sim_.command(sim::autopilot::command_input(out.command));
    vehicle_->write(out.bytes);
    node_->step();
  }

  MavlinkCounters counters() const {
    const auto& c = node_->link().counters();
    MavlinkCounters m;
    m.setpoints = c.setpoints;
    m.landing_targets = c.landing_targets;
    m.commands_accepted = c.commands_accepted;
    m.commands_refused = c.commands_refused;
    m.commands_timed_out = c.commands_timed_out;
    m.frames_refused = static_cast<int64_t>(node_->link().parser_counters().refused() + face_.parser_counters().refused());
    m.autopilot_mode = face_.autopilot().mode_name();
    m.precland_state = sim::autopilot::to_string(face_.autopilot().precland_state());
    return m;
  }

 private:
  sim::FlightSim& sim_;
  sim::autopilot::MavlinkFace face_;
  std::unique_ptr<mavlink::Endpoint> vehicle_;
  std::unique_ptr<bridge::MavlinkNode> node_;
};

}  // namespace

RunResult fly(const RunConfig& config) {
  const auto wall0 = std::chrono::steady_clock::now();
  sim::FlightSim simulator(config.sim);
  link::SplitBus buses(config.split);
  bus::Bus& air = buses.on(link::Side::kAir);
  faults::Injector injector(config.faults, config.sim.seed);
  buses.tap(injector.tap(config.on_message));
  sim::FlightSimNodeOptions so;
  so.answer_channels.clear();  // a frame is answered when the buses are settled
  if (config.via != Via::Direct) so.command_channel.clear();  // the autopilot commands the vehicle
  sim::FlightSimNode sim_node(air, simulator, so);
  track::NodeOptions to = config.track;
  to.every_frame = true;  // lock-step: every frame delivered is tracked
  bus::Bus &track_bus = buses.of("track"), &pilot_bus = buses.of("pilot");
  faults::Respawnable<track::TrackNode> track_node(track_bus, [&] { return std::make_unique<track::TrackNode>(track_bus, to); });
  // The pilot's clock is the simulation's: its input-age rule sees the link's delay, not the machine's speed.
  const util::NodeClock now = [&simulator] { return simulator.utime_of(simulator.time()); };
  faults::Respawnable<pilot::PilotNode> pilot_node(
      pilot_bus, [&] { return std::make_unique<pilot::PilotNode>(pilot_bus, config.pilot, pilot::PilotNodeOptions{}, now); });
  faults::Flight flight{&buses, [&](bool stalled) { sim_node.stall_cameras(stalled); }, {}};
  flight.add("track", track_node);
  flight.add("pilot", pilot_node);
  auto wait_tracker = [&] {
    if (track_node.get()) track_node.get()->wait_idle(60000);
  };
  auto pilot_state = [&] { return pilot_node.get() ? pilot_node.get()->pilot().state() : pilot::State::Idle; };
  std::optional<MavlinkPath> mavlink;
  if (config.via != Via::Direct) mavlink.emplace(config, air, simulator);  // the bridge flies with the vehicle

  RunResult r;
  std::map<int64_t, sim::TargetTruth> truth;  // of the last frames, by utime
  bool descending = false;
  pilot_bus.subscribe<aerie::pilot_state_t>("PILOT_STATE", [&](const aerie::pilot_state_t& m, const bus::ReceiveInfo&) {
    descending = m.state == aerie::pilot_state_t::DESCEND;
  }, 1000);
  pilot_bus.subscribe<aerie::target_pose_t>("TARGET_POSE", [&](const aerie::target_pose_t& m, const bus::ReceiveInfo&) {
    ++r.target_poses;
    const auto it = truth.find(m.utime);
    if (!descending || it == truth.end()) return;
    const sim::TargetTruth& g = it->second;
    r.descent.push_back({m.utime * 1e-6, g.position.z(), m.position[0] - g.position.x(), m.position[1] - g.position.y(),
                         m.position[2] - g.position.z(),
                         std::remainder(m.yaw - g.yaw, std::numbers::pi) * 180 / std::numbers::pi,
                         m.source == aerie::target_pose_t::SOURCE_FIT});
  }, 1000);

  int64_t end_frame = -1;
  while (true) {
    const sim::FlightFrame& f = sim_node.publish_next();
    truth[f.utime] = f.target;
    if (truth.size() > 400) truth.erase(truth.begin());  // 20 s at 20 Hz: longer than any link delay studied
    injector.step(f.t, flight);
    buses.settle(f.utime, wait_tracker);
    if (mavlink) mavlink->step();
    if (simulator.outcome().ended() && end_frame < 0) end_frame = f.seq;
    const pilot::State s = pilot_state();
    if (end_frame >= 0 && (s == pilot::State::Landed || s == pilot::State::Aborted ||
                           f.seq >= end_frame + config.frames_after_end))
      break;
  }
  r.outcome = simulator.outcome();
  r.score = sim::score_landing(simulator);
  r.final_state = pilot::state_name(pilot_state());
  r.dead_at_end = !track_node.get() || !pilot_node.get();
  if (const pilot::PilotNode* p = pilot_node.get()) {
    r.losses = p->pilot().status().losses;
    r.reacquisitions = p->pilot().status().reacquisitions;
    r.pilot_stale_holds = p->pilot().status().stale_holds + p->pilot().status().age_holds;
    for (const char* ch : {"TARGET_POSE", "TRACK", "IMU"})
      r.pilot_refused += p->counter(std::string(ch) + "_refused") + p->counter(std::string(ch) + "_time_held");
  }
  r.lockstep_timeouts = sim_node.lockstep_timeouts();
  if (track::TrackNode* t = track_node.get()) {
    t->wait_idle(5000);
    r.pad_refined = t->counter("pad_refined");
    r.pad_not_found = t->counter("pad_not_found");
    r.tracker_reseeded = t->counter("tracker_reseeded");
    for (auto miss : {track::PadMiss::EmptyWindow, track::PadMiss::NoQuad, track::PadMiss::TouchesBorder,
                      track::PadMiss::NoMarking, track::PadMiss::Reprojection})
      if (const int64_t n = t->counter("pad_miss_" + track::to_string(miss)))
        r.pad_misses += (r.pad_misses.empty() ? "" : " ") + track::to_string(miss) + ":" + std::to_string(n);
  }
  r.faults = injector.report(buses, sim_node.stalled_frames(), simulator.vehicle().command_timeouts());
  r.commands_refused = simulator.commands_refused();
  if (mavlink) r.mavlink = mavlink->counters();
  r.link_down = buses.down_counters();
  r.link_up = buses.up_counters();
  r.sim_s = simulator.time();
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return r;
}

}  // namespace aerie::landing
