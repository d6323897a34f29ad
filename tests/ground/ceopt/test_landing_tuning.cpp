// aerie-ceopt landing (ground/ceopt/landing_tuning): the gains are written where the pilot reads
// them, unknown or invalid ones are refused naming them, the cost is the issue's, and a small
// tuning in the closed loop is reproducible: its best candidate, flown again, costs what the
// tuning said, and the pilot.yaml it writes loads with the winner's gains.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <sstream>

#include "air/pilot/pilot_config.hpp"
#include "ground/ceopt/landing_tuning.hpp"
#include "ground/ceopt/thread_pool.hpp"

using namespace aerie;
using namespace aerie::ceopt;

namespace {

const std::string kSource = AERIE_SOURCE_DIR;

std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

std::string refusal(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

pilot::PilotConfig pilot_of(const std::string& yaml) { return pilot::load_pilot_config(util::Config::parse(yaml, "test")); }

LandingTuningConfig config_from(const std::string& yaml) {
  return landing_tuning_config_from(util::Config::parse(yaml, "ceopt_landing.yaml"));
}

}  // namespace

TEST(LandingTuning, GainsAreWrittenWhereThePilotReadsThem) {
  const std::string base = slurp(kSource + "/config/pilot.yaml");
  const pilot::PilotConfig before = pilot_of(base);
  const pilot::PilotConfig after =
      pilot_of(pilot_yaml_with(base, {"horizontal.kp", "up.ki", "yaw.output_limit"}, {3.14159, 0.123456, 20}));
  EXPECT_DOUBLE_EQ(after.forward.kp, 3.142);  // four significant digits, as written
  EXPECT_DOUBLE_EQ(after.left.kp, 3.142);
  EXPECT_DOUBLE_EQ(after.up.ki, 0.1235);
  EXPECT_DOUBLE_EQ(after.yaw.output_limit, 20);
  EXPECT_DOUBLE_EQ(after.forward.kd, before.forward.kd);  // the rest untouched
  EXPECT_DOUBLE_EQ(after.up.kp, before.up.kp);
  EXPECT_EQ(after.touchdown_height_m, before.touchdown_height_m);
}

TEST(LandingTuning, UnknownOrInvalidGainsAreRefusedNamingThem) {
  const std::string base = slurp(kSource + "/config/pilot.yaml");
  const std::string axis = refusal([&] { pilot_yaml_with(base, {"wing.kp"}, {1}); });
  EXPECT_NE(axis.find("unknown landing parameter 'wing.kp'"), std::string::npos) << axis;
  const std::string gain = refusal([&] { pilot_yaml_with(base, {"forward.kx"}, {1}); });
  EXPECT_NE(gain.find("'forward.kx'"), std::string::npos) << gain;
  const std::string value = refusal([&] { pilot_yaml_with(base, {"forward.ku"}, {-1}); });
  EXPECT_NE(value.find("forward.ku=-1 is invalid"), std::string::npos) << value;
  // A bound that makes no valid pilot is refused before anything is flown.
  LandingTuningConfig cfg = config_from("parameters: [{name: left.ku, mean: 1, sigma: 0.5, lower: -1, upper: 2}]");
  cfg.sim_config = kSource + "/config/sim/landing_room.yaml";
  cfg.track_config = kSource + "/config/track_landing.yaml";
  cfg.pilot_config = kSource + "/config/pilot.yaml";
  const std::string bound = refusal([&] { LandingTuning problem(cfg); });
  EXPECT_NE(bound.find("left.ku=-1"), std::string::npos) << bound;
}

TEST(LandingTuning, BadConfigurationIsRefusedNamingTheKey) {
  EXPECT_EQ(refusal([] { config_from(slurp(kSource + "/config/ceopt_landing.yaml")); }), "");
  const std::string key = refusal([] { config_from("cost: {failure: 1}"); });
  EXPECT_NE(key.find("failure"), std::string::npos) << key;
  const std::string seeds = refusal([] { config_from("training: {first: 1, count: 0}"); });
  EXPECT_NE(seeds.find("training.count"), std::string::npos) << seeds;
  const std::string empty = refusal([] { config_from("parameters: []"); });
  EXPECT_NE(empty.find("nothing to tune"), std::string::npos) << empty;
  const std::string missing = refusal([] {
    LandingTuningConfig c = default_landing_tuning_config();
    c.pilot_config = "/nonexistent/pilot.yaml";
    LandingTuning problem(c);
  });
  EXPECT_NE(missing.find("/nonexistent/pilot.yaml"), std::string::npos) << missing;
}

TEST(LandingTuning, CostIsTheTouchdownErrorOrTheFailureCost) {
  LandingTuningConfig cfg;
  cfg.failure_cost_m = 0.5;
  cfg.time_weight_per_s = 0.001;
  LandingRun ok;
  ok.success = true;
  ok.touchdown_error_m = 0.08;
  ok.time_s = 30;
  LandingRun off = ok;
  off.success = false;
  EXPECT_DOUBLE_EQ(run_cost(ok, cfg), 0.08 + 0.03);
  EXPECT_DOUBLE_EQ(run_cost(off, cfg), 0.5);
  EXPECT_DOUBLE_EQ(mean_cost({ok, off}, cfg), (0.11 + 0.5) / 2);
}

// Two candidates, one training seed, no wind: the whole loop, in four landings.
TEST(LandingTuning, ATuningInTheClosedLoopIsReproducibleAndWritesAPilotConfig) {
  LandingTuningConfig cfg = default_landing_tuning_config();
  cfg.sim_config = kSource + "/config/sim/landing_room.yaml";
  cfg.track_config = kSource + "/config/track_landing.yaml";
  cfg.pilot_config = kSource + "/config/pilot.yaml";
  cfg.wind_m_s = 0;
  cfg.training = {7, 1};
  cfg.validation = {0, 0};
  cfg.ce.samples = 2;
  cfg.ce.elite = 1;
  cfg.ce.max_iterations = 1;
  const LandingTuning problem(cfg);
  ThreadPool pool(2);
  cv::setNumThreads(1);  // as aerie-ceopt does with a pool of several threads: one core per landing
  const LandingTuningResult r = tune_landing(problem, pool);
  ASSERT_EQ(r.ce.history.size(), 1u);
  EXPECT_EQ(r.ce.evaluations, 2);
  ASSERT_EQ(r.initial_training.size(), 1u);
  EXPECT_TRUE(r.initial_training[0].success) << "the base gains land on seed 7 without wind";
  EXPECT_TRUE(r.initial_validation.empty());
  // Lock-step: the winner flown again costs exactly what the tuning measured.
  EXPECT_EQ(mean_cost(problem.fly(r.ce.best, cfg.training), cfg), r.ce.best_cost);

  const auto dir = std::filesystem::temp_directory_path() / ("ceopt-landing-" + std::to_string(::getpid()));
  const auto files = write_landing_report(dir.string(), problem, r, "test");
  EXPECT_EQ(files.size(), 4u);
  const pilot::PilotConfig tuned = pilot::load_pilot_config(util::Config::load((dir / "pilot.yaml").string()));
  const pilot::PilotConfig expect = pilot_of(pilot_yaml_with(problem.base_pilot_yaml(), problem.names(), r.ce.best));
  EXPECT_EQ(tuned.forward.kp, expect.forward.kp);
  EXPECT_EQ(tuned.left.ki, expect.left.ki);
  EXPECT_EQ(tuned.forward.ku, expect.forward.ku);
  std::istringstream history(slurp((dir / "ce_history.csv").string()));
  std::string header, row;
  std::getline(history, header);
  EXPECT_EQ(header.rfind("iteration,evaluations,best_cost,iteration_best_cost,eta,horizontal.kp_mean", 0), 0u) << header;
  int rows = 0;
  while (std::getline(history, row)) ++rows;
  EXPECT_EQ(rows, 1);
  std::filesystem::remove_all(dir);
}
