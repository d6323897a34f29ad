// Cross-entropy against other global optimisers on the same FLC tuning problems and
// the same evaluation budget: random search and NLopt's CRS2 (controlled random
// search with local mutation), ISRES (evolution strategy) and DIRECT-L.
//   compare_optimisers [-c config/ceopt.yaml] [--out DIR] [--seeds K] [--budget-iterations T]
// Stage 1 tunes the scaling factors of the initial FLC; stage 2 the set positions of
// the stage-1 CE winner. All optimisers minimise the same deterministic cost (the
// repaired candidate's mean ITSE + penalties). Writes DIR/convergence.csv (best cost
// vs evaluations), DIR/summary.csv and, with python3, DIR/convergence.png.
#include <nlopt.hpp>

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <random>

#include "common/flc/flc_io.hpp"
#include "common/util/config.hpp"
#include "common/util/time.hpp"
#include "ground/ceopt/pipeline.hpp"
#include "ground/ceopt/report.hpp"
#include "ground/ceopt/thread_pool.hpp"

using namespace aerie;
using namespace aerie::ceopt;

namespace {

struct Trace {
  std::string optimiser;
  int stage = 0;
  uint64_t seed = 0;
  std::vector<double> best;  // best cost after each evaluation
  double seconds = 0.0;
};

// Counts evaluations and records the best-so-far curve; stops at the budget.
struct Recorder {
  const FlcTuningProblem& problem;
  size_t budget;
  Trace trace;
  double operator()(std::vector<double> x) {
    problem.repair(x);
    const double c = problem.cost(x);
    const double prev = trace.best.empty() ? std::numeric_limits<double>::infinity() : trace.best.back();
    trace.best.push_back(std::min(prev, c));
    return c;
  }
};

double nlopt_objective(const std::vector<double>& x, std::vector<double>&, void* data) {
  auto* r = static_cast<Recorder*>(data);
  if (r->trace.best.size() >= r->budget) throw nlopt::forced_stop();
  return (*r)(x);
}

Trace run_nlopt(nlopt::algorithm algo, const std::string& name, const FlcTuningProblem& p, const std::vector<CeParameter>& params,
                size_t budget, uint64_t seed, int stage) {
  Recorder rec{p, budget, {name, stage, seed, {}, 0.0}};
  nlopt::opt opt(algo, static_cast<unsigned>(params.size()));
  std::vector<double> lo, hi, x;
  for (const auto& q : params) {
    lo.push_back(q.lower);
    hi.push_back(q.upper);
    x.push_back(q.mean);
  }
  opt.set_lower_bounds(lo);
  opt.set_upper_bounds(hi);
  opt.set_min_objective(nlopt_objective, &rec);
  opt.set_maxeval(static_cast<int>(budget));
  if (algo == nlopt::GN_CRS2_LM || algo == nlopt::GN_ISRES) opt.set_population(static_cast<unsigned>(10 * (params.size() + 1)));
  nlopt::srand(seed);
  double f = 0;
  const util::Stopwatch w;
  try {
    opt.optimize(x, f);
  } catch (const nlopt::forced_stop&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s stage %d: %s (after %zu evaluations)\n", name.c_str(), stage, e.what(), rec.trace.best.size());
  }
  rec.trace.seconds = w.ms() / 1000;
  return rec.trace;
}

Trace run_random(const FlcTuningProblem& p, const std::vector<CeParameter>& params, size_t budget, uint64_t seed, int stage) {
  Recorder rec{p, budget, {"random", stage, seed, {}, 0.0}};
  std::mt19937_64 rng(seed);
  const util::Stopwatch w;
  for (size_t k = 0; k < budget; ++k) {
    std::vector<double> x;
    for (const auto& q : params) x.push_back(std::uniform_real_distribution<double>(q.lower, q.upper)(rng));
    rec(x);
  }
  rec.trace.seconds = w.ms() / 1000;
  return rec.trace;
}

Trace run_ce(const FlcTuningProblem& p, const std::vector<CeParameter>& params, const CeOptions& base, uint64_t seed, int stage) {
  CeOptions opt = base;
  opt.seed = seed;
  ThreadPool one(1);  // each job is single-threaded; jobs run in parallel
  Trace t{"cross-entropy", stage, seed, {}, 0.0};
  const util::Stopwatch w;
  const auto r = cross_entropy(
      params, opt, [&](const std::vector<double>& x) { return p.cost(x); }, one, [&](std::vector<double>& x) { p.repair(x); });
  t.seconds = w.ms() / 1000;
  // The best-so-far after each iteration, spread over its N evaluations.
  for (const auto& it : r.history)
    for (int k = 0; k < opt.samples; ++k) t.best.push_back(it.best_cost);
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"compare_optimisers: cross-entropy vs random search vs NLopt (CRS2, ISRES, DIRECT-L) on the FLC tuning"};
  std::string config, out = "bench-out/ceopt";
  int seeds = 3, iterations = -1, threads = 0;
  app.add_option("-c,--config", config, "ceopt YAML (default: built-in defaults = config/ceopt.yaml)");
  app.add_option("--out", out, "output folder");
  app.add_option("--seeds", seeds, "runs per stochastic optimiser");
  app.add_option("--budget-iterations", iterations, "budget = ce.samples x this (default ce.iterations)");
  app.add_option("--threads", threads, "parallel jobs (0 = all cores)");
  CLI11_PARSE(app, argc, argv);
  try {
    CeoptConfig cfg = config.empty() ? default_ceopt_config() : ceopt_config_from(util::Config::load(config));
    if (iterations > 0) cfg.ce.max_iterations = iterations;
    const size_t budget = static_cast<size_t>(cfg.ce.samples) * static_cast<size_t>(cfg.ce.max_iterations);
    std::filesystem::create_directories(out);
    ThreadPool pool(threads);
    const std::string load_before = read_loadavg();
    std::printf("budget %zu evaluations per run (%d x %d), %d seeds, %d parallel jobs, load %s\n", budget, cfg.ce.samples,
                cfg.ce.max_iterations, seeds, pool.size(), load_before.c_str());

    // Stage 2's base: the stage-1 CE winner (as in aerie-ceopt).
    const flc::FlcSpec initial = cfg.controller.empty() ? flc::thesis_initial() : flc::load_controller(cfg.controller);
    const flc::FlcSpec sf = run_stage(1, initial, cfg.stage1, cfg, pool).controller;
    std::vector<std::string> n1, n2;
    for (const auto& q : cfg.stage1) n1.push_back(q.name);
    for (const auto& q : cfg.stage2) n2.push_back(q.name);
    const FlcTuningProblem p1(initial, n1, cfg.training), p2(sf, n2, cfg.training);

    struct Job {
      std::string optimiser;
      int stage;
      uint64_t seed;
    };
    std::vector<Job> jobs;
    for (int stage : {1, 2}) {
      for (int s = 0; s < seeds; ++s)
        for (const char* o : {"cross-entropy", "random", "nlopt-crs2", "nlopt-isres"}) jobs.push_back({o, stage, 100 + static_cast<uint64_t>(s)});
      jobs.push_back({"nlopt-direct-l", stage, 0});  // deterministic
    }
    std::vector<Trace> traces(jobs.size());
    std::mutex print;
    pool.parallel_for(jobs.size(), [&](size_t i) {
      const Job& j = jobs[i];
      const FlcTuningProblem& p = j.stage == 1 ? p1 : p2;
      const auto& params = j.stage == 1 ? cfg.stage1 : cfg.stage2;
      if (j.optimiser == "cross-entropy") traces[i] = run_ce(p, params, cfg.ce, j.seed, j.stage);
      if (j.optimiser == "random") traces[i] = run_random(p, params, budget, j.seed, j.stage);
      if (j.optimiser == "nlopt-crs2") traces[i] = run_nlopt(nlopt::GN_CRS2_LM, j.optimiser, p, params, budget, j.seed, j.stage);
      if (j.optimiser == "nlopt-isres") traces[i] = run_nlopt(nlopt::GN_ISRES, j.optimiser, p, params, budget, j.seed, j.stage);
      if (j.optimiser == "nlopt-direct-l") traces[i] = run_nlopt(nlopt::GN_DIRECT_L, j.optimiser, p, params, budget, j.seed, j.stage);
      std::lock_guard lock(print);
      std::printf("  stage %d %-15s seed %3llu: best %.1f after %zu evaluations (%.1f s)\n", j.stage, j.optimiser.c_str(),
                  static_cast<unsigned long long>(j.seed), traces[i].best.empty() ? NAN : traces[i].best.back(), traces[i].best.size(),
                  traces[i].seconds);
    });

    std::ofstream conv(out + "/convergence.csv"), sum(out + "/summary.csv");
    conv << "stage,optimiser,seed,evaluations,best_cost\n";
    for (const auto& t : traces)
      for (size_t k = 0; k < t.best.size(); ++k)
        if ((k + 1) % 10 == 0 || k + 1 == t.best.size()) conv << t.stage << "," << t.optimiser << "," << t.seed << "," << k + 1 << "," << t.best[k] << "\n";
    // Summary: final best (mean, min, max over seeds) and the cost reached at 10/25/50/100 % of the budget.
    sum << "stage,optimiser,runs,evaluations,final_mean,final_min,final_max,at_10pct,at_25pct,at_50pct\n";
    std::printf("\n%-6s %-15s %5s %12s %12s %12s %12s %12s\n", "stage", "optimiser", "runs", "final mean", "final min", "at 10%",
                "at 25%", "at 50%");
    std::map<std::pair<int, std::string>, std::vector<const Trace*>> groups;
    for (const auto& t : traces) groups[{t.stage, t.optimiser}].push_back(&t);
    for (const auto& [key, ts] : groups) {
      auto at = [&](double frac) {
        double m = 0;
        for (const Trace* t : ts) m += t->best[std::min(t->best.size() - 1, static_cast<size_t>(frac * budget) - 1)];
        return m / ts.size();
      };
      double mean = 0, mn = 1e300, mx = -1e300;
      size_t evals = 0;
      for (const Trace* t : ts) {
        mean += t->best.back() / ts.size();
        mn = std::min(mn, t->best.back());
        mx = std::max(mx, t->best.back());
        evals = std::max(evals, t->best.size());
      }
      sum << key.first << "," << key.second << "," << ts.size() << "," << evals << "," << mean << "," << mn << "," << mx << "," << at(0.1)
          << "," << at(0.25) << "," << at(0.5) << "\n";
      std::printf("%-6d %-15s %5zu %12.1f %12.1f %12.1f %12.1f %12.1f\n", key.first, key.second.c_str(), ts.size(), mean, mn, at(0.1),
                  at(0.25), at(0.5));
    }
    conv.close();
    sum.close();
    std::printf("load before %s, after %s\n", load_before.c_str(), read_loadavg().c_str());
    const std::string plot = std::string(AERIE_BENCH_CEOPT_DIR) + "/plot_convergence.py";
    const std::string cmd = "/usr/bin/python3 '" + plot + "' '" + out + "'";
    if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "plotting failed: %s\n", cmd.c_str());
    std::printf("wrote %s/convergence.csv, summary.csv, convergence.png\n", out.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "compare_optimisers: %s\n", e.what());
    return 1;
  }
}
