// The cross-entropy optimiser on known functions, the eq. 5.7 schedule, reproducibility
// across thread counts, the FLC tuning problem and the configuration.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <random>

#include "common/flc/flc_io.hpp"
#include "ground/ceopt/cross_entropy.hpp"
#include "ground/ceopt/flc_problem.hpp"
#include "ground/ceopt/pipeline.hpp"
#include "ground/ceopt/report.hpp"
#include "ground/ceopt/thread_pool.hpp"

using namespace aerie;
using namespace aerie::ceopt;

namespace {

double sphere(const std::vector<double>& x) {
  double s = 0;
  for (double v : x) s += (v - 1.5) * (v - 1.5);
  return s;
}

double rosenbrock(const std::vector<double>& x) {
  double s = 0;
  for (size_t i = 0; i + 1 < x.size(); ++i) s += 100 * std::pow(x[i + 1] - x[i] * x[i], 2) + std::pow(1 - x[i], 2);
  return s;
}

std::vector<CeParameter> box(int n, double mean, double sigma, double lo, double hi) {
  std::vector<CeParameter> p;
  for (int i = 0; i < n; ++i) p.push_back({"x" + std::to_string(i), mean, sigma, lo, hi});
  return p;
}

}  // namespace

TEST(CrossEntropy, EtaScheduleIsEq57) {
  // eta(t) = beta - beta (1 - 1/t)^q: beta at t = 1, then decreasing toward 0.
  EXPECT_DOUBLE_EQ(eta(1, 0.8, 5), 0.8);
  EXPECT_DOUBLE_EQ(eta(2, 0.8, 5), 0.8 - 0.8 * std::pow(0.5, 5));
  EXPECT_DOUBLE_EQ(eta(10, 0.7, 2), 0.7 - 0.7 * 0.81);
  EXPECT_NEAR(eta(100, 0.9, 7), 0.9 * (1 - std::pow(0.99, 7)), 1e-15);
  for (int t = 1; t < 200; ++t) EXPECT_GT(eta(t, 0.8, 5), eta(t + 1, 0.8, 5));
  EXPECT_THROW(eta(0, 0.8, 5), std::invalid_argument);
}

TEST(CrossEntropy, SmoothedUpdatesFollowEq57) {
  // With the recorded history, mu(t) and sigma(t) must be the smoothed elite statistics.
  // Check it on a 1-D problem by recomputing the first update from its sample.
  ThreadPool pool(1);
  CeOptions opt;
  opt.samples = 20;
  opt.elite = 5;
  opt.max_iterations = 3;
  opt.alpha = 0.6;
  opt.beta = 0.7;
  opt.q = 3;
  std::vector<std::vector<double>> seen;
  const auto r = cross_entropy(box(1, 4.0, 2.0, -100, 100), opt,
                               [&](const std::vector<double>& x) { return std::abs(x[0] - 1.0); }, pool, {},
                               [&](const CeIteration&) { return true; });
  ASSERT_EQ(r.history.size(), 3u);
  // Reproduce iteration 1 from the same generator.
  std::mt19937_64 rng(opt.seed);
  std::normal_distribution<double> g(0, 1);
  std::vector<double> x(20);
  for (auto& v : x) v = 4.0 + 2.0 * g(rng);
  std::sort(x.begin(), x.end(), [](double a, double b) { return std::abs(a - 1) < std::abs(b - 1); });
  double m = 0, v = 0;
  for (int i = 0; i < 5; ++i) m += x[i] / 5;
  for (int i = 0; i < 5; ++i) v += (x[i] - m) * (x[i] - m) / 5;
  EXPECT_NEAR(r.history[0].mean[0], 0.6 * m + 0.4 * 4.0, 1e-12);
  EXPECT_NEAR(r.history[0].sigma[0], 0.7 * std::sqrt(v) + 0.3 * 2.0, 1e-12);  // eta(1) = beta
  EXPECT_DOUBLE_EQ(r.history[0].eta, 0.7);
  EXPECT_DOUBLE_EQ(r.history[1].eta, eta(2, 0.7, 3));
  EXPECT_EQ(r.history[2].evaluations, 60);
}

TEST(CrossEntropy, ConvergesOnSphereAndRosenbrock) {
  ThreadPool pool(2);
  CeOptions opt;
  opt.samples = 60;
  opt.elite = 5;
  opt.max_iterations = 150;
  const auto s = cross_entropy(box(5, -3.0, 3.0, -10, 10), opt, sphere, pool);
  EXPECT_LT(s.best_cost, 1e-6);
  for (double v : s.best) EXPECT_NEAR(v, 1.5, 1e-3);
  opt.max_iterations = 300;
  opt.samples = 100;
  opt.alpha = 0.8;
  const auto r = cross_entropy(box(2, -1.0, 2.0, -5, 5), opt, rosenbrock, pool);
  EXPECT_LT(r.best_cost, 1e-4);
  EXPECT_NEAR(r.best[0], 1.0, 0.01);
  EXPECT_NEAR(r.best[1], 1.0, 0.02);
}

