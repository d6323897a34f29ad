#pragma once
// The whole tuning of thesis 5.1.5 (Fig. 5.14): stage 1 optimises the scaling factors
// of the initial controller, stage 2 the set positions with the stage-1 factors fixed,
// then overlapping sets and their rules are removed; the controllers are then flown in
// the avoidance experiment of 5.1.6 (speeds x runs with sensor noise).
#include <functional>
#include <string>
#include <vector>

#include "common/flc/flc.hpp"
#include "common/flc/prune.hpp"
#include "common/util/config.hpp"
#include "ground/ceopt/cross_entropy.hpp"
#include "ground/ceopt/flc_problem.hpp"

namespace aerie::ceopt {

struct EvaluationOptions {
  std::vector<double> speeds = {0.4, 0.6, 0.8};
  int runs_per_speed = 20;
  uint64_t seed = 5000;  // run k of a speed uses seed + 1000 * speed index + k (disjoint from training)
};

struct CeoptConfig {
  std::string origin = "<defaults>";
  std::string controller;             // initial controller file; "" = the compiled-in thesis one
  int threads = 0;                    // 0 = all cores
  CeOptions ce;                       // shared by both stages (seed: stage s uses ce.seed + s - 1)
  TrainingOptions training;
  std::vector<CeParameter> stage1, stage2;
  flc::PruneOptions prune;
  // A merge of overlapping sets is kept only if the training cost stays within
  // (1 + this) of the unpruned controller's; < 0 keeps every overlap merge (the
  // thesis' plain reduction).
  double prune_max_cost_increase = 0.1;
  EvaluationOptions evaluation;
};

// CPU time of this process so far, every thread (s).
double process_cpu_seconds();

// The `ce:` section (samples, elite, iterations, alpha, beta, q, sigma_stop, seed) over
// `options`; throws naming the file and what is wrong.
CeOptions ce_options_from(const util::Config& ce, CeOptions options);

// The list `key` of {name, mean, sigma, lower, upper} (CE parameters); fallback when absent.
// Throws naming the file and the entry.
std::vector<CeParameter> ce_parameters_from(const util::Config& cfg, const std::string& key, std::vector<CeParameter> fallback);

// Defaults = the thesis setting (config/ceopt.yaml documents every key).
CeoptConfig default_ceopt_config();
CeoptConfig ceopt_config_from(const util::Config& cfg);

struct StageResult {
  int stage = 0;                      // 1 = scaling factors, 2 = membership functions
  std::vector<std::string> names;
  CeResult ce;
  flc::FlcSpec controller;            // the base with the winner's parameters
  double seconds = 0.0;               // wall-clock time of the stage
  double cpu_seconds = 0.0;           // CPU time of the process over the stage (all threads)
};

// One variable's merge of overlapping sets, tried on the training runs.
struct PruneStep {
  std::string variable;
  std::vector<std::string> merges;   // "<variable>.<set> -> <kept set>"
  double cost_before = 0.0, cost_after = 0.0;
  bool accepted = false;
};

struct TuningResult {
  flc::FlcSpec initial;
  StageResult stage1, stage2;
  flc::FlcSpec pruned;
  flc::PruneReport prune_report;     // stage-2 controller -> pruned, over the accepted merges
  std::vector<PruneStep> prune_steps;
};

// Overlap pruning (flc::prune) one variable at a time, each merge verified on the
// training runs against cfg.prune_max_cost_increase.
flc::FlcSpec prune_verified(const flc::FlcSpec& spec, const CeoptConfig& cfg, flc::PruneReport* report,
                            std::vector<PruneStep>* steps);

// Called after every CE iteration with the stage; return false to stop (Ctrl-C).
using StageCallback = std::function<bool(int stage, const std::vector<std::string>& names, const CeIteration&)>;

StageResult run_stage(int stage, const flc::FlcSpec& base, const std::vector<CeParameter>& parameters,
                      const CeoptConfig& cfg, ThreadPool& pool, const StageCallback& cb = {});
TuningResult run_tuning(const CeoptConfig& cfg, ThreadPool& pool, const StageCallback& cb = {});

// One evaluation run of the experiment.
struct ExperimentRun {
  std::string controller;
  double speed = 0.0;
  int run = 0;
  uint64_t seed = 0;
  sim::AvoidanceResult result;
};

// Flies each controller runs_per_speed times at each speed (in parallel); the first
// run of each (controller, speed) keeps its trajectory.
std::vector<ExperimentRun> run_experiment(const std::vector<std::pair<std::string, flc::FlcSpec>>& controllers,
                                          const CeoptConfig& cfg, ThreadPool& pool);

struct ExperimentSummary {
  std::string controller;
  double speed = 0.0;
  int runs = 0;
  int settled = 0;                   // runs that reached the settle band
  double rmse_mean = 0.0, rmse_std = 0.0;  // steady-state heading RMSE over the settled runs (deg)
  double min_wall_distance = 0.0;    // smallest over the runs (m)
  int entered_dangerous = 0, collided = 0, completed = 0;
  double itse_mean = 0.0, settle_time_mean = 0.0;
};
std::vector<ExperimentSummary> summarise(const std::vector<ExperimentRun>& runs);

}  // namespace aerie::ceopt
