#include "ground/ceopt/landing_tuning.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "common/sim/vehicle/scenario_config.hpp"
#include "common/util/time.hpp"
#include "ground/ceopt/pipeline.hpp"
#include "ground/ceopt/report.hpp"
#include "ground/ceopt/thread_pool.hpp"
#include "loop/landing.hpp"

namespace aerie::ceopt {
namespace {

std::string read_text(const std::string& path, const std::string& what) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error("cannot read the " + what + " '" + path + "'");
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

SeedRange seeds_from(const util::Config& cfg, const std::string& key, SeedRange fallback, int min_count) {
  const auto s = cfg.section(key);
  sim::require_known_keys(s, {"first", "count"});
  fallback.first = s.get<uint64_t>("first", fallback.first);
  fallback.count = s.get("count", fallback.count);
  if (fallback.count < min_count)
    throw std::runtime_error(cfg.origin() + ": " + key + ".count must be >= " + std::to_string(min_count));
  return fallback;
}

// Four significant digits, as pilot.yaml holds them: what is flown is what the file says.
std::string four_digits(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", v);
  return text;
}

double mean_of(const std::vector<LandingRun>& runs, double LandingRun::*field, bool successes_only) {
  double sum = 0;
  int n = 0;
  for (const auto& r : runs)
    if (!successes_only || r.success) {
      sum += r.*field;
      ++n;
    }
  return n ? sum / n : std::nan("");
}

// Flies seed by seed on the pool (one landing per task).
std::vector<LandingRun> fly_on(const LandingTuning& problem, const std::vector<double>& x, const SeedRange& seeds,
                               ThreadPool& pool) {
  std::vector<LandingRun> runs(static_cast<size_t>(seeds.count));
  pool.parallel_for(runs.size(), [&](size_t i) {
    runs[i] = problem.fly(x, {seeds.first + i, 1}).front();
  });
  return runs;
}

}  // namespace

namespace {

// tune_landing with every landing flown through `flier`: the same steps in the same order, each
// CE iteration's candidates as one call.
LandingTuningResult tune_landing_through(const LandingTuning& problem, const IterationCallback& on_iteration,
                                         const CandidateCallback& on_candidate, const LandingFlier& flier) {
  const LandingTuningConfig& cfg = problem.config();
  LandingTuningResult res;
  const util::Stopwatch watch;
  const double cpu0 = process_cpu_seconds();
  for (const auto& p : cfg.parameters) res.initial.push_back(p.mean);
  res.initial_training = flier({{res.initial, cfg.training}}).at(0);
  auto batch_cost = [&](const std::vector<std::vector<double>>& xs) {
    std::vector<LandingJob> jobs;
    for (const auto& x : xs) jobs.push_back({x, cfg.training});
    const auto runs = flier(jobs);
    std::vector<double> costs;
    for (size_t i = 0; i < xs.size(); ++i) {
      costs.push_back(mean_cost(runs.at(i), cfg));
      if (on_candidate) on_candidate(xs[i], runs[i], costs.back());
    }
    return costs;
  };
  ThreadPool unused(1);
  res.ce = cross_entropy(cfg.parameters, cfg.ce, {}, unused, {}, on_iteration, batch_cost);
  if (!res.ce.best.empty()) {
    res.tuned_pilot_yaml = pilot_yaml_with(problem.base_pilot_yaml(), problem.names(), res.ce.best);
    if (res.ce.stop_reason != "cancelled" && cfg.validation.count > 0) {
      const auto v = flier({{res.initial, cfg.validation}, {res.ce.best, cfg.validation}});
      res.initial_validation = v.at(0);
      res.tuned_validation = v.at(1);
    }
  }
  res.seconds = watch.ms() / 1000.0;
  res.cpu_seconds = process_cpu_seconds() - cpu0;
  return res;
}

}  // namespace

LandingTuningConfig default_landing_tuning_config() {
  LandingTuningConfig c;
  c.ce.samples = 10;
  c.ce.elite = 3;
  c.ce.max_iterations = 5;
  c.ce.alpha = 0.7;
  c.ce.beta = 0.8;
  // The fuzzy horizontal loop's scaling factors (forward and left alike), from config/pilot.yaml's.
  c.parameters = {{"horizontal.kp", 2.0, 0.8, 0.5, 6.0},
                  {"horizontal.kd", 0.3, 0.15, 0.02, 1.2},
                  {"horizontal.ki", 0.5, 0.4, 0.02, 2.0},
                  {"horizontal.ku", 0.8, 0.3, 0.2, 1.6}};
  return c;
}

LandingTuningConfig landing_tuning_config_from(const util::Config& cfg) {
  LandingTuningConfig c = default_landing_tuning_config();
  c.origin = cfg.origin();
  sim::require_known_keys(cfg, {"sim_config", "track_config", "pilot_config", "tracker", "wind_m_s", "vibration", "training",
                                "validation", "cost", "threads", "ce", "parameters"});
  c.sim_config = cfg.get("sim_config", c.sim_config);
  c.track_config = cfg.get("track_config", c.track_config);
  c.pilot_config = cfg.get("pilot_config", c.pilot_config);
  c.tracker = cfg.get("tracker", c.tracker);
  c.wind_m_s = cfg.get_in("wind_m_s", c.wind_m_s, 0.0, 20.0);
  c.vibration = cfg.get("vibration", c.vibration);
  c.training = seeds_from(cfg, "training", c.training, 1);
  c.validation = seeds_from(cfg, "validation", c.validation, 0);
  const auto cost = cfg.section("cost");
  sim::require_known_keys(cost, {"failure_m", "time_weight_per_s"});
  c.failure_cost_m = cost.get_in("failure_m", c.failure_cost_m, 0.0, 1e6);
  c.time_weight_per_s = cost.get_in("time_weight_per_s", c.time_weight_per_s, 0.0, 1e3);
  c.threads = cfg.get_in("threads", c.threads, 0, 256);
  c.ce = ce_options_from(cfg.section("ce"), c.ce);
  c.parameters = ce_parameters_from(cfg, "parameters", c.parameters);
  if (c.parameters.empty()) throw std::runtime_error(cfg.origin() + ": 'parameters' is empty: nothing to tune");
  return c;
}

std::string pilot_yaml_with(const std::string& base_yaml, const std::vector<std::string>& names,
                            const std::vector<double>& values) {
  if (names.size() != values.size()) throw std::invalid_argument("pilot_yaml_with: one value per parameter");
  static const std::vector<std::string> kAxes{"forward", "left", "up", "yaw", "horizontal"};
  static const std::vector<std::string> kGains{"kp", "kd", "ki", "ku", "integral_limit", "output_limit"};
  YAML::Node root = YAML::Load(base_yaml);
  const std::string controller = root["controller"] ? root["controller"].as<std::string>() : "fuzzy";
  for (size_t i = 0; i < names.size(); ++i) {
    const auto dot = names[i].find('.');
    const std::string axis = names[i].substr(0, dot), gain = dot == std::string::npos ? "" : names[i].substr(dot + 1);
    if (std::find(kAxes.begin(), kAxes.end(), axis) == kAxes.end() || std::find(kGains.begin(), kGains.end(), gain) == kGains.end())
      throw std::runtime_error("unknown landing parameter '" + names[i] +
                               "': expected <axis>.<gain>, axis forward|left|up|yaw|horizontal, gain "
                               "kp|kd|ki|ku|integral_limit|output_limit");
    for (const std::string& a : axis == "horizontal" ? std::vector<std::string>{"forward", "left"} : std::vector<std::string>{axis})
      root["gains"][controller][a][gain] = four_digits(values[i]);
  }
  YAML::Emitter out;
  out << root;
  std::ostringstream what;
  what << "the pilot configuration with";
  for (size_t i = 0; i < names.size(); ++i) what << " " << names[i] << "=" << four_digits(values[i]);
  try {
    loop::landing::LandingSpec check;
    check.pilot = what.str();
    check.pilot_yaml = out.c_str();
    loop::landing::load_landing_pilot(check);
  } catch (const std::exception& e) {
    throw std::runtime_error(what.str() + " is invalid: " + e.what());
  }
  return out.c_str();
}

double run_cost(const LandingRun& r, const LandingTuningConfig& cfg) {
  return (r.success ? r.touchdown_error_m : cfg.failure_cost_m) + (r.success ? cfg.time_weight_per_s * r.time_s : 0.0);
}

double mean_cost(const std::vector<LandingRun>& runs, const LandingTuningConfig& cfg) {
  if (runs.empty()) return std::nan("");
  double sum = 0;
  for (const auto& r : runs) sum += run_cost(r, cfg);
  return sum / static_cast<double>(runs.size());
}

LandingTuning::LandingTuning(LandingTuningConfig cfg) : cfg_(std::move(cfg)) {
  base_pilot_yaml_ = read_text(cfg_.pilot_config, "pilot configuration");
  spec_.sim = cfg_.sim_config;
  spec_.track = cfg_.track_config;
  spec_.pilot = cfg_.pilot_config;
  spec_.tracker = cfg_.tracker;
  spec_.wind_m_s = cfg_.wind_m_s;
  spec_.vibration = cfg_.vibration;
  loop::landing::load_landing_run(spec_, cfg_.training.first);  // refuses a bad file now, not in a worker
  // Every parameter's bounds must give a valid pilot (unknown names are refused here too).
  std::vector<double> lo, hi;
  for (const auto& p : cfg_.parameters) {
    lo.push_back(p.lower);
    hi.push_back(p.upper);
  }
  pilot_yaml_with(base_pilot_yaml_, names(), lo);
  pilot_yaml_with(base_pilot_yaml_, names(), hi);
}

std::vector<std::string> LandingTuning::names() const {
  std::vector<std::string> n;
  for (const auto& p : cfg_.parameters) n.push_back(p.name);
  return n;
}

std::vector<LandingRun> LandingTuning::fly(const std::vector<double>& x, const SeedRange& seeds) const {
  loop::landing::LandingSpec spec = spec_;
  spec.pilot_yaml = pilot_yaml_with(base_pilot_yaml_, names(), x);
  std::vector<LandingRun> runs;
  for (int i = 0; i < seeds.count; ++i) {
    const uint64_t seed = seeds.first + static_cast<uint64_t>(i);
    const loop::landing::RunResult r = loop::landing::fly(loop::landing::load_landing_run(spec, seed));
    LandingRun l;
    l.seed = seed;
    l.success = r.score.success;
    l.collided = r.outcome.collided;
    l.touchdown_error_m = r.score.touchdown_error_m;
    l.time_s = r.score.time_s;
    l.sim_s = r.sim_s;
    l.wall_s = r.wall_s;
    l.losses = r.losses;
    runs.push_back(l);
  }
  return runs;
}

LandingTuningResult tune_landing(const LandingTuning& problem, ThreadPool& pool, const IterationCallback& on_iteration,
                                 const CandidateCallback& on_candidate, const LandingFlier& flier) {
  if (flier) return tune_landing_through(problem, on_iteration, on_candidate, flier);
  const LandingTuningConfig& cfg = problem.config();
  LandingTuningResult res;
  const util::Stopwatch watch;
  const double cpu0 = process_cpu_seconds();
  for (const auto& p : cfg.parameters) res.initial.push_back(p.mean);
  res.initial_training = fly_on(problem, res.initial, cfg.training, pool);
  std::mutex report_mutex;
  auto cost = [&](const std::vector<double>& x) {
    const std::vector<LandingRun> runs = problem.fly(x, cfg.training);
    const double c = mean_cost(runs, cfg);
    if (on_candidate) {
      std::lock_guard lk(report_mutex);
      on_candidate(x, runs, c);
    }
    return c;
  };
  res.ce = cross_entropy(cfg.parameters, cfg.ce, cost, pool, {}, on_iteration);
  if (!res.ce.best.empty()) {
    res.tuned_pilot_yaml = pilot_yaml_with(problem.base_pilot_yaml(), problem.names(), res.ce.best);
    if (res.ce.stop_reason != "cancelled" && cfg.validation.count > 0) {
      res.initial_validation = fly_on(problem, res.initial, cfg.validation, pool);
      res.tuned_validation = fly_on(problem, res.ce.best, cfg.validation, pool);
    }
  }
  res.seconds = watch.ms() / 1000.0;
  res.cpu_seconds = process_cpu_seconds() - cpu0;
  return res;
}

namespace {

std::string summary_row(const std::string& name, const std::vector<LandingRun>& runs, const LandingTuningConfig& cfg) {
  if (runs.empty()) return "| " + name + " | not flown | | | | |\n";
  int ok = 0;
  std::vector<double> err;
  for (const auto& r : runs) {
    ok += r.success;
    if (r.success) err.push_back(r.touchdown_error_m);
  }
  std::sort(err.begin(), err.end());
  const double p95 = err.empty() ? std::nan("")
                                 : err[std::min(err.size() - 1, static_cast<size_t>(std::ceil(0.95 * static_cast<double>(err.size()))) - 1)];
  char line[256];
  std::snprintf(line, sizeof line, "| %s | %d/%zu | %.1f / %.1f | %.1f | %.4f |\n", name.c_str(), ok, runs.size(),
                100 * mean_of(runs, &LandingRun::touchdown_error_m, true), 100 * p95,
                mean_of(runs, &LandingRun::time_s, true), mean_cost(runs, cfg));
  return line;
}

}  // namespace

std::vector<std::string> write_landing_report(const std::string& out_dir, const LandingTuning& problem,
                                              const LandingTuningResult& res, const std::string& command_line) {
  namespace fs = std::filesystem;
  const LandingTuningConfig& cfg = problem.config();
  const auto names = problem.names();
  fs::create_directories(out_dir);
  std::vector<std::string> files;
  auto open = [&](const std::string& name) {
    files.push_back((fs::path(out_dir) / name).string());
    std::ofstream f(files.back());
    if (!f) throw std::runtime_error("cannot write '" + files.back() + "'");
    return f;
  };
  if (!res.tuned_pilot_yaml.empty()) {
    auto f = open("pilot.yaml");
    f << "# aerie-ceopt landing: " << cfg.pilot_config << " with the gains tuned in the closed loop (report.md)\n"
      << res.tuned_pilot_yaml << "\n";
  }
  {
    auto f = open("ce_history.csv");
    f << "iteration,evaluations,best_cost,iteration_best_cost,eta";
    for (const auto& n : names) f << ',' << n << "_mean," << n << "_sigma";
    f << '\n';
    for (const auto& it : res.ce.history) {
      f << it.iteration << ',' << it.evaluations << ',' << it.best_cost << ',' << it.iteration_best_cost << ',' << it.eta;
      for (size_t j = 0; j < names.size(); ++j) f << ',' << it.mean[j] << ',' << it.sigma[j];
      f << '\n';
    }
  }
  {
    auto f = open("validation.csv");
    f << "gains,set,seed,success,collision,touchdown_error_m,time_s,losses,cost,sim_s,wall_s\n";
    auto rows = [&](const char* gains, const char* set, const std::vector<LandingRun>& runs) {
      for (const auto& r : runs)
        f << gains << ',' << set << ',' << r.seed << ',' << r.success << ',' << r.collided << ',' << r.touchdown_error_m << ','
          << r.time_s << ',' << r.losses << ',' << run_cost(r, cfg) << ',' << r.sim_s << ',' << r.wall_s << '\n';
    };
    rows("initial", "training", res.initial_training);
    rows("initial", "validation", res.initial_validation);
    rows("tuned", "validation", res.tuned_validation);
  }
  {
    auto f = open("report.md");
    f << "# Landing controller tuned by cross-entropy in the closed loop\n\n"
      << "Command: `" << command_line << "`; configuration " << cfg.origin << ".\n\n"
      << "Closed loop: " << cfg.sim_config << " at " << cfg.wind_m_s << " m/s wind, vibration "
      << (cfg.vibration ? "on" : "off") << ", tracker " << cfg.tracker << ", pilot " << cfg.pilot_config << ". Cost per run: "
      << "touchdown error (m) if successful, else " << cfg.failure_cost_m << ", plus " << cfg.time_weight_per_s
      << " per second to land. CE: N = " << cfg.ce.samples << ", N_elite = " << cfg.ce.elite << ", "
      << res.ce.history.size() << " iterations (stopped on: " << res.ce.stop_reason << "), " << res.ce.evaluations
      << " candidates, each on training seeds " << cfg.training.first << "-" << cfg.training.first + cfg.training.count - 1
      << " (the same for all).\n\n"
      << "| parameter | initial | tuned | final mean ± sigma |\n|---|---|---|---|\n";
    for (size_t j = 0; j < names.size(); ++j) {
      f << "| " << names[j] << " | " << res.initial[j] << " | ";
      if (res.ce.best.empty())
        f << "- | - |\n";
      else
        f << four_digits(res.ce.best[j]) << " | " << four_digits(res.ce.final_mean[j]) << " ± " << four_digits(res.ce.final_sigma[j])
          << " |\n";
    }
    f << "\n| gains, seeds | success | touchdown error mean / p95 (cm) | time (s) | cost |\n|---|---|---|---|---|\n"
      << summary_row("initial, training", res.initial_training, cfg);
    char best[128];
    std::snprintf(best, sizeof best, "| tuned, training | | | | %.4f (the best candidate's) |\n", res.ce.best_cost);
    f << best;
    if (cfg.validation.count > 0) {
      const std::string v = ", validation " + std::to_string(cfg.validation.first) + "-" +
                            std::to_string(cfg.validation.first + cfg.validation.count - 1);
      f << summary_row("initial" + v, res.initial_validation, cfg) << summary_row("tuned" + v, res.tuned_validation, cfg);
    }
    char cost[256];
    std::snprintf(cost, sizeof cost, "\nWall time %.0f s, process CPU %.0f s (every thread), load %s.\n", res.seconds,
                  res.cpu_seconds, read_loadavg().c_str());
    f << cost;
  }
  return files;
}

}  // namespace aerie::ceopt
