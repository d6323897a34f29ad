#pragma once
// One autonomous landing in lock-step: the flight simulator node, the tracking node and the
// pilot node — the same classes as aerie-flightsim, aerie-track and aerie-pilot — on one
// in-process LCM bus (memq://), flown until the simulator reports the flight over. With a
// split, "track" and "pilot" may run on the ground side, behind the link in simulation
// time (tools/link/sim_link.hpp). Each frame, the buses are settled (every message
// handled, the tracker idle, the link's due messages delivered) before the physics steps,
// so the result depends on the configs and the seed alone. Used by aerie-bench-landing,
// aerie-linkstudy and the closed-loop tests.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "air/pilot/pilot.hpp"
#include "air/track/node/track_node.hpp"
#include "air/mavlink/autopilot_link.hpp"
#include "common/sim/autopilot/sim_autopilot.hpp"
#include "common/sim/flight/flight_sim.hpp"
#include "tools/faults/faults.hpp"
#include "tools/link/sim_link.hpp"

namespace aerie::landing {

// How the pilot's commands reach the vehicle: straight to the simulator (CTRL_CMD), or
// through aerie-mavlink to the simulator's autopilot over MAVLink 2 (signed), which Aerie
// flies in offboard mode or lets land on its LANDING_TARGET (docs/mavlink.md).
enum class Via { Direct, MavlinkOffboard, MavlinkPrecland };
const char* to_string(Via v);  // "direct", "mavlink-offboard", "mavlink-precland"
Via via_from_string(const std::string& name);  // throws std::invalid_argument

struct RunConfig {
  sim::FlightSimConfig sim;
  track::NodeOptions track;
  pilot::PilotConfig pilot;
  // After the simulator reports the end, frames flown until the pilot says LANDED or
  // ABORTED, at most this many.
  int frames_after_end = 100;
  // Nodes "track" and "pilot" on the ground side, and the link; none: one bus.
  std::optional<link::Split> split;
  // Sees every message on each side's bus in bus order, with the simulation time it is
  // handled at, e.g. to record it (the air side only without a split).
  link::SplitBus::Tap on_message;
  // Injected during the flight (tools/faults): nodes "track" and "pilot" can be killed.
  std::vector<faults::Fault> faults;
  Via via = Via::Direct;
  sim::autopilot::Personality autopilot = sim::autopilot::Personality::Px4;  // behind MAVLink
  bridge::BridgeConfig bridge;  // aerie-mavlink's (landing_path set from `via`)
};

// aerie-mavlink's and the autopilot's counters of a flight through MAVLink.
struct MavlinkCounters {
  int64_t setpoints = 0, landing_targets = 0, commands_accepted = 0, commands_refused = 0, commands_timed_out = 0;
  int64_t frames_refused = 0;      // by either side's parser
  std::string autopilot_mode;      // at the end
  std::string precland_state;      // PX4's precland state at the end (mavlink-precland)
};

// TARGET_POSE against the truth of its frame, during the pilot's DESCEND; fitted: the pad's
// corners fitted (SOURCE_FIT, what the pilot descends on), else the tracker's box only.
struct DescentSample {
  double t = 0, height = 0, ex = 0, ey = 0, ez = 0, eyaw_deg = 0;
  bool fitted = true;
};

struct RunResult {
  sim::LandingScore score;
  sim::FlightOutcome outcome;
  std::string final_state;         // the pilot's (of its last incarnation)
  int losses = 0, reacquisitions = 0;
  int64_t pilot_stale_holds = 0;   // the pilot's HOLDs on stale inputs: a silent tracker, or results older than its age limit
  int64_t lockstep_timeouts = 0, target_poses = 0, commands_refused = 0;
  int64_t pad_refined = 0, pad_not_found = 0, tracker_reseeded = 0;  // aerie-track's counters (last incarnation)
  std::string pad_misses;          // "reason:count ..." of the frames the pad was not found
  link::DirectionCounters link_down, link_up;  // with a split
  faults::Report faults;
  int64_t pilot_refused = 0;       // inputs the pilot refused: bad values, held time stamps (last incarnation)
  bool dead_at_end = false;        // a node was dead when the flight ended
  double sim_s = 0, wall_s = 0;
  std::vector<DescentSample> descent;
  MavlinkCounters mavlink;         // through MAVLink only
  // 0..2: x, y, z (m); 3: yaw (deg); over every DESCEND sample or the fitted ones; NaN without samples
  double rmse(int axis, bool fitted_only = false) const;
  int64_t box_poses() const;       // DESCEND samples from the tracker's box only
};

RunResult fly(const RunConfig& config);

}  // namespace aerie::landing
