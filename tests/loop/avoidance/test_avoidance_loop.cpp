// The collision-avoidance flight of thesis ch. 5 flown on Aerie's own VO + IMU estimate, in
// lock-step: the thesis' outcome (no collision, no entry into the dangerous area, a steady
// heading parallel to the wall) and determinism (the same seed gives the same flight and
// the same commands, byte for byte).
#include <aerie/control_cmd_t.hpp>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "common/flc/flc_io.hpp"
#include "loop/avoidance.hpp"

using namespace aerie;

namespace {

loop::avoidance::RunConfig config(loop::avoidance::Source source, double speed) {
  loop::avoidance::RunConfig rc =
      loop::avoidance::load_avoidance_run(util::Config::load(AERIE_SOURCE_DIR "/config/avoidance.yaml"), AERIE_SOURCE_DIR);
  rc.source = source;
  rc.speed_m_s = speed;
  rc.controller = flc::load_controller(AERIE_SOURCE_DIR "/config/flc/sfmf.yaml");
  return rc;
}

}  // namespace

TEST(AvoidanceLoop, VoPlusImuFliesPastTheWallParallelAndTheSameTwice) {
  loop::avoidance::RunConfig rc = config(loop::avoidance::Source::kVio, 0.6);
  std::vector<std::vector<uint8_t>> commands[2];
  loop::avoidance::RunResult r[2];
  for (int i = 0; i < 2; ++i) {
    rc.on_message = [&](link::Side, const std::string& channel, const uint8_t* data, size_t size, int64_t) {
      if (channel == "CTRL_CMD") commands[i].emplace_back(data, data + size);
    };
    r[i] = loop::avoidance::fly(rc);
  }
  const loop::avoidance::RunResult& a = r[0];
  EXPECT_TRUE(a.completed);
  EXPECT_FALSE(a.collided) << a.collision;
  EXPECT_FALSE(a.entered_danger);
  EXPECT_EQ(a.lockstep_timeouts, 0);
  EXPECT_EQ(a.commands_refused, 0);
  EXPECT_EQ(a.nav_gated, 0);
  // The turn starts at the end of the normal flight area (1 m) as the estimate measures it.
  EXPECT_NEAR(a.activation_travel_m, 1.0, 0.1);
  EXPECT_GT(a.min_wall_distance_m, 1.5);
  // Settled parallel to the wall; the estimate it flew on within a degree of the truth.
  ASSERT_GE(a.heading_rmse_deg, 0.0);
  EXPECT_LT(a.heading_rmse_deg, 1.5);
  EXPECT_LT(a.estimate_rmse_deg, 1.0);
  EXPECT_GT(a.vo_poses, 150);
  // Lock-step: the second flight is the first one.
  ASSERT_FALSE(commands[0].empty());
  EXPECT_EQ(commands[0], commands[1]);
  ASSERT_EQ(a.trajectory.size(), r[1].trajectory.size());
  for (size_t k = 0; k < a.trajectory.size(); ++k) {
    ASSERT_EQ(a.trajectory[k].heading_deg, r[1].trajectory[k].heading_deg) << k;
    ASSERT_EQ(a.trajectory[k].travel_m, r[1].trajectory[k].travel_m) << k;
  }
}

TEST(AvoidanceLoop, ABadScenarioIsRefusedNamingWhatIsWrong) {
  loop::avoidance::RunConfig rc = config(loop::avoidance::Source::kGt, 0.6);
  rc.scene.wall_y_m = 7;  // the room's wall is 5 m ahead of the start
  try {
    loop::avoidance::fly(rc);
    FAIL() << "flew a scenario whose wall is not where it says";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("scene.wall_m is 7"), std::string::npos) << e.what();
  }
  EXPECT_THROW(loop::avoidance::source_from_name("imu"), std::invalid_argument);
  try {
    loop::avoidance::load_avoidance_run(util::Config::parse("sim: {placement: {start_height_m: 1}}\n", "a.yaml"), AERIE_SOURCE_DIR);
    FAIL() << "accepted a scenario without a start";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("a.yaml: sim.placement needs start_x_m"), std::string::npos) << e.what();
  }
}
