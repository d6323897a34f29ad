#pragma once
// One autonomous landing in lock-step: the flight simulator node, the tracking node and the
// pilot node — the same classes as aerie-flightsim, aerie-track and aerie-pilot — on one
// in-process LCM bus (memq://), flown until the simulator reports the flight over. The
// result depends on the configs and the seed alone. Used by aerie-bench-landing and the
// closed-loop tests.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "air/pilot/pilot.hpp"
#include "air/track/node/track_node.hpp"
#include "common/sim/flight/flight_sim.hpp"

namespace aerie::landing {

struct RunConfig {
  sim::FlightSimConfig sim;
  track::NodeOptions track;
  pilot::PilotConfig pilot;
  // After the simulator reports the end, frames flown until the pilot says LANDED or
  // ABORTED, at most this many.
  int frames_after_end = 100;
  // Sees every message on the bus (channel, payload) in bus order, e.g. to record it.
  std::function<void(const std::string&, const uint8_t*, size_t)> on_message;
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
  std::string final_state;         // the pilot's
  int losses = 0, reacquisitions = 0;
  int64_t lockstep_timeouts = 0, target_poses = 0, commands_refused = 0;
  int64_t pad_refined = 0, pad_not_found = 0, tracker_reseeded = 0;  // aerie-track's counters
  std::string pad_misses;          // "reason:count ..." of the frames the pad was not found
  double sim_s = 0, wall_s = 0;
  std::vector<DescentSample> descent;
  // 0..2: x, y, z (m); 3: yaw (deg); over every DESCEND sample or the fitted ones; NaN without samples
  double rmse(int axis, bool fitted_only = false) const;
  int64_t box_poses() const;       // DESCEND samples from the tracker's box only
};

RunResult fly(const RunConfig& config);

}  // namespace aerie::landing
