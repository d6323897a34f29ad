// aerie-bench-avoidance: the collision-avoidance flights of thesis ch. 5 in the closed-loop
// simulator, steered by aerie-control on a chosen heading source, one row per run.
//   aerie-bench-avoidance --runs N --seed S --speed M_S --source gt|vo|vio
//                         --controller FILE_OR_NAME --out DIR
// Each run flies loop/avoidance.hpp (config/avoidance.yaml) in lock-step, so a row depends on
// its seed alone. Lists (--speed 0.4,0.6,0.8 --source gt,vo,vio --controller sf,sfmf) run
// every combination. Writes DIR/avoidance.csv and DIR/trajectories.csv and prints one
// summary line per configuration; DIR/*.png when bench/avoidance/plot_avoidance.py runs.
// The runs are one study (tools/study): on --jobs threads, or over the ranks when started by
// mpirun/srun (`mpirun -np N aerie-bench-avoidance ...`, the same rows); --resume DIR continues
// an interrupted study from its CSVs and DIR/study.progress (docs/scale.md).
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/core.hpp>
#include <sstream>

#include "common/flc/flc_io.hpp"
#include "bench/seeded_runs.hpp"
#include "loop/avoidance.hpp"
#include "tools/study/note.hpp"
#include "tools/study/study.hpp"

using namespace aerie;

namespace {

struct Setup {
  double speed = 0.6;
  loop::avoidance::Source source = loop::avoidance::Source::kVio;
  std::string controller;
  bool vibration = true;
};

// What a configuration's summary line needs of a run, as its study note (exact), so that a
// summary also covers runs flown on other ranks or before a --resume.
struct Share {
  bool entered_danger = false, collided = false, completed = false;
  double heading_rmse_deg = 0, estimate_rmse_deg = 0, min_wall_distance_m = 0, wall_s = 0, sim_s = 0;
};

std::string note_of(const loop::avoidance::RunResult& r) {
  study::NoteWriter n;
  n.integer(r.entered_danger).integer(r.collided).integer(r.completed);
  n.real(r.heading_rmse_deg).real(r.estimate_rmse_deg).real(r.min_wall_distance_m).real(r.wall_s).real(r.sim_s);
  return n.str();
}

Share share_of(const std::string& note) {
  study::NoteReader in(note, "aerie-bench-avoidance: a run's summary note");
  Share s;
  s.entered_danger = in.integer() != 0;
  s.collided = in.integer() != 0;
  s.completed = in.integer() != 0;
  s.heading_rmse_deg = in.real();
  s.estimate_rmse_deg = in.real();
  s.min_wall_distance_m = in.real();
  s.wall_s = in.real();
  s.sim_s = in.real();
  in.end();
  return s;
}

std::string summary(const Setup& s, const std::vector<Share>& runs) {
  int danger = 0, collisions = 0, completed = 0, settled = 0;
  double rmse = 0, est = 0, wall = 0, sim_s = 0, min_wall = 1e9;
  for (const auto& r : runs) {
    danger += r.entered_danger;
    collisions += r.collided;
    completed += r.completed;
    if (r.heading_rmse_deg >= 0) {
      rmse += r.heading_rmse_deg;
      ++settled;
    }
    est += r.estimate_rmse_deg;
    min_wall = std::min(min_wall, r.min_wall_distance_m);
    wall += r.wall_s;
    sim_s += r.sim_s;
  }
  const double n = static_cast<double>(runs.size());
  char line[512];
  std::snprintf(line, sizeof line,
                "%-4s %-8s %.1f m/s vib %-3s: %d/%zu completed, steady heading RMSE %.2f deg (%d settled), heading estimate "
                "RMSE %.2f deg, %d in the dangerous area, %d collisions, closest to the wall %.2f m, %.2f s wall per "
                "simulated s",
                loop::avoidance::source_name(s.source), s.controller.c_str(), s.speed, s.vibration ? "on" : "off", completed, runs.size(),
                settled ? rmse / settled : std::nan(""), settled, est / n, danger, collisions, min_wall, wall / sim_s);
  return line;
}

// One run's rows of avoidance.csv and trajectories.csv.
study::Record rows_of(const Setup& s, uint64_t run_seed, const loop::avoidance::RunResult& r) {
  std::ostringstream csv, traj;
  const char* src = loop::avoidance::source_name(s.source);
  csv << run_seed << ',' << s.speed << ',' << src << ',' << s.controller << ',' << r.heading_rmse_deg << ','
      << r.entered_danger << ',' << r.collided << ',' << (s.vibration ? "on" : "off") << ',' << r.completed << ',' << r.timed_out << ',' << r.settle_time_s
      << ',' << r.itse << ',' << r.activation_travel_m << ',' << r.min_wall_distance_m << ',' << r.estimate_rmse_deg
      << ',' << r.vo_poses << ',' << r.vo_not_ok << ',' << r.nav_gated << ',' << r.commands_fallback << ','
      << r.commands_refused << ',' << r.lockstep_timeouts << ',' << r.sim_s << ',' << r.wall_s << '\n';
  for (const auto& p : r.trajectory)
    traj << run_seed << ',' << s.speed << ',' << src << ',' << s.controller << ',' << (s.vibration ? "on" : "off")
         << ',' << p.t << ',' << p.travel_m << ','
         << p.lateral_m << ',' << p.heading_deg << ',' << p.estimate_deg << ',' << p.command_deg_s << ','
         << p.turning << '\n';
  return study::Record{{csv.str(), traj.str()}, note_of(r), ""};
}

}  // namespace

