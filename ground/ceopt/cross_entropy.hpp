#pragma once
// The cross-entropy method for continuous minimisation (thesis 5.1.4, Algorithm 3):
// N candidates per iteration from independent Gaussians, one per parameter; the
// N_elite lowest-cost candidates give the mean and standard deviation of the next
// Gaussians through the smoothed updates of eq. 5.7:
//   eta(t)   = beta - beta (1 - 1/t)^q
//   mu(t)    = alpha mu~(t) + (1 - alpha) mu(t-1)
//   sigma(t) = eta(t) sigma~(t) + (1 - eta(t)) sigma(t-1)
// Candidates are evaluated in parallel; sampling happens on the calling thread from
// one seeded generator, so a run is reproducible from its seed whatever the number of
// threads (given a deterministic cost).
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace aerie::ceopt {

class ThreadPool;

struct CeParameter {
  std::string name;
  double mean = 0.0;    // initial mean mu(0)
  double sigma = 1.0;   // initial standard deviation sigma(0)
  double lower = -1e300, upper = 1e300;  // samples are clipped to [lower, upper]
};

struct CeOptions {
  int samples = 50;           // N, candidates per iteration
  int elite = 5;              // N_elite
  int max_iterations = 100;
  double alpha = 0.5;         // mean smoothing, thesis range [0.4, 0.9]
  double beta = 0.7;          // sigma smoothing, thesis range [0.6, 0.9]
  double q = 5.0;             // thesis range [2, 7]
  double sigma_stop = 0.0;    // stop when every sigma(t) < sigma_stop * sigma(0); 0 = never
  uint64_t seed = 1;
  void validate() const;      // throws std::invalid_argument
};

// eq. 5.7's dynamic smoothing factor for sigma at iteration t >= 1.
double eta(int t, double beta, double q);

struct CeIteration {
  int iteration = 0;                 // t, from 1
  int evaluations = 0;               // cost evaluations so far
  std::vector<double> mean, sigma;   // mu(t), sigma(t) after the update
  double eta = 0.0;
  double iteration_best_cost = 0.0;
  double best_cost = 0.0;            // best so far
  std::vector<double> best;          // best candidate so far
  std::vector<double> elite_costs;   // gamma(t) is the last one
};

struct CeResult {
  std::vector<double> best;          // the best candidate evaluated (the "winner")
  double best_cost = 0.0;
  int best_iteration = 0;            // the iteration that found it
  int evaluations = 0;
  std::vector<double> final_mean, final_sigma;
  std::string stop_reason;           // "iterations", "sigma", or "cancelled"
  std::vector<CeIteration> history;
};

// Cost of a candidate (lower is better); must be safe to call from several threads.
// NaN counts as +infinity.
using CostFunction = std::function<double(const std::vector<double>&)>;
// Maps a clipped sample to a feasible one in place (e.g. ordering constraints); the
// repaired sample is what is evaluated and what updates the Gaussians.
using RepairFunction = std::function<void(std::vector<double>&)>;
// Called after each iteration; return false to stop.
using IterationCallback = std::function<bool(const CeIteration&)>;
// The costs of one iteration's candidates at once, in their order (aerie-ceopt under MPI: the
// candidates are the runs of a study over the ranks). When set, it replaces `cost` on the pool.
using BatchCostFunction = std::function<std::vector<double>(const std::vector<std::vector<double>>&)>;

CeResult cross_entropy(const std::vector<CeParameter>& parameters, const CeOptions& options, const CostFunction& cost,
                       ThreadPool& pool, const RepairFunction& repair = {}, const IterationCallback& on_iteration = {},
                       const BatchCostFunction& batch_cost = {});

}  // namespace aerie::ceopt
