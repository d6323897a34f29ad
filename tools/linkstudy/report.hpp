#pragma once
// aerie-linkstudy's report (OUT/report.md): per workload and sweep, success and the error
// metric against the swept factor, one line per placement and tracker; the factor value
// at which success falls below 95 % and 50 %; the operator's view age; which stale-input
// fallbacks fired; the link's traffic. With fault scenarios, those tables are of the first
// scenario, and a table per placement and condition says, per scenario, whether the vehicle
// stayed safe, completed its mission and how it reacted. The plots (plot_linkstudy.py) are
// linked from it.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "tools/linkstudy/study.hpp"

namespace aerie::linkstudy {

// Aggregate of the runs of one (workload, placement, tracker, condition, fault scenario).
struct Cell {
  int runs = 0, successes = 0, collisions = 0;
  // Runs in which a stale-input fallback fired (the pilot's HOLD, aerie-control's fallback
  // hover), and in which the autopilot held because commands stopped.
  int runs_fallback = 0, runs_offboard_hold = 0;
  double malformed = 0;
  std::map<std::string, int> final_states;
  double metric_sum = 0;
  int metric_n = 0;
  double age_p50_sum = 0, age_p95_sum = 0;
  int age_n = 0;
  double stale_holds = 0, fallbacks = 0, frames_lost = 0, down_kbit_s = 0, down_lost = 0, down_queue_dropped = 0;
  // channel -> (direction, hop latency medians of the runs, sent, delivered)
  struct Hop {
    std::string direction;
    double median_sum = 0;
    int runs = 0;
    int64_t sent = 0, delivered = 0;
  };
  std::map<std::string, Hop> hops;
  double success_rate() const { return runs ? static_cast<double>(successes) / runs : 0; }
  double metric_mean() const;
};

// The first value of the sweep (in the order of worsening: increasing delay, jitter and loss;
// decreasing bandwidth and JPEG quality, 0 = unlimited/raw counted best) at which the success
// rate is below `rate`; nullopt when none is.
std::optional<double> breaking_point(const std::string& factor, const std::vector<std::pair<double, Cell>>& by_value,
                                     double rate);

void write_report(const StudyConfig& study, const std::vector<RunSpec>& specs,
                  const std::vector<std::optional<RunRow>>& rows, const std::string& out_dir);

}  // namespace aerie::linkstudy