TEST(CrossEntropy, ReproducibleWhateverTheThreadCountAndStopsOnSigma) {
  CeOptions opt;
  opt.samples = 30;
  opt.max_iterations = 40;
  opt.seed = 42;
  auto run = [&](int threads) {
    ThreadPool pool(threads);
    return cross_entropy(box(3, 2.0, 1.0, -5, 5), opt, rosenbrock, pool);
  };
  const auto a = run(1), b = run(2), c = run(3);
  EXPECT_EQ(a.best, b.best);
  EXPECT_EQ(a.best, c.best);
  EXPECT_EQ(a.final_mean, c.final_mean);
  opt.seed = 43;
  EXPECT_NE(run(2).best, a.best);
  // Stopping rule on sigma.
  opt.sigma_stop = 1e-3;
  opt.max_iterations = 1000;
  ThreadPool pool(2);
  const auto s = cross_entropy(box(2, 3.0, 1.0, -5, 5), opt, sphere, pool);
  EXPECT_EQ(s.stop_reason, "sigma");
  EXPECT_LT(static_cast<int>(s.history.size()), 1000);
  for (double sg : s.final_sigma) EXPECT_LT(sg, 1e-3);
}

TEST(CrossEntropy, ThreadPoolPropagatesExceptionsAndInvalidOptions) {
  ThreadPool pool(2);
  std::atomic<int> calls{0};
  EXPECT_THROW(pool.parallel_for(100,
                                 [&](size_t i) {
                                   ++calls;
                                   if (i == 7) throw std::runtime_error("boom");
                                 }),
               std::runtime_error);
  pool.parallel_for(10, [&](size_t) { ++calls; });  // still usable
  CeOptions bad;
  bad.elite = 0;
  EXPECT_THROW(cross_entropy(box(1, 0, 1, -1, 1), bad, sphere, pool), std::invalid_argument);
  bad = CeOptions{};
  bad.alpha = 1.5;
  EXPECT_THROW(cross_entropy(box(1, 0, 1, -1, 1), bad, sphere, pool), std::invalid_argument);
}

TEST(FlcTuning, RepairKeepsSetsOrderedAndTheCostRanksControllers) {
  TrainingOptions t;
  t.runs_per_speed = 1;
  const FlcTuningProblem mf(flc::thesis_initial(),
                            {"error.Left", "yaw_rate.BigLeft", "yaw_rate.Left", "yaw_rate.LittleLeft"}, t);
  std::vector<double> x = {-95.0, -10.0, -50.0, -50.0};  // outside, unordered, coincident
  mf.repair(x);
  const auto spec = mf.controller(x);  // valid
  EXPECT_GT(x[0], -90.0);
  EXPECT_LT(x[1], x[2]);  // sorted in set order: BigLeft < Left < LittleLeft
  EXPECT_LT(x[2], x[3]);
  EXPECT_GE(x[2] - x[1], 0.18 - 1e-12);  // at least 1e-3 of the range apart
  EXPECT_EQ(spec.output.positions[1], x[1]);
  EXPECT_EQ(spec.output.positions[7], -x[1]);

  const FlcTuningProblem sf(flc::thesis_initial(), {"Kp", "Kd", "Ki"}, t);
  EXPECT_EQ(sf.initial(), (std::vector<double>{1, 1, 1}));
  // The hand-tuned initial FLC hits the wall (its integral rules push against the turn);
  // a PD-like tuning avoids it.
  const double initial = sf.cost({1, 1, 1});
  const double tuned = sf.cost({3.0, 0.01, -0.01});
  EXPECT_GT(initial, t.penalty_dangerous);
  EXPECT_LT(tuned, 1e4);
  EXPECT_TRUE(std::isinf(sf.cost({0.0, 1, 1})));  // an invalid controller (Kp = 0)
}

