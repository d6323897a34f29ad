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

// `load` of `yaml` fails with an error naming the file and `needle`.
template <typename Load>
void expect_load_error(Load load, const std::string& yaml, const std::string& needle) {
  try {
    load(util::Config::parse(yaml, "test.yaml"));
    FAIL() << "no error for " << yaml;
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("test.yaml"), std::string::npos) << e.what();
  }
}

TEST(SimConfig, RejectsTyposAndBadValues) {
  auto expect_error = [](const std::string& yaml, const std::string& needle) {
    expect_load_error(load_simulation_config, yaml, needle);
  };
  expect_error("rig: {widht: 100}", "widht");
  expect_error("wrld: {seed: 2}", "wrld");
  expect_error("trajectory: {kind: spiral}", "kind");
  expect_error("world: {seed: abc}", "seed");
}

TEST(SimConfig, ExitsKeysAreCheckedAndTheFileIsTheDefaults) {
  auto expect_error = [](const std::string& yaml, const std::string& needle) {
    expect_load_error(load_exits_config, yaml, needle);
  };
  expect_error("exits: {exitz: 2}", "exitz");
  expect_error("exits: {kinds: [pan, spin]}", "spin");
  expect_error("exits: {out_frames_min: 20, out_frames_max: 10}", "out_frames_min");
  expect_error("exits: {min_visible: 0}", "min_visible");
  expect_error("intruder: {frames: 3}", "intruder");
  expect_error("exits: {seed: abc}", "seed");
  expect_error("exits: {frames: 30}", "frames");  // an intruder key that the exits do not read
  const auto keys =
      load_exits_config(util::Config::parse("exits: {seed: 9, wingspan_px: 60, exits: 1, color: true}"));
  EXPECT_EQ(keys.look.seed, 9u);
  EXPECT_DOUBLE_EQ(keys.look.wingspan_px, 60.0);
  EXPECT_TRUE(keys.look.color);
  EXPECT_EQ(keys.exits, 1);
  const auto file =
      load_exits_config(util::Config::load((test::source_dir() / "config" / "sim" / "exits.yaml").string()));
  const ExitsConfig defaults;
  EXPECT_EQ(file.look.seed, defaults.look.seed);
  EXPECT_DOUBLE_EQ(file.look.vibration_px, defaults.look.vibration_px);
  EXPECT_DOUBLE_EQ(file.look.wingspan_px, defaults.look.wingspan_px);
  EXPECT_DOUBLE_EQ(file.look.max_roll_deg, defaults.look.max_roll_deg);
  EXPECT_EQ(file.kinds, defaults.kinds);
  EXPECT_EQ(file.out_frames_max, defaults.out_frames_max);
  EXPECT_DOUBLE_EQ(file.min_visible, defaults.min_visible);
  EXPECT_DOUBLE_EQ(file.reenter_elsewhere, defaults.reenter_elsewhere);
}

}  // namespace
}  // namespace aerie::sim
