// The simulator's YAML configuration: the shipped files load, keys reach the structs,
// typos and bad values are rejected naming the file and key.
#include <gtest/gtest.h>

#include "common/sim/sim_config.hpp"
#include "tests/support/test_support.hpp"

namespace aerie::sim {
namespace {

TEST(SimConfig, ShippedFilesLoad) {
  for (const char* name : {"demo.yaml", "vo_loops.yaml", "landing.yaml", "intruder.yaml"}) {
    const auto cfg = util::Config::load((test::source_dir() / "config" / "sim" / name).string());
    EXPECT_NO_THROW(load_simulation_config(cfg)) << name;
    EXPECT_NO_THROW(load_intruder_config(cfg.section("intruder"))) << name;
  }
  const auto loops = load_simulation_config(
      util::Config::load((test::source_dir() / "config" / "sim" / "vo_loops.yaml").string()));
  EXPECT_EQ(loops.trajectory.kind, "loops");
  EXPECT_EQ(loops.trajectory.loops, 10);
  EXPECT_DOUBLE_EQ(loops.rig.pitch_deg, 10.0);
}

TEST(SimConfig, KeysReachTheStructs) {
  const auto cfg = util::Config::parse(R"(
world: {seed: 7, room_x: 9, n_obstacles: 3, texels_per_metre: 40}
rig: {width: 752, height: 480, color: true, noise_sigma: 2.5}
trajectory: {kind: landing, speed: 0.5, rate_hz: 10, start_utime: 1000}
intruder: {frames: 12, vibration_px: 0.5}
)");
  const SimulationConfig s = load_simulation_config(cfg);
  EXPECT_EQ(s.world.seed, 7u);
  EXPECT_DOUBLE_EQ(s.world.room_x, 9.0);
  EXPECT_EQ(s.world.n_obstacles, 3);
  EXPECT_EQ(s.rig.width, 752);
  EXPECT_TRUE(s.rig.color);
  EXPECT_DOUBLE_EQ(s.rig.noise_sigma, 2.5);
  EXPECT_DOUBLE_EQ(s.rig.baseline, 0.12);  // default kept
  EXPECT_EQ(s.trajectory.kind, "landing");
  EXPECT_EQ(load_intruder_config(cfg.section("intruder")).frames, 12);
  const StereoSimulation sim = make_simulation(s);
  EXPECT_EQ(sim.world().obstacles().size(), 3u);
  EXPECT_EQ(sim.intrinsics().width, 752);
  EXPECT_EQ(sim.utime_of(1), 1000 + 100000);
  EXPECT_NEAR(sim.trajectory().duration(), Trajectory::landing(sim.world(), 0.5).duration(), 1e-9);
}

TEST(SimConfig, RejectsTyposAndBadValues) {
  auto expect_error = [](const std::string& yaml, const std::string& needle) {
    try {
      load_simulation_config(util::Config::parse(yaml, "test.yaml"));
      FAIL() << "no error for " << yaml;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("test.yaml"), std::string::npos) << e.what();
    }
  };
  expect_error("rig: {widht: 100}", "widht");
  expect_error("wrld: {seed: 2}", "wrld");
  expect_error("trajectory: {kind: spiral}", "kind");
  expect_error("world: {seed: abc}", "seed");
}

}  // namespace
}  // namespace aerie::sim
