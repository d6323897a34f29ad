#include "tools/landing/landing_run.hpp"

#include <aerie/pilot_state_t.hpp>
#include <aerie/target_pose_t.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <numbers>

#include "air/pilot/node/pilot_node.hpp"
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

RunResult fly(const RunConfig& config) {
  const auto wall0 = std::chrono::steady_clock::now();
  sim::FlightSim simulator(config.sim);
  bus::Bus bus("memq://");
  if (config.on_message)
    bus.subscribe_raw(".*", [&](const uint8_t* data, size_t size, const bus::ReceiveInfo& info) {
      config.on_message(info.channel, data, size);
    }, 100000);
  sim::FlightSimNode sim_node(bus, simulator, {});
  track::TrackNode track_node(bus, config.track);
  pilot::PilotNode pilot_node(bus, config.pilot);

  RunResult r;
  std::map<int64_t, sim::TargetTruth> truth;  // of the last frames, by utime
  bool descending = false;
  bus.subscribe<aerie::pilot_state_t>("PILOT_STATE", [&](const aerie::pilot_state_t& m, const bus::ReceiveInfo&) {
    descending = m.state == aerie::pilot_state_t::DESCEND;
  });
  bus.subscribe<aerie::target_pose_t>("TARGET_POSE", [&](const aerie::target_pose_t& m, const bus::ReceiveInfo&) {
    ++r.target_poses;
    const auto it = truth.find(m.utime);
    if (!descending || it == truth.end()) return;
    const sim::TargetTruth& g = it->second;
    r.descent.push_back({m.utime * 1e-6, g.position.z(), m.position[0] - g.position.x(), m.position[1] - g.position.y(),
                         m.position[2] - g.position.z(),
                         std::remainder(m.yaw - g.yaw, std::numbers::pi) * 180 / std::numbers::pi,
                         m.source == aerie::target_pose_t::SOURCE_FIT});
  });

  int64_t end_frame = -1;
  while (true) {
    const sim::FlightFrame& f = sim_node.publish_next();
    truth[f.utime] = f.target;
    if (truth.size() > 50) truth.erase(truth.begin());
    sim_node.wait_answers();
    if (simulator.outcome().ended() && end_frame < 0) end_frame = f.seq;
    const pilot::State s = pilot_node.pilot().state();
    if (end_frame >= 0 && (s == pilot::State::Landed || s == pilot::State::Aborted ||
                           f.seq >= end_frame + config.frames_after_end))
      break;
  }
  track_node.wait_idle(5000);
  r.outcome = simulator.outcome();
  r.score = sim::score_landing(simulator);
  r.final_state = pilot::state_name(pilot_node.pilot().state());
  r.losses = pilot_node.pilot().status().losses;
  r.reacquisitions = pilot_node.pilot().status().reacquisitions;
  r.lockstep_timeouts = sim_node.lockstep_timeouts();
  r.pad_refined = track_node.counter("pad_refined");
  r.pad_not_found = track_node.counter("pad_not_found");
  r.tracker_reseeded = track_node.counter("tracker_reseeded");
  for (auto miss : {track::PadMiss::EmptyWindow, track::PadMiss::NoQuad, track::PadMiss::TouchesBorder,
                    track::PadMiss::NoMarking, track::PadMiss::Reprojection})
    if (const int64_t n = track_node.counter("pad_miss_" + track::to_string(miss)))
      r.pad_misses += (r.pad_misses.empty() ? "" : " ") + track::to_string(miss) + ":" + std::to_string(n);
  r.commands_refused = simulator.commands_refused();
  r.sim_s = simulator.time();
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return r;
}

}  // namespace aerie::landing
