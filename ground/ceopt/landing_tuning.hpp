#pragma once
// Cross-entropy tuning of the landing controller in the closed loop (issue 13; the method
// of thesis 5.1.4, Algorithm 3, applied to aerie-pilot's controller): a candidate is a set of
// gains of config/pilot.yaml (`<axis>.<gain>`, e.g. horizontal.kp for forward and left
// alike); its cost is the mean over the training seeds of one lock-step landing each
// (loop/landing.hpp: the real flight simulator, tracking and pilot nodes in loop::Harness):
//   cost(run) = touchdown error (m) if the landing succeeded, else failure_cost_m,
//               + time_weight_per_s * time to land (s, landed runs)
// Every candidate flies the same seeds (common random numbers), so two candidates differ by
// their gains and not by their luck. The winner and the initial gains are then flown on
// validation seeds that took no part in the choice.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "common/util/config.hpp"
#include "ground/ceopt/cross_entropy.hpp"
#include "loop/landing.hpp"

namespace aerie::ceopt {

struct SeedRange {
  uint64_t first = 0;
  int count = 0;
};

struct LandingTuningConfig {
  std::string origin = "<defaults>";
  std::string sim_config = "config/sim/landing_room.yaml";  // paths relative to the working directory
  std::string track_config = "config/track_landing.yaml";
  std::string pilot_config = "config/pilot.yaml";  // the base: every key but the tuned gains is kept
  std::string tracker = "amcmr-ct";
  double wind_m_s = 2.0;
  bool vibration = true;
  SeedRange training{2001, 16};
  SeedRange validation{3001, 50};  // count 0: no validation
  double failure_cost_m = 0.5;     // cost of a failed landing (collision, out of bounds, timed out)
  double time_weight_per_s = 0.001;  // m of cost per s to land
  int threads = 0;                 // 0 = all cores
  CeOptions ce;
  std::vector<CeParameter> parameters;
};

// Defaults: config/ceopt_landing.yaml documents every key.
LandingTuningConfig default_landing_tuning_config();
LandingTuningConfig landing_tuning_config_from(const util::Config& cfg);

// The base pilot configuration (YAML text) with `values` set for `names` under
// gains.<controller>: "<axis>.<gain>", axis forward | left | up | yaw | horizontal (forward
// and left), gain kp | kd | ki | ku | integral_limit | output_limit. Throws naming an unknown
// parameter or an invalid result.
std::string pilot_yaml_with(const std::string& base_yaml, const std::vector<std::string>& names,
                            const std::vector<double>& values);

struct LandingRun {
  uint64_t seed = 0;
  bool success = false, collided = false;
  double touchdown_error_m = 0, time_s = 0, sim_s = 0, wall_s = 0;
  int losses = 0;
};

double run_cost(const LandingRun& r, const LandingTuningConfig& cfg);
double mean_cost(const std::vector<LandingRun>& runs, const LandingTuningConfig& cfg);

class LandingTuning {
 public:
  // Reads the three configuration files once; throws naming what is wrong.
  explicit LandingTuning(LandingTuningConfig cfg);
  const LandingTuningConfig& config() const { return cfg_; }
  std::vector<std::string> names() const;
  const std::string& base_pilot_yaml() const { return base_pilot_yaml_; }

  // One landing per seed of `seeds` with the gains `x` (one per parameter), in order; safe
  // to call from several threads.
  std::vector<LandingRun> fly(const std::vector<double>& x, const SeedRange& seeds) const;

 private:
  LandingTuningConfig cfg_;
  std::string base_pilot_yaml_;
  loop::landing::LandingSpec spec_;  // the files and what is set over them; the pilot's text per candidate
};

struct LandingTuningResult {
  CeResult ce;
  std::vector<double> initial;                // the parameters' initial means (the base gains)
  std::string tuned_pilot_yaml;               // the base pilot config with the winner's gains
  std::vector<LandingRun> initial_training;   // the base gains on the training seeds
  std::vector<LandingRun> initial_validation, tuned_validation;
  double seconds = 0, cpu_seconds = 0;        // wall and process CPU time of the whole tuning
};

// A set of gains flown on a range of seeds: what tune_landing asks to be flown.
struct LandingJob {
  std::vector<double> x;
  SeedRange seeds;
};
// Flies every landing of the jobs; each job's runs in seed order. aerie-ceopt under MPI spreads
// them over the ranks (ground/ceopt/landing_study.hpp): one call per CE iteration.
using LandingFlier = std::function<std::vector<std::vector<LandingRun>>(const std::vector<LandingJob>&)>;

class ThreadPool;
// Called as each candidate's landings are done (from the pool's threads, one at a time; with a
// flier, on the calling thread in candidate order).
using CandidateCallback = std::function<void(const std::vector<double>& x, const std::vector<LandingRun>& runs, double cost)>;
// Without a flier the landings fly on the pool; with one, through it (the pool then idles): the
// same landings, the same figures.
LandingTuningResult tune_landing(const LandingTuning& problem, ThreadPool& pool, const IterationCallback& on_iteration = {},
                                 const CandidateCallback& on_candidate = {}, const LandingFlier& flier = {});

// OUT/pilot.yaml (the tuned configuration), OUT/ce_history.csv, OUT/validation.csv and
// OUT/report.md; returns the files written.
std::vector<std::string> write_landing_report(const std::string& out_dir, const LandingTuning& problem,
                                              const LandingTuningResult& result, const std::string& command_line);

}  // namespace aerie::ceopt