TEST(Config, TheShippedConfigIsTheDefaultAndErrorsNameTheKey) {
  const auto cfg = ceopt_config_from(util::Config::load(std::string(AERIE_SOURCE_DIR) + "/config/ceopt.yaml"));
  const auto def = default_ceopt_config();
  EXPECT_EQ(cfg.ce.samples, def.ce.samples);
  EXPECT_EQ(cfg.ce.elite, 5);
  EXPECT_EQ(cfg.ce.max_iterations, 100);
  ASSERT_EQ(cfg.stage1.size(), def.stage1.size());
  ASSERT_EQ(cfg.stage2.size(), def.stage2.size());
  for (size_t i = 0; i < cfg.stage2.size(); ++i) {
    EXPECT_EQ(cfg.stage2[i].name, def.stage2[i].name);
    EXPECT_EQ(cfg.stage2[i].mean, def.stage2[i].mean);
    EXPECT_EQ(cfg.stage2[i].sigma, def.stage2[i].sigma);
  }
  EXPECT_EQ(cfg.training.scenario.scene.safe_area_m, 3.0);
  EXPECT_EQ(cfg.training.scenario.settle_band_deg, def.training.scenario.settle_band_deg);
  EXPECT_EQ(cfg.evaluation.runs_per_speed, 20);
  auto refuses = [](const std::string& yaml, const std::string& what) {
    try {
      ceopt_config_from(util::Config::parse(yaml, "x.yaml"));
      ADD_FAILURE() << "accepted " << yaml;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  refuses("ce: {elite: 0}\n", "elite");
  refuses("ce: {samles: 10}\n", "samles");
  refuses("scenario: {vehicle: blimp}\n", "blimp");
  refuses("scenario: {scene: {safe_area_m: 5}}\n", "normal + safe");
  refuses("stage1: [{name: Kp, mean: 20, sigma: 1, lower: 0, upper: 10}]\n", "lower <= mean <= upper");
}

TEST(Pipeline, ShortTuningImprovesOnTheInitialControllerAndIsReproducible) {
  CeoptConfig cfg = default_ceopt_config();
  cfg.ce.samples = 12;
  cfg.ce.max_iterations = 4;
  cfg.training.runs_per_speed = 1;
  cfg.evaluation.runs_per_speed = 2;
  ThreadPool pool(2);
  int calls = 0;
  const auto t = run_tuning(cfg, pool, [&](int, const std::vector<std::string>&, const CeIteration&) {
    ++calls;
    return true;
  });
  EXPECT_EQ(calls, 8);
  EXPECT_EQ(t.stage1.ce.evaluations, 48);
  const FlcTuningProblem p(t.initial, {"Kp"}, cfg.training);
  EXPECT_LT(t.stage1.ce.best_cost, p.cost({1.0}));
  EXPECT_LE(t.stage2.ce.best_cost, t.stage1.ce.best_cost * 1.5);
  EXPECT_NO_THROW(flc::Flc{t.pruned});
  // Verified pruning: every tried merge is recorded with its cost; with no tolerance
  // limit (< 0) all overlap merges are kept, as flc::prune does at once.
  for (const auto& st : t.prune_steps) EXPECT_EQ(st.accepted, st.cost_after <= t.stage2.ce.best_cost * 1.1 + 1e-9) << st.variable;
  CeoptConfig all = cfg;
  all.prune_max_cost_increase = -1;
  flc::PruneReport rep;
  std::vector<PruneStep> steps;
  const auto pruned_all = prune_verified(t.stage2.controller, all, &rep, &steps);
  EXPECT_EQ(pruned_all.rules.size(), flc::prune(t.stage2.controller, cfg.prune).rules.size());
  for (const auto& st : steps) EXPECT_TRUE(st.accepted);
  ThreadPool one(1);
  const auto again = run_tuning(cfg, one);
  EXPECT_EQ(again.stage2.ce.best, t.stage2.ce.best);
  const auto runs = run_experiment({{"sf", t.stage1.controller}}, cfg, pool);
  ASSERT_EQ(runs.size(), 6u);
  EXPECT_FALSE(runs[0].result.trajectory.empty());
  EXPECT_TRUE(runs[1].result.trajectory.empty());
  const auto sum = summarise(runs);
  ASSERT_EQ(sum.size(), 3u);
  EXPECT_EQ(sum[0].runs, 2);
}

TEST(CeoptReport, AnExperimentWithNoSettledRunSaysSoInsteadOfNan) {
  // Issue 18: the hand-tuned initial FLC never settles; the summary printed "RMSE nan ± nan".
  ExperimentSummary s;
  s.controller = "initial";
  s.runs = 20;
  s.rmse_mean = s.rmse_std = std::nan("");
  EXPECT_EQ(rmse_text(s), "never settled");
  s.settled = 20;
  s.rmse_mean = 1.156;
  s.rmse_std = 0.164;
  EXPECT_EQ(rmse_text(s), "1.16 ± 0.16");
}
