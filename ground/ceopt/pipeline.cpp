#include "ground/ceopt/pipeline.hpp"

#include <sys/resource.h>

#include <cmath>
#include <map>
#include <stdexcept>

#include "common/flc/flc_io.hpp"
#include "common/sim/vehicle/scenario_config.hpp"
#include "common/util/time.hpp"
#include "ground/ceopt/thread_pool.hpp"

namespace aerie::ceopt {

double process_cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

CeOptions ce_options_from(const util::Config& ce, CeOptions options) {
  sim::require_known_keys(ce, {"samples", "elite", "iterations", "alpha", "beta", "q", "sigma_stop", "seed"});
  options.samples = ce.get("samples", options.samples);
  options.elite = ce.get("elite", options.elite);
  options.max_iterations = ce.get("iterations", options.max_iterations);
  options.alpha = ce.get("alpha", options.alpha);
  options.beta = ce.get("beta", options.beta);
  options.q = ce.get("q", options.q);
  options.sigma_stop = ce.get("sigma_stop", options.sigma_stop);
  options.seed = ce.get<uint64_t>("seed", options.seed);
  try {
    options.validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(ce.origin() + ": " + e.what());
  }
  return options;
}

std::vector<CeParameter> ce_parameters_from(const util::Config& cfg, const std::string& key, std::vector<CeParameter> fallback) {
  if (!cfg.has(key)) return fallback;
  const YAML::Node list = cfg.node()[key];
  if (!list.IsSequence()) throw std::runtime_error(cfg.origin() + ": '" + key + "' must be a list of {name, mean, sigma, lower, upper}");
  std::vector<CeParameter> out;
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string k = key + "[" + std::to_string(i) + "]";
    const util::Config p = util::Config::parse(YAML::Dump(list[i]), cfg.origin() + ":" + k);
    sim::require_known_keys(p, {"name", "mean", "sigma", "lower", "upper"});
    CeParameter c;
    c.name = p.require<std::string>("name");
    c.mean = p.require<double>("mean");
    c.sigma = p.require<double>("sigma");
    c.lower = p.require<double>("lower");
    c.upper = p.require<double>("upper");
    if (!(c.lower <= c.mean && c.mean <= c.upper && c.sigma > 0))
      throw std::runtime_error(p.origin() + ": needs lower <= mean <= upper and sigma > 0");
    out.push_back(c);
  }
  return out;
}

CeoptConfig default_ceopt_config() {
  CeoptConfig c;
  // Stage 1 from the hand-tuned factors (all 1, thesis 5.1.3).
  // Initial sigmas of about half the box, so that the first iterations sample all of it.
  c.stage1 = {{"Kp", 1.0, 5.0, 0.05, 10.0}, {"Kd", 1.0, 1.0, 0.001, 2.0}, {"Ki", 1.0, 3.0, -3.0, 3.0}};
  // Stage 2 from the initial (evenly spaced) positions of the sets the thesis optimises.
  c.stage2 = {{"error.Left", -45.0, 45.0, -90.0, 0.0},        {"derivative.Negative", -10.0, 10.0, -20.0, 0.0},
              {"integral.Negative", -5.0, 5.0, -10.0, 0.0},    {"yaw_rate.BigLeft", -67.5, 45.0, -90.0, 0.0},
              {"yaw_rate.Left", -45.0, 45.0, -90.0, 0.0},      {"yaw_rate.LittleLeft", -22.5, 45.0, -90.0, 0.0}};
  return c;
}

