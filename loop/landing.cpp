#include "loop/landing.hpp"

#include <aerie/pilot_state_t.hpp>
#include <aerie/target_pose_t.hpp>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "air/mavlink/node/mavlink_node.hpp"
#include "air/pilot/node/pilot_node.hpp"
#include "air/pilot/pilot_config.hpp"
#include "air/track/factory.hpp"
#include "common/sim/autopilot/mavlink_face.hpp"
#include "common/sim/flight/flight_config.hpp"

namespace aerie::loop::landing {

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
      : sim_(simulator), face_(config.autopilot, sim::autopilot::airframe_params(config.sim.vehicle, config.seed)) {
    auto [bridge_end, vehicle_end] = mavlink::memory_pipe("mavlink");
    vehicle_ = std::move(vehicle_end);
    bridge::BridgeConfig bc = config.bridge;
    bc.landing_path = config.via == Via::MavlinkPrecland ? bridge::LandingPath::Autopilot : bridge::LandingPath::Aerie;
    bc.takeoff_altitude_m = simulator.vehicle().params().takeoff_height_m;
    bc.camera_pitch_deg = config.pilot.camera_pitch_deg;
    mavlink::Key key{};
    for (size_t i = 0; i < key.size(); ++i) key[i] = static_cast<uint8_t>(config.seed * 131 + i * 7);
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
  sim::FlightSimNodeOptions so;
  if (config.via != Via::Direct) so.command_channel.clear();  // the autopilot commands the vehicle
  Harness harness(config, config.sim, so);
  sim::FlightSim& simulator = harness.sim();
  track::NodeOptions to = config.track;
  to.every_frame = true;  // lock-step: every frame delivered is tracked
  bus::Bus &track_bus = harness.bus_of("track"), &pilot_bus = harness.bus_of("pilot");
  faults::Respawnable<track::TrackNode> track_node(track_bus, [&] { return std::make_unique<track::TrackNode>(track_bus, to); });
  // The pilot's clock is the simulation's: its input-age rule sees the link's delay, not the machine's speed.
  const util::NodeClock now = harness.clock();
  faults::Respawnable<pilot::PilotNode> pilot_node(
      pilot_bus, [&] { return std::make_unique<pilot::PilotNode>(pilot_bus, config.pilot, pilot::PilotNodeOptions{}, now); });
  harness.add("track", track_node);
  harness.add("pilot", pilot_node);
  harness.wait_workers([&] {
    if (track_node.get()) track_node.get()->wait_idle(60000);
  });
  auto pilot_state = [&] { return pilot_node.get() ? pilot_node.get()->pilot().state() : pilot::State::Idle; };
  std::optional<MavlinkPath> mavlink;
  if (config.via != Via::Direct) mavlink.emplace(config, harness.air(), simulator);  // the bridge flies with the vehicle

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
                         m.source != aerie::target_pose_t::SOURCE_BOX});
  }, 1000);

  int64_t end_frame = -1;
  const auto remember = [&](const sim::FlightFrame& f) {
    truth[f.utime] = f.target;
    if (truth.size() > 400) truth.erase(truth.begin());  // 20 s at 20 Hz: longer than any link delay studied
  };
  while (true) {
    const sim::FlightFrame& f = harness.step(remember);
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
  if (mavlink) r.mavlink = mavlink->counters();
  static_cast<RunStats&>(r) = harness.finish();
  return r;
}

LandingSpec load_landing_spec(const util::Config& section, const std::string& base_dir) {
  section.check_keys({"sim", "track", "pilot", "tracker", "controller", "wind_m_s", "vibration", "max_time_s", "via", "autopilot"});
  const auto path = [&](const std::string& f) { return f.starts_with('/') ? f : base_dir + "/" + f; };
  const auto fail = [&](const std::string& key, const std::string& why) {
    throw std::runtime_error(section.origin() + ": key '" + key + "': " + why);
  };
  LandingSpec s;
  s.sim = path(section.get("sim", s.sim));
  s.track = path(section.get("track", s.track));
  s.pilot = path(section.get("pilot", s.pilot));
  s.tracker = section.get("tracker", s.tracker);
  if (!s.tracker.empty() && !track::is_known_tracker(s.tracker)) fail("tracker", "unknown tracker '" + s.tracker + "'");
  s.controller = section.get("controller", s.controller);
  if (!s.controller.empty() && s.controller != "fuzzy" && s.controller != "pid")
    fail("controller", "expected fuzzy or pid, not '" + s.controller + "'");
  if (section.has("wind_m_s")) s.wind_m_s = section.get_in("wind_m_s", 0.0, 0.0, 20.0);
  if (section.has("vibration")) s.vibration = section.get("vibration", true);
  if (section.has("max_time_s")) s.max_time_s = section.get_in("max_time_s", 90.0, 1.0, 3600.0);
  try {
    s.via = via_from_string(section.get<std::string>("via", to_string(s.via)));
  } catch (const std::invalid_argument& e) {
    fail("via", e.what());
  }
  const std::string autopilot = section.get<std::string>("autopilot", "px4");
  if (autopilot != "px4" && autopilot != "ardupilot") fail("autopilot", "expected px4 or ardupilot, not '" + autopilot + "'");
  s.autopilot = autopilot == "ardupilot" ? sim::autopilot::Personality::ArduCopter : sim::autopilot::Personality::Px4;
  return s;
}

RunConfig load_landing_run(const LandingSpec& spec, uint64_t seed) {
  RunConfig rc;
  rc.seed = seed;
  rc.sim = sim::load_flight_config(util::Config::load(spec.sim));
  if (spec.wind_m_s) rc.sim.wind.mean_m_s = *spec.wind_m_s;
  if (spec.vibration) rc.sim.vibration.enabled = *spec.vibration;
  if (spec.max_time_s) rc.sim.max_time_s = *spec.max_time_s;
  rc.sim.seed = seed;
  rc.track = track::node_options(util::Config::load(spec.track));
  if (!spec.tracker.empty()) rc.track.tracker = spec.tracker;
  rc.track.seed = seed;
  rc.pilot = load_landing_pilot(spec);
  rc.via = spec.via;
  rc.autopilot = spec.autopilot;
  return rc;
}

pilot::PilotConfig load_landing_pilot(const LandingSpec& spec) {
  if (spec.pilot_yaml.empty() && spec.controller.empty()) return pilot::load_pilot_config(util::Config::load(spec.pilot));
  std::string text = spec.pilot_yaml;
  if (text.empty()) {
    std::ifstream f(spec.pilot);
    if (!f) throw std::runtime_error(spec.pilot + ": cannot read the pilot configuration");
    std::stringstream all;
    all << f.rdbuf();
    text = all.str();
  }
  if (!spec.controller.empty()) {
    YAML::Node yaml = YAML::Load(text);
    yaml["controller"] = spec.controller;
    YAML::Emitter out;
    out << yaml;
    text = out.c_str();
  }
  return pilot::load_pilot_config(util::Config::parse(text, spec.pilot));
}

RunConfig load_landing_run(const util::Config& section, uint64_t seed, const std::string& base_dir) {
  return load_landing_run(load_landing_spec(section, base_dir), seed);
}

}  // namespace aerie::loop::landing
