#pragma once
// The landing scenario of the harness (loop/harness.hpp): one autonomous landing in
// lock-step, the tracking node and the pilot node — the same classes as aerie-track and
// aerie-pilot — on the harness's buses, flown until the simulator reports the flight over.
// With a split, "track" and "pilot" may run on the ground side, behind the link in simulation
// time. The result depends on the configs and the seed alone. Used by aerie-bench-landing,
// aerie-linkstudy, aerie-ceopt landing and the closed-loop tests, each through
// load_landing_run.
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
#include "common/util/config.hpp"
#include "loop/harness.hpp"

namespace aerie::loop::landing {

// How the pilot's commands reach the vehicle: straight to the simulator (CTRL_CMD), or
// through aerie-mavlink to the simulator's autopilot over MAVLink 2 (signed), which Aerie
// flies in offboard mode or lets land on its LANDING_TARGET (docs/mavlink.md).
enum class Via { Direct, MavlinkOffboard, MavlinkPrecland };
const char* to_string(Via v);  // "direct", "mavlink-offboard", "mavlink-precland"
Via via_from_string(const std::string& name);  // throws std::invalid_argument

// Wiring: the seed (the simulator's; load_landing_run gives it to the tracker too), the split ("track", "pilot" on the
// ground side), the tap and the faults ("track" and "pilot" can be killed).
struct RunConfig : Wiring {
  sim::FlightSimConfig sim;
  track::NodeOptions track;
  pilot::PilotConfig pilot;
  // After the simulator reports the end, frames flown until the pilot says LANDED or
  // ABORTED, at most this many.
  int frames_after_end = 100;
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
// corners fitted (SOURCE_FIT, or a fiducial board: what the pilot descends on), else the tracker's box only.
struct DescentSample {
  double t = 0, height = 0, ex = 0, ey = 0, ez = 0, eyaw_deg = 0;
  bool fitted = true;
};

struct RunResult : RunStats {
  sim::LandingScore score;
  sim::FlightOutcome outcome;
  std::string final_state;         // the pilot's (of its last incarnation)
  int losses = 0, reacquisitions = 0;
  int64_t pilot_stale_holds = 0;   // the pilot's HOLDs on stale inputs: a silent tracker, or results older than its age limit
  int64_t target_poses = 0;
  int64_t pad_refined = 0, pad_not_found = 0, tracker_reseeded = 0;  // aerie-track's counters (last incarnation)
  std::string pad_misses;          // "reason:count ..." of the frames the pad was not found
  int64_t pilot_refused = 0;       // inputs the pilot refused: bad values, held time stamps (last incarnation)
  bool dead_at_end = false;        // a node was dead when the flight ended
  std::vector<DescentSample> descent;
  MavlinkCounters mavlink;         // through MAVLink only
  // 0..2: x, y, z (m); 3: yaw (deg); over every DESCEND sample or the fitted ones; NaN without samples
  double rmse(int axis, bool fitted_only = false) const;
  int64_t box_poses() const;       // DESCEND samples from the tracker's box only
};

RunResult fly(const RunConfig& config);

// What a landing run is made of: the files (relative to base_dir) and what is set over them.
// The keys of the link study's `landing:` section; aerie-bench-landing's and aerie-ceopt
// landing's options fill the same struct.
struct LandingSpec {
  std::string sim = "config/sim/landing_room.yaml";
  std::string track = "config/track_landing.yaml";
  std::string pilot = "config/pilot.yaml";
  std::string pilot_yaml;              // not empty: the pilot configuration's text (named by `pilot`), e.g. tuned gains
  std::string tracker;                 // "": the track file's
  std::string controller;              // "": the pilot file's (fuzzy | pid)
  std::optional<double> wind_m_s;      // else the sim file's
  std::optional<bool> vibration;
  std::optional<double> max_time_s;
  Via via = Via::Direct;
  sim::autopilot::Personality autopilot = sim::autopilot::Personality::Px4;
};

// A section with the keys sim, track, pilot (files relative to base_dir), tracker,
// controller, wind_m_s, vibration, max_time_s, via, autopilot (px4 | ardupilot); throws
// std::runtime_error naming the file, the key and its line for an unknown key or a bad value.
LandingSpec load_landing_spec(const util::Config& section, const std::string& base_dir = ".");
// The run of `spec` with `seed` (the simulator's and the tracker's): every file read afresh
// (the tracker's options hold YAML nodes, not safe to share between threads). Throws naming
// the file that cannot be read or is invalid.
RunConfig load_landing_run(const LandingSpec& spec, uint64_t seed);
RunConfig load_landing_run(const util::Config& section, uint64_t seed, const std::string& base_dir = ".");
// The pilot configuration of `spec` (its text or file, with its controller); throws naming `spec.pilot`.
pilot::PilotConfig load_landing_pilot(const LandingSpec& spec);

}  // namespace aerie::loop::landing
