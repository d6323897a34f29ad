#pragma once
// The delayed-link study (aerie-linkstudy, docs/linkstudy.md): closed-loop flights of the
// lock-step simulator with the nodes split between the air and the ground sides and the
// air-ground link between them in simulation time (tools/link/sim_link.hpp), over a set of
// link conditions, placements, workloads, trackers and seeds. One row per run.
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "common/util/config.hpp"
#include "loop/avoidance.hpp"
#include "loop/landing.hpp"
#include "loop/replay.hpp"
#include "tools/latency/link_hops.hpp"
#include "tools/link/sim_link.hpp"

namespace aerie::linkstudy {

enum class Workload { kLanding, kAvoidance, kReplay };
Workload workload_from_name(const std::string& name);  // landing | avoidance | replay
const char* workload_name(Workload w);

// One link condition, the same in both directions.
struct Condition {
  double delay_ms = 0, jitter_ms = 0;
  double loss = 0;                 // mean loss rate
  link::LossModel loss_model = link::LossModel::Bernoulli;
  double burst_length = 4;         // Gilbert-Elliott: mean messages per loss burst
  double bandwidth_mbit = 0;       // 0 = unlimited
  int jpeg_quality = 0;            // images re-encoded at this quality on the way; 0 = raw
  std::string name() const;        // e.g. "delay100_jit0_loss0.1_bw5_q60" (unique per condition)
  // The link direction this condition makes, carrying `channels`.
  link::DirectionConfig direction(const std::string& label, const std::string& channels, int64_t queue_bytes,
                                  uint64_t seed) const;
};

// A factor swept over values from the baseline (the other factors: the baseline's, then `with`).
struct Sweep {
  std::string factor;              // delay_ms, jitter_ms, loss, bandwidth_mbit or jpeg_quality
  std::vector<Condition> conditions;
};

struct Placement {
  std::string name;
  std::map<std::string, link::Side> nodes;  // nodes not named: air
};

struct StudyConfig {
  std::vector<Sweep> sweeps;
  std::vector<Placement> placements;
  std::vector<Workload> workloads;
  std::vector<std::string> trackers{"amcmr-ct"};  // landing and replay workloads
  // Fault scenarios (loop/faults.hpp, docs/faults.md), each one or more specs separated by
  // spaces; "none" flies without a fault. Closed-loop workloads (landing, avoidance) only.
  std::vector<std::string> faults{"none"};
  uint64_t first_seed = 1;
  int seeds = 3;
  int64_t queue_bytes = 262144;    // the radio's buffer per direction
  // landing workload: its `landing:` section (loop::landing::load_landing_spec; tracker and seed set per run)
  loop::landing::LandingSpec landing;
  // avoidance workload (seed set per run)
  loop::avoidance::RunConfig avoidance;
  // replay workload (open loop): a recorded log through the link; the tracker as landing.track says
  std::shared_ptr<const loop::replay::Recording> replay;
};

// The built-in placements (docs/linkstudy.md):
//   onboard          (a) everything on the air side, the ground only monitors;
//   ground-tracking  (b) tracking (and VO, nav, control, pilot) on the ground: images down, commands up;
//   ground-control   (c) tracking and VO on the air side, control and pilot on the ground.
std::vector<Placement> builtin_placements();
// The nodes a placement may name.
const std::vector<std::string>& known_nodes();

// Reads a study YAML (config/linkstudy/quick.yaml documents every key); files it names are
// relative to base_dir (the repository root). Throws std::runtime_error naming the file and
// the field for an unknown key, node, placement, workload or tracker, or a value out of range.
StudyConfig load_study(const util::Config& cfg, const std::string& base_dir = ".");

// What crosses the link for a workload and placement: the channels produced on one side
// and read on the other (the ground always reads what the operator watches). "" = none.
struct Crossing {
  std::string down, up;
  std::string operator_channel;    // what the operator's view is measured on
};
Crossing crossing(const StudyConfig& study, Workload w, const Placement& p);

struct RunSpec {
  const Condition* condition = nullptr;
  const Placement* placement = nullptr;
  Workload workload = Workload::kLanding;
  std::string tracker;             // "-" for avoidance
  uint64_t seed = 1;
  std::string faults = "none";     // the fault scenario
};

struct RunRow {
  bool success = false, collision = false;
  std::string metric;              // touchdown_error_m (landing), heading_rmse_deg (avoidance) or auc (replay)
  double value = 0;
  double touchdown_error_m = -1, yaw_error_deg = -1, time_s = -1;  // landing
  int losses = 0;
  double target_rmse_xy_m = -1;    // landing: TARGET_POSE during the descent, the poses descended on
  double heading_rmse_deg = -1;    // avoidance
  double auc = -1, mean_iou = -1, centre_error_px = -1;  // replay: the boxes that reached the operator
  int64_t frames_visible = 0, frames_lost = 0;
  bool entered_danger = false;
  double view_age_p50_ms = -1, view_age_p95_ms = -1;  // the operator's view, behind the vehicle
  int64_t view_messages = 0;
  int64_t pilot_stale_holds = 0, control_fallbacks = 0;
  link::DirectionCounters down, up;
  std::vector<latency::LinkHop> hops;  // the air and ground logs joined (aerie-latency AIR GROUND)
  double down_kbit_s = 0, up_kbit_s = 0;  // delivered wire bytes per simulated second
  std::string final_state;
  loop::faults::Report faults;     // landing, avoidance: what the flight saw of its faults
  double sim_s = 0, wall_s = 0;
};

// One flight; with log_prefix, writes log_prefix + "-air.lcm" and "-ground.lcm" (event time:
// simulation time).
RunRow run(const StudyConfig& study, const RunSpec& spec, const std::string& log_prefix = "");

// The CSV header and a row (the first columns are the interface). No wall-clock
// column: a study's CSV is the same on any machine.
std::string csv_header();
std::string csv_row(const std::string& sweep, const RunSpec& spec, const RunRow& row);

// A row as a study note (tools/study) and back, every field exact (row_note.cpp): how a run
// flown on another MPI rank, or before a --resume, reaches the CSV and the report. The reader
// throws std::runtime_error naming `what` when the note is not a row's.
std::string row_note(const RunRow& row);
RunRow row_from_note(const std::string& note, const std::string& what);

}  // namespace aerie::linkstudy
