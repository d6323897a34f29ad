#pragma once
// The avoidance scenario of the harness (loop/harness.hpp): one collision-avoidance flight of
// thesis 5.1.2 / Fig. 5.2 in lock-step: the simulator renders the forward stereo pair and the IMU; the real
// aerie-vo, aerie-nav and aerie-control classes run on one in-process LCM bus (memq://), and
// aerie-control steers the vehicle on the heading source under test:
//   gt  — GT_POSE (the simulator's truth);
//   vo  — VO_POSE (stereo odometry alone);
//   vio — NAV_STATE (the VO + IMU error-state EKF).
// The vehicle starts hovering square to a wall (scene.wall_m ahead), flies ahead at the
// speed, turns at the end of the normal flight area (aerie-control's activation distance, on
// its own estimate) to fly parallel to the wall, and the flight ends after
// scene.lateral_limit_m sideways, a collision, or the time limit. Every node handles its
// messages on the calling thread, so a frame is answered when the bus is empty: a run is a
// function of its configuration and seed. With a split, "vo", "nav" and "control" may run on
// the ground side, behind the link in simulation time.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "air/control/control_node.hpp"
#include "air/nav/nav_config.hpp"
#include "air/stereo/node/vo_node.hpp"
#include "common/flc/flc.hpp"
#include "common/sim/flight/flight_sim.hpp"
#include "common/sim/vehicle/avoidance.hpp"
#include "common/util/config.hpp"
#include "loop/harness.hpp"

namespace aerie::loop::avoidance {

enum class Source { kGt, kVo, kVio };
Source source_from_name(const std::string& name);  // gt | vo | vio; throws std::invalid_argument
const char* source_name(Source source);

// Wiring: the seed, the split ("vo", "nav", "control" on the ground side), the tap and the
// faults (the nodes that run — "vo", "nav", "control" — can be killed).
struct RunConfig : Wiring {
  sim::FlightSimConfig sim;     // stereo on; a given start, hovering, facing the wall
  sim::Scene scene;             // zones along the start heading (thesis Fig. 5.2)
  double settle_band_deg = 4.5; // steady state: after the last time |error| > this
  Source source = Source::kVio;
  double speed_m_s = 0.6;
  flc::FlcSpec controller;
  control::NodeOptions control; // input, channel, rate (one command per input) and heading frame are set per source
  stereo::VoNodeConfig vo;      // its bundle adjustment runs synchronously here (reproducible)
  nav::NavConfig nav;
};

// config/avoidance.yaml: `sim:` (config/sim/landing_room.yaml's keys), `scene:`,
// `settle_band_deg`, `control:` (stale_timeout_s, limits) and the files of `vo:` and `nav:`
// (relative paths from base_dir, the repository root). Throws naming the file and key.
// The controller is the thesis' initial one; the seed 1.
RunConfig load_avoidance_run(const util::Config& cfg, const std::string& base_dir = ".");

// "initial": the thesis' initial FLC; a bare name: config/flc/NAME.yaml under base_dir (sf,
// sfmf: aerie-ceopt's); else a file. Throws naming the file.
flc::FlcSpec controller_named(const std::string& name, const std::string& base_dir = ".");

// One frame of the flight (true values unless named estimate).
struct Sample {
  double t = 0, travel_m = 0, lateral_m = 0;  // along and across the start heading
  double heading_deg = 0;                     // clockwise from the start heading
  double estimate_deg = 0;                    // the heading aerie-control used, in the same frame (aligned at its first input)
  double command_deg_s = 0;
  bool turning = false;
};

struct RunResult : RunStats {
  bool activated = false, completed = false, collided = false, entered_danger = false, timed_out = false;
  std::string collision;
  double activation_travel_m = 0;   // true travel when aerie-control started the turn (its estimate said 1 m)
  double settle_time_s = -1, heading_rmse_deg = -1, itse = 0;  // sim::SettlingStats of the true heading
  double min_wall_distance_m = 0;
  double estimate_rmse_deg = std::nan("");  // heading estimate vs truth over the flight
  int64_t vo_poses = 0, vo_not_ok = 0, nav_gated = 0, commands_fallback = 0;
  std::vector<Sample> trajectory;
};

RunResult fly(const RunConfig& config);

}  // namespace aerie::loop::avoidance