CeoptConfig ceopt_config_from(const util::Config& cfg) {
  CeoptConfig c = default_ceopt_config();
  c.origin = cfg.origin();
  sim::require_known_keys(cfg, {"controller", "threads", "ce", "training", "scenario", "limits", "stage1", "stage2", "prune",
                                "evaluation"});
  c.controller = cfg.get<std::string>("controller", "");
  c.threads = cfg.get("threads", 0);

  c.ce = ce_options_from(cfg.section("ce"), c.ce);

  c.training.scenario = sim::avoidance_config_from(cfg.section("scenario"));
  const auto tr = cfg.section("training");
  sim::require_known_keys(tr, {"speeds", "runs_per_speed", "seed", "penalty_dangerous", "penalty_incomplete"});
  c.training.speeds = tr.get("speeds", c.training.speeds);
  c.training.runs_per_speed = tr.get("runs_per_speed", c.training.runs_per_speed);
  c.training.seed = tr.get<uint64_t>("seed", c.training.seed);
  c.training.penalty_dangerous = tr.get("penalty_dangerous", c.training.penalty_dangerous);
  c.training.penalty_incomplete = tr.get("penalty_incomplete", c.training.penalty_incomplete);

  const auto lim = cfg.section("limits");
  sim::require_known_keys(lim, {"max_yaw_rate_deg_s", "max_yaw_accel_deg_s2"});
  c.training.limits.max_yaw_rate_deg_s = lim.get("max_yaw_rate_deg_s", c.training.limits.max_yaw_rate_deg_s);
  c.training.limits.max_yaw_accel_deg_s2 = lim.get("max_yaw_accel_deg_s2", c.training.limits.max_yaw_accel_deg_s2);

  c.stage1 = ce_parameters_from(cfg, "stage1", c.stage1);
  c.stage2 = ce_parameters_from(cfg, "stage2", c.stage2);
  const auto pr = cfg.section("prune");
  sim::require_known_keys(pr, {"overlap_fraction", "max_cost_increase"});
  c.prune.overlap_fraction = pr.get("overlap_fraction", c.prune.overlap_fraction);
  c.prune_max_cost_increase = pr.get("max_cost_increase", c.prune_max_cost_increase);

  const auto ev = cfg.section("evaluation");
  sim::require_known_keys(ev, {"speeds", "runs_per_speed", "seed"});
  c.evaluation.speeds = ev.get("speeds", c.evaluation.speeds);
  c.evaluation.runs_per_speed = ev.get("runs_per_speed", c.evaluation.runs_per_speed);
  c.evaluation.seed = ev.get<uint64_t>("seed", c.evaluation.seed);
  if (c.training.speeds.empty() || c.training.runs_per_speed < 1 || c.evaluation.speeds.empty() || c.evaluation.runs_per_speed < 1)
    throw std::runtime_error(cfg.origin() + ": training and evaluation need speeds and runs_per_speed >= 1");
  return c;
}

StageResult run_stage(int stage, const flc::FlcSpec& base, const std::vector<CeParameter>& parameters, const CeoptConfig& cfg,
                      ThreadPool& pool, const StageCallback& cb) {
  StageResult r;
  r.stage = stage;
  for (const auto& p : parameters) r.names.push_back(p.name);
  const FlcTuningProblem problem(base, r.names, cfg.training);
  CeOptions opt = cfg.ce;
  opt.seed = cfg.ce.seed + static_cast<uint64_t>(stage - 1);
  const util::Stopwatch watch;
  const double cpu0 = process_cpu_seconds();
  r.ce = cross_entropy(
      parameters, opt, [&](const std::vector<double>& x) { return problem.cost(x); }, pool,
      [&](std::vector<double>& x) { problem.repair(x); },
      [&](const CeIteration& it) { return cb ? cb(stage, r.names, it) : true; });
  r.seconds = watch.ms() / 1000.0;
  r.cpu_seconds = process_cpu_seconds() - cpu0;
  r.controller = problem.controller(r.ce.best);
  r.controller.id = stage == 1 ? "ce-sf" : "ce-sfmf";
  return r;
}

TuningResult run_tuning(const CeoptConfig& cfg, ThreadPool& pool, const StageCallback& cb) {
  TuningResult t;
  t.initial = cfg.controller.empty() ? flc::thesis_initial() : flc::load_controller(cfg.controller);
  t.stage1 = run_stage(1, t.initial, cfg.stage1, cfg, pool, cb);
  if (t.stage1.ce.stop_reason == "cancelled") return t;
  t.stage2 = run_stage(2, t.stage1.controller, cfg.stage2, cfg, pool, cb);
  t.pruned = prune_verified(t.stage2.controller, cfg, &t.prune_report, &t.prune_steps);
  return t;
}

