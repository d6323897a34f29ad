#include "ground/ceopt/report.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "common/flc/flc_io.hpp"

namespace aerie::ceopt {
namespace fs = std::filesystem;
namespace {

// Thesis 5.1.6, real flights: average steady-state RMSE (deg) per speed.
struct ThesisRmse {
  double speed, sf, sfmf;
};
constexpr ThesisRmse kThesis[] = {{0.4, 4.812, 2.583}, {0.6, 6.060, 3.218}, {0.8, 7.427, 4.069}};

std::string f(double v, int digits = 3) {
  if (std::isnan(v)) return "nan";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", digits, v);
  return buf;
}
std::string g(double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.10g", v);
  return buf;
}

class Writer {
 public:
  Writer(const fs::path& path, std::vector<std::string>& written) : out_(path) {
    if (!out_) throw std::runtime_error(path.string() + ": cannot write");
    written.push_back(path.string());
  }
  template <typename T>
  Writer& operator<<(const T& v) {
    out_ << v;
    return *this;
  }

 private:
  std::ofstream out_;
};

void write_progress(const fs::path& path, const StageResult& st, std::vector<std::string>& written) {
  Writer w(path, written);
  w << "iteration,evaluations,eta,best_cost,iteration_best_cost,gamma";
  for (const auto& n : st.names) w << ",mean_" << n << ",sigma_" << n;
  w << "\n";
  for (const auto& it : st.ce.history) {
    w << it.iteration << "," << it.evaluations << "," << g(it.eta) << "," << g(it.best_cost) << "," << g(it.iteration_best_cost)
      << "," << g(it.elite_costs.back());
    for (size_t j = 0; j < st.names.size(); ++j) w << "," << g(it.mean[j]) << "," << g(it.sigma[j]);
    w << "\n";
  }
}

void write_mfs(Writer& w, const std::string& name, const flc::FlcSpec& s) {
  auto var = [&](const flc::Variable& v, bool output) {
    const int n = v.size();
    for (int k = 0; k < n; ++k) {
      const auto& c = v.positions;
      const double a = k > 0 ? c[k - 1] : (n > 1 ? c[0] - (c[1] - c[0]) : c[0] - 1);
      const double e = k < n - 1 ? c[k + 1] : (n > 1 ? c[n - 1] + (c[n - 1] - c[n - 2]) : c[0] + 1);
      w << name << "," << v.name << "," << v.sets[k] << "," << g(a) << "," << g(c[k]) << "," << g(e) << "," << g(v.min) << ","
        << g(v.max) << "," << (output ? 1 : 0) << "\n";
    }
  };
  for (const auto& v : s.inputs) var(v, false);
  var(s.output, true);
}

}  // namespace

std::string read_loadavg() {
  std::ifstream f("/proc/loadavg");
  std::string line;
  std::getline(f, line);
  return line;
}

std::vector<std::string> write_report(const std::string& dir_name, const ReportInputs& in) {
  const fs::path dir(dir_name);
  fs::create_directories(dir);
  std::vector<std::string> written;
  const TuningResult& t = *in.tuning;
  const CeoptConfig& cfg = *in.config;

  for (const auto& [name, spec] : in.controllers) {
    flc::save_yaml(spec, (dir / (name + ".yaml")).string());
    flc::save_fll(spec, (dir / (name + ".fll")).string());
    written.push_back((dir / (name + ".yaml")).string());
    written.push_back((dir / (name + ".fll")).string());
  }
  for (const StageResult* st : {&t.stage1, &t.stage2})
    if (!st->ce.history.empty()) write_progress(dir / ("progress_stage" + std::to_string(st->stage) + ".csv"), *st, written);
  {
    Writer w(dir / "mfs.csv", written);
    w << "controller,variable,set,a,b,c,min,max,output\n";
    for (const auto& [name, spec] : in.controllers) write_mfs(w, name, spec);
  }
  {
    Writer w(dir / "experiment_runs.csv", written);
    w << "controller,speed,run,seed,steady_rmse_deg,min_wall_distance_m,entered_dangerous,collided,completed,itse,settle_time_s,"
         "activation_time_s,duration_s\n";
    for (const auto& r : in.runs) {
      const auto& a = r.result;
      w << r.controller << "," << r.speed << "," << r.run << "," << r.seed << "," << g(a.steady_rmse_deg) << ","
        << g(a.min_wall_distance_m) << "," << a.entered_dangerous << "," << a.collided << "," << a.completed << "," << g(a.itse)
        << "," << g(a.settle_time_s) << "," << g(a.activation_time_s) << "," << g(a.duration_s) << "\n";
    }
  }
  {
    Writer w(dir / "trajectories.csv", written);
    w << "controller,speed,t,x,y,heading_deg,measured_heading_deg,reference_deg,command_deg_s,active\n";
    for (const auto& r : in.runs)
      for (const auto& s : r.result.trajectory)
        w << r.controller << "," << r.speed << "," << g(s.t) << "," << g(s.x) << "," << g(s.y) << "," << g(s.heading_deg) << ","
          << g(s.measured_heading_deg) << "," << g(s.reference_deg) << "," << g(s.command_deg_s) << "," << s.active << "\n";
  }
  const auto summary = summarise(in.runs);
  {
    Writer w(dir / "experiment_summary.csv", written);
    w << "controller,speed,runs,settled,rmse_mean_deg,rmse_std_deg,min_wall_distance_m,entered_dangerous,collided,completed,"
         "itse_mean,settle_time_mean_s\n";
    for (const auto& s : summary)
      w << s.controller << "," << s.speed << "," << s.runs << "," << s.settled << "," << g(s.rmse_mean) << "," << g(s.rmse_std)
        << "," << g(s.min_wall_distance) << "," << s.entered_dangerous << "," << s.collided << "," << s.completed << ","
        << g(s.itse_mean) << "," << g(s.settle_time_mean) << "\n";
  }
  {
    Writer w(dir / "summary.json", written);
    w << "{\n  \"command\": \"" << in.command_line << "\",\n  \"threads\": " << in.threads << ",\n  \"loadavg_before\": \""
      << in.load_before << "\",\n  \"loadavg_after\": \"" << in.load_after << "\",\n  \"samples\": " << cfg.ce.samples
      << ",\n  \"elite\": " << cfg.ce.elite << ",\n  \"runs_per_evaluation\": "
      << cfg.training.speeds.size() * static_cast<size_t>(cfg.training.runs_per_speed) << ",\n  \"scene\": {\"normal_area_m\": "
      << g(cfg.training.scenario.scene.normal_area_m) << ", \"safe_area_m\": " << g(cfg.training.scenario.scene.safe_area_m)
      << ", \"wall_m\": " << g(cfg.training.scenario.scene.wall_y_m) << ", \"lateral_limit_m\": "
      << g(cfg.training.scenario.scene.lateral_limit_m) << "},\n  \"stages\": [";
    bool first = true;
    for (const StageResult* st : {&t.stage1, &t.stage2}) {
      if (st->ce.history.empty()) continue;
      w << (first ? "" : ",") << "\n    {\"stage\": " << st->stage << ", \"seconds\": " << g(st->seconds)
        << ", \"cpu_seconds\": " << g(st->cpu_seconds)
        << ", \"iterations\": " << st->ce.history.size() << ", \"evaluations\": " << st->ce.evaluations
        << ", \"best_cost\": " << g(st->ce.best_cost) << ", \"winner_iteration\": " << st->ce.best_iteration
        << ", \"stop_reason\": \"" << st->ce.stop_reason << "\", \"best\": {";
      for (size_t j = 0; j < st->names.size(); ++j) w << (j ? ", " : "") << "\"" << st->names[j] << "\": " << g(st->ce.best[j]);
      w << "}}";
      first = false;
    }
    w << "\n  ],\n  \"prune\": {\"rules_before\": " << t.prune_report.rules_before << ", \"rules_after\": " << t.prune_report.rules_after
      << ", \"sets_before\": " << t.prune_report.sets_before << ", \"sets_after\": " << t.prune_report.sets_after
      << ", \"max_cost_increase\": " << g(cfg.prune_max_cost_increase) << ", \"removed\": [";
    for (size_t k = 0; k < t.prune_report.removed_sets.size(); ++k)
      w << (k ? ", " : "") << "\"" << t.prune_report.removed_sets[k] << "\"";
    w << "]},\n  \"experiment\": [";
    for (size_t k = 0; k < summary.size(); ++k) {
      const auto& s = summary[k];
      w << (k ? "," : "") << "\n    {\"controller\": \"" << s.controller << "\", \"speed\": " << s.speed << ", \"runs\": " << s.runs
        << ", \"settled\": " << s.settled << ", \"rmse_mean_deg\": " << (std::isnan(s.rmse_mean) ? "null" : g(s.rmse_mean))
        << ", \"rmse_std_deg\": " << (std::isnan(s.rmse_std) ? "null" : g(s.rmse_std))
        << ", \"min_wall_distance_m\": " << g(s.min_wall_distance) << ", \"entered_dangerous\": " << s.entered_dangerous
        << ", \"collided\": " << s.collided << "}";
    }
    w << "\n  ]\n}\n";
  }
  {
    Writer w(dir / "report.md", written);
    w << "# Cross-entropy optimisation of the heading FLC\n\n"
      << "Command: `" << in.command_line << "`  \nThreads: " << in.threads << "; load average before/after: `" << in.load_before
      << "` / `" << in.load_after << "`\n\n"
      << "CE: N = " << cfg.ce.samples << " candidates per iteration, N_elite = " << cfg.ce.elite << ", alpha = " << cfg.ce.alpha
      << ", beta = " << cfg.ce.beta << ", q = " << cfg.ce.q << "; each candidate flies "
      << cfg.training.speeds.size() * static_cast<size_t>(cfg.training.runs_per_speed)
      << " training runs (cost: mean ITSE + penalties).\n\n"
      << "| stage | parameters | iterations | evaluations | wall time (s) | CPU time (s) | best cost | winner iteration | best values |\n"
      << "|---|---|---|---|---|---|---|---|---|\n";
    for (const StageResult* st : {&t.stage1, &t.stage2}) {
      if (st->ce.history.empty()) continue;
      w << "| " << st->stage << " | " << st->names.size() << " | " << st->ce.history.size() << " | " << st->ce.evaluations << " | "
        << f(st->seconds, 1) << " | " << f(st->cpu_seconds, 1) << " | " << f(st->ce.best_cost, 1) << " | " << st->ce.best_iteration << " | ";
      for (size_t j = 0; j < st->names.size(); ++j) w << (j ? ", " : "") << st->names[j] << " = " << f(st->ce.best[j], 4);
      w << " |\n";
    }
    w << "\nPruning (overlap fraction " << cfg.prune.overlap_fraction << "): rules " << t.prune_report.rules_before << " -> "
      << t.prune_report.rules_after << ", sets " << t.prune_report.sets_before << " -> " << t.prune_report.sets_after << "; removed: ";
    for (size_t k = 0; k < t.prune_report.removed_sets.size(); ++k) w << (k ? ", " : "") << "`" << t.prune_report.removed_sets[k] << "`";
    w << (t.prune_report.removed_sets.empty() ? "none" : "") << ".\n\n";
    if (!t.prune_steps.empty()) {
      w << "| merge tried | training cost before | after | kept (limit +" << f(100 * cfg.prune_max_cost_increase, 0)
        << " % of the unpruned cost) |\n|---|---|---|---|\n";
      for (const auto& st : t.prune_steps) {
        w << "| ";
        for (size_t k = 0; k < st.merges.size(); ++k) w << (k ? ", " : "") << "`" << st.merges[k] << "`";
        w << " | " << f(st.cost_before, 1) << " | " << f(st.cost_after, 1) << " | " << (st.accepted ? "yes" : "no") << " |\n";
      }
      w << "\n";
    }
    w << "## Avoidance experiment (" << cfg.evaluation.runs_per_speed << " runs per case, sensor noise "
      << cfg.training.scenario.sensor.noise_std_deg << " deg, latency " << cfg.training.scenario.sensor.delay_s
      << " s, safe avoiding area " << cfg.training.scenario.scene.safe_area_m << " m)\n\n"
      << "| controller | speed (m/s) | steady-state RMSE (deg) | thesis (real flights) | min. wall distance (m) | runs in "
         "dangerous area | collisions | settled |\n|---|---|---|---|---|---|---|---|\n";
    for (const auto& s : summary) {
      std::string thesis = "-";
      for (const auto& th : kThesis)
        if (std::abs(th.speed - s.speed) < 1e-9) {
          if (s.controller == "sf") thesis = f(th.sf, 2);
          if (s.controller == "sfmf") thesis = f(th.sfmf, 2);
        }
      w << "| " << s.controller << " | " << f(s.speed, 1) << " | " << rmse_text(s) << " | "
        << thesis << " | " << f(s.min_wall_distance, 2) << " | " << s.entered_dangerous << "/" << s.runs << " | " << s.collided
        << " | " << s.settled << "/" << s.runs << " |\n";
    }
    w << "\n![cost](cost.png)\n\n![pdf](pdf_stage1.png)\n\n![pdf](pdf_stage2.png)\n\n![mfs](mfs.png)\n\n"
      << "![trajectories](trajectories.png)\n\n![heading](heading.png)\n\n![rmse](rmse.png)\n";
  }
  return written;
}

bool draw_plots(const std::string& dir, const std::string& script, std::string* error) {
  if (!fs::exists(script)) {
    if (error) *error = "plot script not found: " + script;
    return false;
  }
  const std::string cmd = "/usr/bin/python3 '" + script + "' '" + dir + "' 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) {
    if (error) *error = "cannot run " + cmd;
    return false;
  }
  std::string out;
  char buf[512];
  while (fgets(buf, sizeof(buf), p)) out += buf;
  const int rc = pclose(p);
  if (rc != 0 && error) *error = "plot script failed (" + std::to_string(rc) + "): " + out;
  return rc == 0;
}

std::string rmse_text(const ExperimentSummary& s) {
  return s.settled > 0 ? f(s.rmse_mean, 2) + " ± " + f(s.rmse_std, 2) : "never settled";
}

}  // namespace aerie::ceopt