int main(int argc, char** argv) {
  study::Session session(argc, argv);  // MPI only when mpirun/srun started us (docs/scale.md)
  CLI::App app{"aerie-bench-avoidance: seeded collision-avoidance flights in lock-step (CSV, summary, plots); "
               "spreads them over the ranks when started by mpirun"};
  int runs = 20, jobs = 1;
  uint64_t seed = 1;
  std::vector<double> speeds{0.6};
  std::vector<std::string> sources{"vio"}, controllers{"sfmf"}, vibrations;
  std::string out_dir = "bench-avoidance", resume_dir, config_file = "config/avoidance.yaml", log_level = "warn";
  bool plots = true;
  double rank_timeout_s = 600;
  app.add_option("--runs", runs, "flights per configuration")->check(CLI::PositiveNumber);
  app.add_option("--seed", seed, "seed of the first run (run i uses seed + i)");
  app.add_option("--speed", speeds, "forward speeds in m/s (comma-separated; thesis: 0.4,0.6,0.8)")->delimiter(',')
      ->check(CLI::Range(0.05, 2.0));
  app.add_option("--source", sources, "heading source: gt (GT_POSE), vo (VO_POSE), vio (NAV_STATE: VO + IMU), or a list")
      ->delimiter(',')
      ->check(CLI::IsMember({"gt", "vo", "vio"}));
  app.add_option("--controller", controllers,
                 "controllers: initial, a name in config/flc (sf, sfmf: aerie-ceopt's), or a .yaml/.fll file; or a list")
      ->delimiter(',');
  app.add_option("--vibration", vibrations, "camera vibration: on, off or on,off (default: the config's sim.vibration.enabled)")->delimiter(',')
      ->check(CLI::IsMember({"on", "off"}));
  auto* out_opt = app.add_option("--out", out_dir, "output folder (avoidance.csv, trajectories.csv, study.progress, plots)");
  app.add_option("--resume", resume_dir,
                 "continue the study in this folder (started with --out and the same options): the runs already in its "
                 "CSVs are skipped")
      ->excludes(out_opt);
  app.add_option("--config", config_file, "scenario, simulator and node configuration");
  app.add_option("--jobs", jobs, "flights in parallel (threads; under MPI each rank flies one at a time)")
      ->check(CLI::Range(1, 64));
  app.add_option("--rank-timeout", rank_timeout_s,
                 "under MPI: seconds a rank may take over one flight before the study stops, naming it")
      ->check(CLI::PositiveNumber);
  app.add_flag("!--no-plots", plots, "do not run bench/avoidance/plot_avoidance.py");
  app.add_option("--log-level", log_level, "the nodes' log level");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = session.rank() == 0 ? app.exit(e) : e.get_exit_code();  // the help or the error, once
    return rc == 0 ? 0 : 2;
  }
  spdlog::set_level(spdlog::level::from_str(log_level));
  const bool writer = session.rank() == 0;

  loop::avoidance::RunConfig base;
  std::vector<std::pair<std::string, flc::FlcSpec>> flcs;
  try {
    base = loop::avoidance::load_avoidance_run(util::Config::load(config_file));
    for (const auto& c : controllers) flcs.emplace_back(c, loop::avoidance::controller_named(c));
  } catch (const std::exception& e) {
    if (writer) std::fprintf(stderr, "aerie-bench-avoidance: %s\n", e.what());
    return 2;
  }
  if (!resume_dir.empty()) out_dir = resume_dir;
  if (vibrations.empty()) vibrations.push_back(base.sim.vibration.enabled ? "on" : "off");
  std::vector<Setup> setups;
  for (const auto& vib : vibrations)
    for (const auto& c : controllers)
      for (const auto& src : sources)
        for (double v : speeds) setups.push_back({v, loop::avoidance::source_from_name(src), c, vib == "on"});
  if (jobs > 1 || session.distributed()) cv::setNumThreads(1);  // one core per flight
  if (session.distributed() && jobs > 1 && writer)
    std::fprintf(stderr, "aerie-bench-avoidance: --jobs %d ignored under MPI (%d ranks, one flight each at a time)\n", jobs,
                 session.size());
  std::vector<loop::avoidance::RunConfig> configs;
  for (const auto& s : setups) {
    loop::avoidance::RunConfig rc = base;
    rc.source = s.source;
    rc.speed_m_s = s.speed;
    rc.sim.vibration.enabled = s.vibration;
    rc.controller = std::find_if(flcs.begin(), flcs.end(), [&](const auto& f) { return f.first == s.controller; })->second;
    configs.push_back(std::move(rc));
  }

  // One study over every configuration x seed (index = setup * runs + i): rows in the order the
  // per-configuration loop wrote them.
  std::ostringstream definition;
  definition << "runs=" << runs << " seed=" << seed << " config=" << config_file << " configurations:";
  for (const auto& s : setups)
    definition << ' ' << loop::avoidance::source_name(s.source) << '/' << s.controller << '/' << s.speed << "/vib"
               << (s.vibration ? "on" : "off");
  std::vector<std::vector<Share>> shares(setups.size());
  std::vector<int> written(setups.size(), 0);
  int failures = 0;
  auto seed_of = [&](int index) { return seed + static_cast<uint64_t>(index % runs); };
  study::Study st;
  st.tool = "aerie-bench-avoidance";
  st.dir = out_dir;
  st.runs = runs * static_cast<int>(setups.size());
  st.outputs = {{"avoidance.csv",
                 "seed,speed_m_s,source,controller,heading_rmse_deg,entered_danger,collision,vibration,completed,timed_out,"
                 "settle_time_s,itse,activation_travel_m,min_wall_distance_m,estimate_rmse_deg,vo_poses,vo_not_ok,nav_gated,"
                 "commands_fallback,commands_refused,lockstep_timeouts,sim_s,wall_s\n"},
                {"trajectories.csv",
                 "seed,speed_m_s,source,controller,vibration,t_s,travel_m,lateral_m,heading_deg,estimate_deg,command_deg_s,"
                 "turning\n"}};
  st.definition = definition.str();
  st.run = [&](int index) {
    const auto k = static_cast<size_t>(index / runs);
    loop::avoidance::RunConfig rc = configs[k];
    rc.seed = seed_of(index);
    const loop::avoidance::RunResult r = loop::avoidance::fly(rc);
    if (r.sim_s <= 0) throw std::runtime_error("the flight simulated no time");
    return rows_of(setups[k], seed_of(index), r);
  };
  st.describe = [&](int index) {  // as run_seeded said it: the seed
    return "run with seed " + std::to_string(seed_of(index));
  };
  st.on_written = [&](int index, const study::Record& r) {
    const auto k = static_cast<size_t>(index / runs);
    if (r.failed())
      ++failures;
    else
      shares[k].push_back(share_of(r.note));
    if (++written[k] == runs && !shares[k].empty()) {
      std::printf("%s\n", summary(setups[k], shares[k]).c_str());
      std::fflush(stdout);
    }
  };
  if (!study::run_or_exit(st, {jobs, !resume_dir.empty(), rank_timeout_s}, session).writer) return 0;
  return bench::finish("aerie-bench-avoidance", "bench/avoidance/plot_avoidance.py", out_dir, plots, failures);
}
