#pragma once
// Tuning the FLC in simulation (thesis 5.1.5, Fig. 5.14): a candidate is a vector of
// named FLC parameters (stage 1: the scaling factors; stage 2: the left-side set
// positions, mirrored to the right); its cost is the ITSE of the avoidance manoeuvre,
// averaged over training runs at several speeds with sensor noise, plus penalties
// for runs that enter the dangerous area or do not finish.
#include <cstdint>
#include <string>
#include <vector>

#include "common/flc/flc.hpp"
#include "common/flc/heading_loop.hpp"
#include "common/sim/vehicle/avoidance.hpp"

namespace aerie::ceopt {

struct TrainingOptions {
  sim::AvoidanceConfig scenario;               // vehicle, scene, sensor, camera, gusts
  std::vector<double> speeds = {0.4, 0.6, 0.8};
  int runs_per_speed = 2;
  uint64_t seed = 1000;                        // noise seed of training run k is seed + k
  double penalty_dangerous = 1e6;              // per run that enters the dangerous area, times (1 + depth in m)
  double penalty_incomplete = 1e6;             // per run that hits the wall or times out
  flc::CommandLimits limits;
};

// Cost of one run: ITSE plus its penalties.
double run_cost(const sim::AvoidanceResult& r, const TrainingOptions& opt);

// Mean run cost of a controller over the training runs.
double controller_cost(const flc::Flc& flc, const TrainingOptions& opt);

// One avoidance run of a controller.
sim::AvoidanceResult fly(const flc::Flc& flc, const sim::AvoidanceConfig& scenario, double speed, uint64_t seed,
                         const flc::CommandLimits& limits, bool record = false);

class FlcTuningProblem {
 public:
  // names: FLC parameter names (FlcSpec::parameter_names()); throws if one is unknown.
  FlcTuningProblem(flc::FlcSpec base, std::vector<std::string> names, TrainingOptions options);

  const std::vector<std::string>& names() const { return names_; }
  const flc::FlcSpec& base() const { return base_; }
  const TrainingOptions& options() const { return opt_; }
  std::vector<double> initial() const;  // the base controller's values of the parameters

  // Makes a sample a valid controller: positions of one variable sorted in set order and
  // kept at least min_gap apart (and from the fixed sets and zero); scaling factors
  // kept away from zero.
  void repair(std::vector<double>& x) const;
  flc::FlcSpec controller(const std::vector<double>& x) const;  // base + x; throws if invalid
  // Mean run cost over the training runs; +infinity for an invalid controller.
  double cost(const std::vector<double>& x) const;
  int runs_per_evaluation() const { return static_cast<int>(opt_.speeds.size()) * opt_.runs_per_speed; }

  static constexpr double kMinGapFraction = 1e-3;  // of the variable's range

 private:
  flc::FlcSpec base_;
  std::vector<std::string> names_;
  TrainingOptions opt_;
};

}  // namespace aerie::ceopt
