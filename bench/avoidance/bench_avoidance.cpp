// aerie-bench-avoidance: the collision-avoidance flights of thesis ch. 5 in the closed-loop
// simulator, steered by aerie-control on a chosen heading source, one row per run.
//   aerie-bench-avoidance --runs N --seed S --speed M_S --source gt|vo|vio
//                         --controller FILE_OR_NAME --out DIR
// Each run flies tools/avoidance (config/avoidance.yaml) in lock-step, so a row depends on
// its seed alone. Lists (--speed 0.4,0.6,0.8 --source gt,vo,vio --controller sf,sfmf) run
// every combination. Writes DIR/avoidance.csv and DIR/trajectories.csv and prints one
// summary line per configuration; DIR/*.png when bench/avoidance/plot_avoidance.py runs.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>

#include "common/flc/flc_io.hpp"
#include "bench/seeded_runs.hpp"
#include "tools/avoidance/avoidance_run.hpp"

using namespace aerie;

namespace {

struct Setup {
  double speed = 0.6;
  avoidance::Source source = avoidance::Source::kVio;
  std::string controller;
  bool vibration = true;
};

std::string summary(const Setup& s, const std::vector<avoidance::RunResult>& runs) {
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
                avoidance::source_name(s.source), s.controller.c_str(), s.speed, s.vibration ? "on" : "off", completed, runs.size(),
                settled ? rmse / settled : std::nan(""), settled, est / n, danger, collisions, min_wall, wall / sim_s);
  return line;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"aerie-bench-avoidance: seeded collision-avoidance flights in lock-step (CSV, summary, plots)"};
  int runs = 20, jobs = 1;
  uint64_t seed = 1;
  std::vector<double> speeds{0.6};
  std::vector<std::string> sources{"vio"}, controllers{"sfmf"}, vibrations;
  std::string out_dir = "bench-avoidance", config_file = "config/avoidance.yaml", log_level = "warn";
  bool plots = true;
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
  app.add_option("--out", out_dir, "output folder (avoidance.csv, trajectories.csv, plots)");
  app.add_option("--config", config_file, "scenario, simulator and node configuration");
  app.add_option("--jobs", jobs, "flights in parallel (threads)")->check(CLI::Range(1, 64));
  app.add_flag("!--no-plots", plots, "do not run bench/avoidance/plot_avoidance.py");
  app.add_option("--log-level", log_level, "the nodes' log level");
  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(spdlog::level::from_str(log_level));

  avoidance::RunConfig base;
  std::vector<std::pair<std::string, flc::FlcSpec>> flcs;
  try {
    base = avoidance::load_run_config(util::Config::load(config_file));
    for (const auto& c : controllers) flcs.emplace_back(c, avoidance::controller_named(c));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "aerie-bench-avoidance: %s\n", e.what());
    return 2;
  }
  if (vibrations.empty()) vibrations.push_back(base.sim.vibration.enabled ? "on" : "off");
  std::vector<Setup> setups;
  for (const auto& vib : vibrations)
    for (const auto& c : controllers)
      for (const auto& src : sources)
        for (double v : speeds) setups.push_back({v, avoidance::source_from_name(src), c, vib == "on"});
  if (jobs > 1) cv::setNumThreads(1);  // one core per flight
  std::filesystem::create_directories(out_dir);
  std::ofstream csv(out_dir + "/avoidance.csv"), traj(out_dir + "/trajectories.csv");
  csv << "seed,speed_m_s,source,controller,heading_rmse_deg,entered_danger,collision,vibration,completed,timed_out,settle_time_s,"
         "itse,activation_travel_m,min_wall_distance_m,estimate_rmse_deg,vo_poses,vo_not_ok,nav_gated,commands_fallback,"
         "commands_refused,lockstep_timeouts,sim_s,wall_s\n";
  traj << "seed,speed_m_s,source,controller,vibration,t_s,travel_m,lateral_m,heading_deg,estimate_deg,command_deg_s,turning\n";
  int failures = 0;
  for (const auto& s : setups) {
    avoidance::RunConfig rc = base;
    rc.source = s.source;
    rc.speed_m_s = s.speed;
    rc.sim.vibration.enabled = s.vibration;
    rc.controller = std::find_if(flcs.begin(), flcs.end(), [&](const auto& f) { return f.first == s.controller; })->second;
    const auto results = bench::run_seeded<avoidance::RunResult>(
        runs, jobs, seed, "aerie-bench-avoidance", [&](uint64_t run_seed) { return avoidance::fly(rc, run_seed); }, failures);
    std::vector<avoidance::RunResult> flown;
    const char* src = avoidance::source_name(s.source);
    for (size_t i = 0; i < results.size(); ++i) {
      const auto& r = results[i];
      if (r.sim_s <= 0) continue;  // the run failed (said above)
      flown.push_back(r);
      const uint64_t run_seed = seed + i;
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
    }
    csv.flush();
    traj.flush();
    if (!flown.empty()) std::printf("%s\n", summary(s, flown).c_str());
    std::fflush(stdout);
  }
  return bench::finish("aerie-bench-avoidance", "bench/avoidance/plot_avoidance.py", out_dir, plots, failures);
}
