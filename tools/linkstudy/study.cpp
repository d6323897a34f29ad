#include "tools/linkstudy/study.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>

#include "air/track/factory.hpp"
#include "common/bus/bus.hpp"
#include "common/logio/event_log.hpp"
#include "tools/latency/stats.hpp"

namespace aerie::linkstudy {

namespace {

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

// The factors of a condition, with their valid ranges.
struct Factor {
  const char* key;
  double lo, hi;
};
constexpr Factor kFactors[] = {{"delay_ms", 0, 60000}, {"jitter_ms", 0, 10000}, {"loss", 0, 0.9},
                               {"bandwidth_mbit", 0, 10000}, {"jpeg_quality", 0, 100}, {"burst_length", 1, 1000}};

void set_factor(Condition& c, const std::string& key, double v) {
  if (key == "delay_ms") c.delay_ms = v;
  else if (key == "jitter_ms") c.jitter_ms = v;
  else if (key == "loss") c.loss = v;
  else if (key == "bandwidth_mbit") c.bandwidth_mbit = v;
  else if (key == "jpeg_quality") c.jpeg_quality = static_cast<int>(std::lround(v));
  else if (key == "burst_length") c.burst_length = v;
}

// Reads the factors present in `section` into c, range-checked (the error names the key).
void read_factors(const util::Config& section, Condition& c) {
  for (const Factor& f : kFactors)
    if (section.has(f.key)) set_factor(c, f.key, section.get_in<double>(f.key, 0, f.lo, f.hi));
  if (section.has("loss_model")) c.loss_model = link::loss_model_from_string(section.get<std::string>("loss_model", ""));
}

// What each node reads and writes, per workload; "sim" (the vehicle) is always on the air side.
struct NodeIo {
  std::string node;
  std::vector<std::string> in, out;
};

std::vector<NodeIo> node_io(const StudyConfig& s, Workload w) {
  if (w == Workload::kReplay)  // "sim": the log played back on the air side
    return {{"sim", {}, {"CAM_DOWN", "GT_TRACK"}}, {"track", {"CAM_DOWN", "GT_TRACK"}, {"TRACK", "TARGET_POSE"}}};
  if (w == Workload::kLanding)
    return {{"sim", {"CTRL_CMD"}, {"IMU", "CAM_DOWN", "GT_TRACK"}},
            {"track", {"CAM_DOWN", "GT_TRACK"}, {"TRACK", "TARGET_POSE"}},
            {"pilot", {"TARGET_POSE", "TRACK", "IMU"}, {"CTRL_CMD", "PILOT_STATE"}}};
  const std::string pose = s.avoidance.source == loop::avoidance::Source::kGt   ? "GT_POSE"
                           : s.avoidance.source == loop::avoidance::Source::kVo ? "VO_POSE"
                                                                          : "NAV_STATE";
  std::vector<NodeIo> io{{"sim", {"CTRL_CMD"}, {"IMU", "CAM_STEREO", "GT_POSE"}}, {"control", {pose}, {"CTRL_CMD"}}};
  if (s.avoidance.source != loop::avoidance::Source::kGt) io.push_back({"vo", {"CAM_STEREO"}, {"VO_POSE"}});
  if (s.avoidance.source == loop::avoidance::Source::kVio) io.push_back({"nav", {"IMU", "VO_POSE"}, {"NAV_STATE"}});
  return io;
}

// What the operator watches on the ground: the landing camera with the tracker's box and the
// pilot's state; the vehicle's heading estimate and commands during avoidance.
std::vector<std::string> operator_channels(const StudyConfig& s, Workload w) {
  if (w == Workload::kReplay) return {"TRACK", "CAM_DOWN"};
  if (w == Workload::kLanding) return {"CAM_DOWN", "TRACK", "PILOT_STATE"};
  return {s.avoidance.source == loop::avoidance::Source::kGt ? "GT_POSE"
          : s.avoidance.source == loop::avoidance::Source::kVo ? "VO_POSE"
                                                        : "NAV_STATE",
          "CTRL_CMD"};
}

std::string join(const std::set<std::string>& channels) {
  std::string r;
  for (const auto& c : channels) r += (r.empty() ? "" : "|") + c;
  return r;
}

template <class T>
std::string names(const std::vector<T>& v) {
  std::string r;
  for (const auto& x : v) r += (r.empty() ? "" : ", ") + std::string(x);
  return r;
}

}  // namespace

Workload workload_from_name(const std::string& name) {
  if (name == "landing") return Workload::kLanding;
  if (name == "avoidance") return Workload::kAvoidance;
  if (name == "replay") return Workload::kReplay;
  throw std::invalid_argument("workload must be landing, avoidance or replay, not '" + name + "'");
}

const char* workload_name(Workload w) {
  return w == Workload::kLanding ? "landing" : w == Workload::kAvoidance ? "avoidance" : "replay";
}

std::string Condition::name() const {
  std::string n = "delay" + num(delay_ms) + "_jit" + num(jitter_ms) + "_loss" + num(loss);
  if (loss_model == link::LossModel::GilbertElliott) n += "ge" + num(burst_length);
  return n + "_bw" + num(bandwidth_mbit) + "_q" + std::to_string(jpeg_quality);
}

link::DirectionConfig Condition::direction(const std::string& label, const std::string& channels, int64_t queue_bytes,
                                           uint64_t seed) const {
  link::DirectionConfig d;
  d.name = label;
  d.channels = channels;
  d.delay_ms = delay_ms;
  d.jitter_ms = jitter_ms;
  d.loss_model = loss_model;
  if (loss_model == link::LossModel::Bernoulli) {
    d.loss = loss;
  } else {
    // Bursts of mean length L: leave Bad with r = 1/L; enter it with p so that p / (p + r) = loss.
    auto& ge = d.gilbert_elliott;
    ge.p_bad_to_good = 1.0 / burst_length;
    ge.p_good_to_bad = loss * ge.p_bad_to_good / (1.0 - loss);
    ge.loss_good = 0;
    ge.loss_bad = 1;
  }
  d.bandwidth_bps = bandwidth_mbit * 1e6;
  d.queue_bytes = queue_bytes;
  d.queue_policy = link::QueuePolicy::DropOldest;  // fresh data wins
  d.jpeg_channels = jpeg_quality > 0 ? "CAM_.*" : "";
  d.jpeg_quality = jpeg_quality > 0 ? jpeg_quality : 50;
  d.seed = seed;
  return d;
}

std::vector<Placement> builtin_placements() {
  using link::Side;
  return {{"onboard", {}},
          {"ground-tracking",
           {{"track", Side::kGround}, {"pilot", Side::kGround}, {"vo", Side::kGround}, {"nav", Side::kGround},
            {"control", Side::kGround}}},
          {"ground-control", {{"pilot", Side::kGround}, {"control", Side::kGround}}}};
}

const std::vector<std::string>& known_nodes() {
  static const std::vector<std::string> nodes{"track", "pilot", "vo", "nav", "control"};
  return nodes;
}

StudyConfig load_study(const util::Config& cfg, const std::string& base_dir) {
  const std::string& origin = cfg.origin();
  auto fail = [&](const std::string& field, const std::string& why) -> void {
    throw std::runtime_error(origin + ": " + field + ": " + why);
  };
  auto path = [&](const std::string& f) { return f.starts_with('/') ? f : base_dir + "/" + f; };
  std::vector<std::string> known{"seeds.first", "seeds.count", "queue_bytes", "workloads", "trackers", "placements",
                                 "baseline.loss_model", "landing.sim", "landing.track", "landing.pilot",
                                 "landing.wind_m_s", "landing.vibration", "landing.max_time_s", "avoidance.config",
                                 "avoidance.controller", "avoidance.source", "avoidance.speed_m_s", "replay.log",
                                 "faults"};
  for (const Factor& f : kFactors) {
    known.push_back(std::string("baseline.") + f.key);
    known.push_back(std::string("sweeps.") + f.key + ".values");
    for (const Factor& g : kFactors) known.push_back(std::string("sweeps.") + f.key + ".with." + g.key);
    known.push_back(std::string("sweeps.") + f.key + ".with.loss_model");
  }
  cfg.check_keys(known);

  StudyConfig s;
  s.first_seed = cfg.get<uint64_t>("seeds.first", s.first_seed);
  s.seeds = cfg.get_in("seeds.count", s.seeds, 1, 100000);
  s.queue_bytes = cfg.get_in<int64_t>("queue_bytes", s.queue_bytes, 1500, int64_t{1} << 30);

  // Conditions: the baseline, then each sweep's values.
  Condition baseline;
  read_factors(cfg.section("baseline"), baseline);
  const YAML::Node sweeps = cfg.node()["sweeps"];
  if (!sweeps || sweeps.size() == 0) fail("sweeps", "at least one sweep is needed (e.g. delay_ms: {values: [0, 100]})");
  for (const Factor& f : kFactors) {
    const std::string key = std::string("sweeps.") + f.key;
    if (!cfg.has(key)) continue;
    Sweep sw{f.key, {}};
    const auto values = cfg.require<std::vector<double>>(key + ".values");
    if (values.empty()) fail(key + ".values", "no values");
    Condition base = baseline;
    read_factors(cfg.section(key + ".with"), base);
    for (double v : values) {
      if (!(v >= f.lo && v <= f.hi))
        fail(key + ".values", num(v) + " is outside its valid range [" + num(f.lo) + ", " + num(f.hi) + "]");
      Condition c = base;
      set_factor(c, f.key, v);
      sw.conditions.push_back(c);
    }
    s.sweeps.push_back(std::move(sw));
  }

  // Placements: built-in names, or {name: {node: air|ground}}.
  const YAML::Node placements = cfg.node()["placements"];
  if (!placements || !placements.IsSequence() || placements.size() == 0)
    fail("placements", "a list of placements is needed (built-in: onboard, ground-tracking, ground-control)");
  const auto builtin = builtin_placements();
  for (size_t i = 0; i < placements.size(); ++i) {
    const std::string field = "placements[" + std::to_string(i) + "]";
    const YAML::Node p = placements[i];
    Placement pl;
    if (p.IsScalar()) {
      const auto it = std::find_if(builtin.begin(), builtin.end(), [&](const Placement& b) { return b.name == p.Scalar(); });
      if (it == builtin.end())
        fail(field, "unknown placement '" + p.Scalar() +
                        "' (built-in: onboard, ground-tracking, ground-control; or define one as {name: {node: side}})");
      pl = *it;
    } else if (p.IsMap() && p.size() == 1) {
      pl.name = p.begin()->first.as<std::string>();
      const YAML::Node nodes = p.begin()->second;
      if (!nodes.IsMap()) fail(field, "placement '" + pl.name + "' must map nodes to air or ground");
      for (const auto& kv : nodes) {
        const std::string node = kv.first.as<std::string>();
        if (std::find(known_nodes().begin(), known_nodes().end(), node) == known_nodes().end())
          fail(field + "." + pl.name, "unknown node '" + node + "' (nodes: " + names(known_nodes()) + ")");
        try {
          pl.nodes[node] = link::side_from_name(kv.second.as<std::string>());
        } catch (const std::exception& e) {
          fail(field + "." + pl.name + "." + node, e.what());
        }
      }
    } else {
      fail(field, "a built-in placement's name or {name: {node: air|ground}}");
    }
    for (const auto& other : s.placements)
      if (other.name == pl.name) fail(field, "placement '" + pl.name + "' is given twice");
    s.placements.push_back(std::move(pl));
  }

  for (const auto& w : cfg.get<std::vector<std::string>>("workloads", {"landing"})) {
    try {
      s.workloads.push_back(workload_from_name(w));
    } catch (const std::exception& e) {
      fail("workloads", e.what());
    }
  }
  if (s.workloads.empty()) fail("workloads", "none given (landing, avoidance)");
  s.trackers = cfg.get<std::vector<std::string>>("trackers", s.trackers);
  for (const auto& t : s.trackers)
    if (!track::is_known_tracker(t)) fail("trackers", "unknown tracker '" + t + "'");

  const auto has = [&](Workload w) { return std::find(s.workloads.begin(), s.workloads.end(), w) != s.workloads.end(); };
  s.faults = cfg.get<std::vector<std::string>>("faults", s.faults);
  if (s.faults.empty()) fail("faults", "none given (leave the key out, or list \"none\" and the scenarios)");
  for (const auto& f : s.faults) {
    try {
      const auto parsed = loop::faults::parse_list(f);
      loop::faults::Injector check(parsed, 1);
      if (!parsed.empty() && has(Workload::kReplay))
        fail("faults", "faults are injected into closed-loop flights (landing, avoidance), not the replay; '" + f + "'");
    } catch (const std::invalid_argument& e) {
      fail("faults", e.what());
    }
  }
  if (has(Workload::kLanding) || has(Workload::kReplay)) {
    s.landing = loop::landing::load_landing_spec(cfg.section("landing"), base_dir);
    // Every file read now, so that a bad one is refused before the first run.
    const track::NodeOptions to = loop::landing::load_landing_run(s.landing, s.first_seed).track;
    if (has(Workload::kReplay)) {
      if (!cfg.has("replay.log")) fail("replay.log", "the replay workload needs a recorded log (e.g. aerie-bench-landing --log-dir)");
      const std::string log = path(cfg.get<std::string>("replay.log", ""));
      if (!std::filesystem::is_regular_file(log)) fail("replay.log", "'" + log + "' is not a file");
      s.replay = loop::replay::load_recording(log, to.camera_channel, to.gt_channel);  // once: every replay run shares it
    }
  }
  if (has(Workload::kAvoidance)) {
    s.avoidance = loop::avoidance::load_avoidance_run(
        util::Config::load(path(cfg.get<std::string>("avoidance.config", "config/avoidance.yaml"))), base_dir);
    s.avoidance.controller = loop::avoidance::controller_named(cfg.get<std::string>("avoidance.controller", "sfmf"), base_dir);
    try {
      s.avoidance.source = loop::avoidance::source_from_name(cfg.get<std::string>("avoidance.source", "vio"));
    } catch (const std::exception& e) {
      fail("avoidance.source", e.what());
    }
    s.avoidance.speed_m_s = cfg.get_in("avoidance.speed_m_s", s.avoidance.speed_m_s, 0.05, 2.0);
  }
  return s;
}

Crossing crossing(const StudyConfig& study, Workload w, const Placement& p) {
  const auto io = node_io(study, w);
  const link::Split where{p.nodes, {}, {}};
  auto side = [&](const std::string& node) { return where.side(node); };
  std::set<std::string> read_on[2];  // by side
  for (const auto& n : io)
    for (const auto& c : n.in) read_on[static_cast<int>(side(n.node))].insert(c);
  for (const auto& c : operator_channels(study, w)) read_on[static_cast<int>(link::Side::kGround)].insert(c);
  std::set<std::string> down, up;
  for (const auto& n : io)
    for (const auto& c : n.out) {
      if (side(n.node) == link::Side::kAir && read_on[static_cast<int>(link::Side::kGround)].count(c)) down.insert(c);
      if (side(n.node) == link::Side::kGround && read_on[static_cast<int>(link::Side::kAir)].count(c)) up.insert(c);
    }
  return {join(down), join(up), operator_channels(study, w).front()};
}

RunRow run(const StudyConfig& study, const RunSpec& spec, const std::string& log_prefix) {
  const Crossing x = crossing(study, spec.workload, *spec.placement);
  link::Split split;
  split.nodes = spec.placement->nodes;
  split.down = spec.condition->direction("air->ground", x.down, study.queue_bytes, 2 * spec.seed - 1);
  split.up = spec.condition->direction("ground->air", x.up, study.queue_bytes, 2 * spec.seed);

  std::unique_ptr<logio::Writer> air_log, ground_log;
  if (!log_prefix.empty()) {
    air_log = std::make_unique<logio::Writer>(log_prefix + "-air.lcm");
    ground_log = std::make_unique<logio::Writer>(log_prefix + "-ground.lcm");
  }
  std::vector<double> ages_ms;
  latency::LinkJoin join;
  for (const auto& [channels, down] : {std::pair{x.down, true}, std::pair{x.up, false}}) {
    std::stringstream names(channels);
    for (std::string c; std::getline(names, c, '|');) join.hint(c, down);
  }
  // Each side's log at the simulation time its messages are handled, as each side's
  // lcm-logger would record them; the operator's view age on the ground.
  auto tap = [&](link::Side side, const std::string& channel, const uint8_t* data, size_t size, int64_t now_us) {
    if (air_log) (side == link::Side::kAir ? air_log : ground_log)->write(now_us, channel, data, size);
    join.add(side == link::Side::kAir ? latency::LinkJoin::Log::kAir : latency::LinkJoin::Log::kGround, channel, now_us,
             data, size);
    if (side == link::Side::kGround && channel == x.operator_channel)
      if (const auto u = bus::peek_utime(data, size); u && *u > 0)  // utime 0: no estimate yet (aerie-nav aligning)
        ages_ms.push_back(static_cast<double>(now_us - *u) / 1000.0);
  };

  RunRow row;
  if (spec.workload == Workload::kLanding) {
    loop::landing::LandingSpec ls = study.landing;
    ls.tracker = spec.tracker;
    loop::landing::RunConfig rc = loop::landing::load_landing_run(ls, spec.seed);
    rc.split = split;
    rc.on_message = tap;
    rc.faults = loop::faults::parse_list(spec.faults);
    const loop::landing::RunResult r = loop::landing::fly(rc);
    row.success = r.score.success;
    row.collision = r.outcome.collided;
    row.metric = "touchdown_error_m";
    row.touchdown_error_m = r.outcome.landed ? r.score.touchdown_error_m : -1;
    row.value = row.touchdown_error_m;
    row.yaw_error_deg = r.outcome.landed ? r.score.yaw_error_deg : -1;
    row.time_s = r.outcome.landed ? r.score.time_s : -1;
    row.losses = r.losses;
    const double ex = r.rmse(0, true), ey = r.rmse(1, true);
    row.target_rmse_xy_m = std::isfinite(ex) && std::isfinite(ey) ? std::hypot(ex, ey) : -1;
    row.pilot_stale_holds = r.pilot_stale_holds;
    row.down = r.link_down;
    row.up = r.link_up;
    row.final_state = r.final_state;
    row.faults = r.faults;
    row.sim_s = r.sim_s;
    row.wall_s = r.wall_s;
  } else if (spec.workload == Workload::kReplay) {
    loop::replay::RunConfig rc = loop::replay::load_replay_run(study.replay, study.landing.track, spec.tracker, spec.seed);
    rc.split = split;
    rc.on_message = tap;
    const loop::replay::RunResult r = loop::replay::fly(rc);
    row.metric = "auc";
    row.auc = row.value = r.auc;
    row.mean_iou = r.mean_iou;
    row.centre_error_px = r.centre_error_px;
    row.frames_visible = r.frames_visible;
    row.frames_lost = r.frames_lost;
    // The operator had a box on the target in at least 90 % of the frames it was visible in.
    row.success = r.frames_visible > 0 && r.auc > 0 &&
                  static_cast<double>(r.frames_visible - r.frames_lost) >= 0.9 * static_cast<double>(r.frames_visible) &&
                  r.mean_iou >= 0.5;
    row.down = r.link_down;
    row.up = r.link_up;
    row.final_state = "replayed";
    row.sim_s = r.sim_s;
  } else {
    loop::avoidance::RunConfig rc = study.avoidance;
    rc.seed = spec.seed;
    rc.split = split;
    rc.on_message = tap;
    rc.faults = loop::faults::parse_list(spec.faults);
    const loop::avoidance::RunResult r = loop::avoidance::fly(rc);
    row.collision = r.collided;
    row.entered_danger = r.entered_danger;
    row.success = r.completed && !r.collided && !r.entered_danger;
    row.metric = "heading_rmse_deg";
    row.heading_rmse_deg = r.heading_rmse_deg;
    row.value = r.heading_rmse_deg;
    row.control_fallbacks = r.commands_fallback;
    row.down = r.link_down;
    row.up = r.link_up;
    row.final_state = r.completed ? "completed" : r.collided ? "collided" : r.timed_out ? "timed_out" : "ended";
    row.faults = r.faults;
    row.sim_s = r.sim_s;
    row.wall_s = r.wall_s;
  }
  row.hops = join.hops();
  row.view_messages = static_cast<int64_t>(ages_ms.size());
  if (!ages_ms.empty()) {
    row.view_age_p50_ms = latency::percentile(ages_ms, 0.5);
    row.view_age_p95_ms = latency::percentile(ages_ms, 0.95);
  }
  if (row.sim_s > 0) {
    row.down_kbit_s = static_cast<double>(row.down.bytes_delivered) * 8e-3 / row.sim_s;
    row.up_kbit_s = static_cast<double>(row.up.bytes_delivered) * 8e-3 / row.sim_s;
  }
  return row;
}

std::string csv_header() {
  return "condition,delay_ms,loss,bandwidth_mbit,placement,workload,tracker,seed,success,metric,value,"
         "sweep,jitter_ms,loss_model,burst_length,jpeg_quality,collision,touchdown_error_m,yaw_error_deg,time_s,losses,"
         "target_rmse_xy_m,heading_rmse_deg,entered_danger,mean_iou,centre_error_px,frames_visible,frames_lost,view_age_p50_ms,view_age_p95_ms,view_messages,"
         "pilot_stale_holds,control_fallbacks,down_received,down_delivered,down_lost,down_queue_dropped,"
         "up_received,up_delivered,up_lost,up_queue_dropped,down_kbit_s,up_kbit_s,final_state,sim_s,"
         "faults,faults_applied,command_timeouts,camera_stalled_frames,malformed,burst_messages,nan_messages,kills,"
         "respawns,down_outage_dropped,up_outage_dropped";
}

std::string csv_row(const std::string& sweep, const RunSpec& spec, const RunRow& r) {
  const Condition& c = *spec.condition;
  std::ostringstream o;
  o << c.name() << ',' << c.delay_ms << ',' << c.loss << ',' << c.bandwidth_mbit << ',' << spec.placement->name << ','
    << workload_name(spec.workload) << ',' << spec.tracker << ',' << spec.seed << ',' << r.success << ',' << r.metric
    << ',' << r.value << ',' << sweep << ',' << c.jitter_ms << ','
    << (c.loss_model == link::LossModel::Bernoulli ? "bernoulli" : "gilbert_elliott") << ',' << c.burst_length << ','
    << c.jpeg_quality << ','
    << r.collision << ',' << r.touchdown_error_m << ',' << r.yaw_error_deg << ',' << r.time_s << ',' << r.losses << ','
    << r.target_rmse_xy_m << ',' << r.heading_rmse_deg << ',' << r.entered_danger << ',' << r.mean_iou << ','
    << r.centre_error_px << ',' << r.frames_visible << ',' << r.frames_lost << ',' << r.view_age_p50_ms << ','
    << r.view_age_p95_ms << ',' << r.view_messages << ',' << r.pilot_stale_holds << ',' << r.control_fallbacks << ','
    << r.down.received << ',' << r.down.delivered << ',' << r.down.dropped_loss << ',' << r.down.dropped_queue << ','
    << r.up.received << ',' << r.up.delivered << ',' << r.up.dropped_loss << ',' << r.up.dropped_queue << ','
    << r.down_kbit_s << ',' << r.up_kbit_s << ',' << r.final_state << ',' << r.sim_s << ',' << spec.faults << ','
    << r.faults.applied << ',' << r.faults.command_timeouts << ',' << r.faults.stalled_frames << ',' << r.faults.malformed
    << ',' << r.faults.counters.burst_messages << ',' << r.faults.counters.nan_messages << ',' << r.faults.counters.kills
    << ',' << r.faults.counters.respawns << ','
    << r.down.dropped_outage << ',' << r.up.dropped_outage;
  return o.str();
}

}  // namespace aerie::linkstudy