flc::FlcSpec prune_verified(const flc::FlcSpec& spec, const CeoptConfig& cfg, flc::PruneReport* report,
                            std::vector<PruneStep>* steps) {
  const double base = controller_cost(flc::Flc(spec), cfg.training);
  flc::FlcSpec current = spec;
  flc::PruneReport total;
  for (const flc::Variable* v : {&spec.inputs[0], &spec.inputs[1], &spec.inputs[2], &spec.output}) {
    flc::PruneOptions opt = cfg.prune;
    opt.variables = {v->name};
    flc::PruneReport r;
    const flc::FlcSpec candidate = flc::prune(current, opt, &r);
    if (r.removed_sets.empty()) continue;
    PruneStep step{v->name, r.removed_sets, controller_cost(flc::Flc(current), cfg.training),
                   controller_cost(flc::Flc(candidate), cfg.training), false};
    step.accepted = cfg.prune_max_cost_increase < 0.0 || step.cost_after <= base * (1.0 + cfg.prune_max_cost_increase);
    if (step.accepted) {
      current = candidate;
      total.removed_sets.insert(total.removed_sets.end(), r.removed_sets.begin(), r.removed_sets.end());
    }
    if (steps) steps->push_back(step);
  }
  auto sets = [](const flc::FlcSpec& s) {
    return s.inputs[0].size() + s.inputs[1].size() + s.inputs[2].size() + s.output.size();
  };
  total.rules_before = static_cast<int>(spec.rules.size());
  total.rules_after = static_cast<int>(current.rules.size());
  total.sets_before = sets(spec);
  total.sets_after = sets(current);
  current.id = spec.id + "-pruned";
  if (report) *report = total;
  return current;
}

std::vector<ExperimentRun> run_experiment(const std::vector<std::pair<std::string, flc::FlcSpec>>& controllers,
                                          const CeoptConfig& cfg, ThreadPool& pool) {
  std::vector<ExperimentRun> runs;
  std::vector<flc::Flc> compiled;
  for (const auto& [name, spec] : controllers) {
    compiled.emplace_back(spec);
    for (size_t s = 0; s < cfg.evaluation.speeds.size(); ++s)
      for (int k = 0; k < cfg.evaluation.runs_per_speed; ++k) {
        ExperimentRun r;
        r.controller = name;
        r.speed = cfg.evaluation.speeds[s];
        r.run = k;
        r.seed = cfg.evaluation.seed + 1000 * s + static_cast<uint64_t>(k);
        runs.push_back(r);
      }
  }
  const size_t per_controller = cfg.evaluation.speeds.size() * static_cast<size_t>(cfg.evaluation.runs_per_speed);
  pool.parallel_for(runs.size(), [&](size_t i) {
    ExperimentRun& r = runs[i];
    r.result = fly(compiled[i / per_controller], cfg.training.scenario, r.speed, r.seed, cfg.training.limits, r.run == 0);
  });
  return runs;
}

std::vector<ExperimentSummary> summarise(const std::vector<ExperimentRun>& runs) {
  std::vector<ExperimentSummary> out;
  std::map<std::pair<std::string, double>, size_t> index;
  for (const auto& r : runs) {
    auto [it, fresh] = index.try_emplace({r.controller, r.speed}, out.size());
    if (fresh) {
      ExperimentSummary s;
      s.controller = r.controller;
      s.speed = r.speed;
      s.min_wall_distance = r.result.min_wall_distance_m;
      out.push_back(s);
    }
    ExperimentSummary& s = out[it->second];
    const auto& a = r.result;
    ++s.runs;
    s.min_wall_distance = std::min(s.min_wall_distance, a.min_wall_distance_m);
    s.entered_dangerous += a.entered_dangerous;
    s.collided += a.collided;
    s.completed += a.completed;
    s.itse_mean += a.itse;
    if (a.steady_rmse_deg >= 0.0) {
      ++s.settled;
      s.rmse_mean += a.steady_rmse_deg;
      s.rmse_std += a.steady_rmse_deg * a.steady_rmse_deg;
      s.settle_time_mean += a.settle_time_s;
    }
  }
  for (auto& s : out) {
    s.itse_mean /= s.runs;
    if (s.settled) {
      s.rmse_mean /= s.settled;
      s.rmse_std = std::sqrt(std::max(0.0, s.rmse_std / s.settled - s.rmse_mean * s.rmse_mean));
      s.settle_time_mean /= s.settled;
    } else {
      s.rmse_mean = s.rmse_std = s.settle_time_mean = NAN;
    }
  }
  return out;
}

}  // namespace aerie::ceopt
