#include "ground/ceopt/cross_entropy.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>

#include "ground/ceopt/thread_pool.hpp"

namespace aerie::ceopt {

void CeOptions::validate() const {
  auto bad = [](const std::string& what) { throw std::invalid_argument("cross-entropy: " + what); };
  if (samples < 2) bad("samples (N) must be >= 2");
  if (elite < 1 || elite > samples) bad("elite (N_elite) must be in [1, samples]");
  if (max_iterations < 1) bad("max_iterations must be >= 1");
  if (!(alpha > 0.0 && alpha <= 1.0)) bad("alpha must be in (0, 1]");
  if (!(beta > 0.0 && beta <= 1.0)) bad("beta must be in (0, 1]");
  if (!(q > 0.0)) bad("q must be > 0");
  if (!(sigma_stop >= 0.0)) bad("sigma_stop must be >= 0");
}

double eta(int t, double beta, double q) {
  if (t < 1) throw std::invalid_argument("eta(t) is defined for t >= 1");
  return beta - beta * std::pow(1.0 - 1.0 / t, q);
}

CeResult cross_entropy(const std::vector<CeParameter>& parameters, const CeOptions& opt, const CostFunction& cost,
                       ThreadPool& pool, const RepairFunction& repair, const IterationCallback& on_iteration,
                       const BatchCostFunction& batch_cost) {
  opt.validate();
  const size_t h = parameters.size();
  if (h == 0) throw std::invalid_argument("cross-entropy: no parameters");
  std::vector<double> mu(h), sigma(h), sigma0(h);
  for (size_t j = 0; j < h; ++j) {
    const auto& p = parameters[j];
    if (!(p.lower <= p.upper) || !(p.sigma > 0.0) || !std::isfinite(p.mean))
      throw std::invalid_argument("cross-entropy: parameter '" + p.name + "' needs lower <= upper, sigma > 0, a finite mean");
    mu[j] = p.mean;
    sigma[j] = sigma0[j] = p.sigma;
  }
  std::mt19937_64 rng(opt.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const auto n = static_cast<size_t>(opt.samples);
  const auto ne = static_cast<size_t>(opt.elite);
  std::vector<std::vector<double>> x(n, std::vector<double>(h));
  std::vector<double> costs(n);
  std::vector<size_t> order(n);

  CeResult res;
  res.best_cost = std::numeric_limits<double>::infinity();
  res.stop_reason = "iterations";
  for (int t = 1; t <= opt.max_iterations; ++t) {
    // Step 2: N candidates from g(x, v(t)).
    for (auto& xi : x) {
      for (size_t j = 0; j < h; ++j) xi[j] = std::clamp(mu[j] + sigma[j] * gauss(rng), parameters[j].lower, parameters[j].upper);
      if (repair) repair(xi);
    }
    // Step 3: their costs (in parallel), ordered from smallest.
    if (batch_cost) {
      costs = batch_cost(x);
      if (costs.size() != n) throw std::logic_error("cross-entropy: the batch cost returned a cost per candidate too few or many");
      for (double& c : costs)
        if (std::isnan(c)) c = std::numeric_limits<double>::infinity();
    } else {
      pool.parallel_for(n, [&](size_t i) {
        const double c = cost(x[i]);
        costs[i] = std::isnan(c) ? std::numeric_limits<double>::infinity() : c;
      });
    }
    res.evaluations += opt.samples;
    std::iota(order.begin(), order.end(), size_t{0});
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return costs[a] < costs[b]; });
    if (costs[order[0]] < res.best_cost) {
      res.best_cost = costs[order[0]];
      res.best = x[order[0]];
      res.best_iteration = t;
    }
    // Step 4 with eq. 5.7: elite mean/standard deviation, smoothed.
    const double et = eta(t, opt.beta, opt.q);
    for (size_t j = 0; j < h; ++j) {
      double m = 0.0;
      for (size_t e = 0; e < ne; ++e) m += x[order[e]][j];
      m /= static_cast<double>(ne);
      double v = 0.0;
      for (size_t e = 0; e < ne; ++e) v += (x[order[e]][j] - m) * (x[order[e]][j] - m);
      const double s = std::sqrt(v / static_cast<double>(ne));
      mu[j] = opt.alpha * m + (1.0 - opt.alpha) * mu[j];
      sigma[j] = et * s + (1.0 - et) * sigma[j];
    }
    CeIteration it;
    it.iteration = t;
    it.evaluations = res.evaluations;
    it.mean = mu;
    it.sigma = sigma;
    it.eta = et;
    it.iteration_best_cost = costs[order[0]];
    it.best_cost = res.best_cost;
    it.best = res.best;
    for (size_t e = 0; e < ne; ++e) it.elite_costs.push_back(costs[order[e]]);
    res.history.push_back(it);
    if (on_iteration && !on_iteration(it)) {
      res.stop_reason = "cancelled";
      break;
    }
    // Step 5: the ending criterion.
    bool small = opt.sigma_stop > 0.0;
    for (size_t j = 0; j < h && small; ++j) small = sigma[j] < opt.sigma_stop * sigma0[j];
    if (small) {
      res.stop_reason = "sigma";
      break;
    }
  }
  res.final_mean = mu;
  res.final_sigma = sigma;
  return res;
}

}  // namespace aerie::ceopt
