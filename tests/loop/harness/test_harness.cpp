// loop::Harness (issue 51): a run is a function of its configuration and seed — two flights of
// the same landing configuration and seed give identical RunStats and results, a different seed
// does not — and the run loaders refuse a bad key naming the file, the key and its line.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "loop/avoidance.hpp"
#include "loop/landing.hpp"

using namespace aerie;

namespace {

loop::landing::RunConfig short_landing(uint64_t seed) {
  // A split with a delayed, lossy link and a fault: every part of the harness has a say.
  loop::landing::RunConfig rc = loop::landing::load_landing_run(
      util::Config::parse("max_time_s: 14\nwind_m_s: 1\n", "test_harness"), seed, AERIE_SOURCE_DIR);
  rc.frames_after_end = 0;
  link::Split split;
  split.nodes = {{"track", link::Side::kGround}, {"pilot", link::Side::kGround}};
  split.down.channels = "CAM_DOWN|GT_TRACK|IMU";
  split.down.delay_ms = 40;
  split.down.loss = 0.05;
  split.down.seed = 2 * seed - 1;
  split.up.channels = "CTRL_CMD";
  split.up.name = "ground->air";
  split.up.delay_ms = 40;
  split.up.seed = 2 * seed;
  rc.split = split;
  rc.faults = loop::faults::parse_list("camera_stall@6~9+1");
  return rc;
}

void expect_same_stats(const loop::RunStats& a, const loop::RunStats& b) {
  EXPECT_EQ(a.faults.applied, b.faults.applied);
  EXPECT_EQ(a.faults.stalled_frames, b.faults.stalled_frames);
  EXPECT_EQ(a.faults.command_timeouts, b.faults.command_timeouts);
  EXPECT_EQ(a.faults.malformed, b.faults.malformed);
  EXPECT_EQ(a.lockstep_timeouts, b.lockstep_timeouts);
  EXPECT_EQ(a.commands_refused, b.commands_refused);
  for (const auto& [x, y] : {std::pair{a.link_down, b.link_down}, std::pair{a.link_up, b.link_up}}) {
    EXPECT_EQ(x.received, y.received);
    EXPECT_EQ(x.delivered, y.delivered);
    EXPECT_EQ(x.dropped_loss, y.dropped_loss);
    EXPECT_EQ(x.dropped_queue, y.dropped_queue);
    EXPECT_EQ(x.bytes_delivered, y.bytes_delivered);
  }
  EXPECT_EQ(a.sim_s, b.sim_s);  // exactly: lock-step
}

std::string refusal(const std::string& yaml, const std::string& origin) {
  try {
    loop::landing::load_landing_run(util::Config::parse(yaml, origin), 1, AERIE_SOURCE_DIR);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Harness, TheSameConfigurationAndSeedFlyTheSameRun) {
  const loop::landing::RunResult a = loop::landing::fly(short_landing(3));
  const loop::landing::RunResult b = loop::landing::fly(short_landing(3));
  expect_same_stats(a, b);
  EXPECT_GT(a.sim_s, 10.0);
  EXPECT_GT(a.link_down.delivered, 100);   // the split carried the images down ...
  EXPECT_GT(a.link_down.dropped_loss, 0);  // ... losing some
  EXPECT_GT(a.link_up.delivered, 100);     // and the commands up
  EXPECT_GT(a.faults.stalled_frames, 0);
  EXPECT_EQ(a.faults.applied, b.faults.applied);
  EXPECT_EQ(a.final_state, b.final_state);
  EXPECT_EQ(a.target_poses, b.target_poses);
  ASSERT_EQ(a.descent.size(), b.descent.size());
  for (size_t i = 0; i < a.descent.size(); ++i) {
    EXPECT_EQ(a.descent[i].ex, b.descent[i].ex) << i;
    EXPECT_EQ(a.descent[i].ey, b.descent[i].ey) << i;
  }
  // Another seed: another world, another draw of the fault's time.
  const loop::landing::RunResult c = loop::landing::fly(short_landing(4));
  EXPECT_NE(c.faults.applied, a.faults.applied);
}

TEST(Harness, ARunConfigurationCarriesItsSeed) {
  const loop::landing::RunConfig rc = short_landing(7);
  EXPECT_EQ(rc.seed, 7u);
  EXPECT_EQ(rc.sim.seed, 7u);
  EXPECT_EQ(rc.track.seed, 7u);
}

TEST(Loaders, AnUnknownKeyIsRefusedNamingTheFileTheKeyAndItsLine) {
  const std::string e = refusal("max_time_s: 14\nwind: 1\n", "bad_landing.yaml");
  EXPECT_NE(e.find("bad_landing.yaml"), std::string::npos) << e;
  EXPECT_NE(e.find("'wind'"), std::string::npos) << e;
  EXPECT_NE(e.find("line 2"), std::string::npos) << e;
  const std::string range = refusal("wind_m_s: 30\n", "windy.yaml");
  EXPECT_NE(range.find("windy.yaml"), std::string::npos) << range;
  EXPECT_NE(range.find("wind_m_s"), std::string::npos) << range;
  EXPECT_NE(range.find("line 1"), std::string::npos) << range;
  const std::string via = refusal("via: radio\n", "via.yaml");
  EXPECT_NE(via.find("via.yaml"), std::string::npos) << via;
  EXPECT_NE(via.find("'via'"), std::string::npos) << via;
  EXPECT_NE(via.find("direct, mavlink-offboard or mavlink-precland"), std::string::npos) << via;
  const std::string tracker = refusal("tracker: crystal-ball\n", "tracker.yaml");
  EXPECT_NE(tracker.find("unknown tracker 'crystal-ball'"), std::string::npos) << tracker;
  const std::string missing = refusal("sim: config/sim/nowhere.yaml\n", "missing.yaml");
  EXPECT_NE(missing.find("nowhere.yaml"), std::string::npos) << missing;
  // The avoidance run's loader, the same way.
  try {
    loop::avoidance::load_avoidance_run(util::Config::parse("sim: {}\nscene: {}\nspeed: 1\n", "bad_avoidance.yaml"),
                                        AERIE_SOURCE_DIR);
    ADD_FAILURE() << "an unknown key was accepted";
  } catch (const std::runtime_error& err) {
    const std::string m = err.what();
    EXPECT_NE(m.find("bad_avoidance.yaml"), std::string::npos) << m;
    EXPECT_NE(m.find("speed"), std::string::npos) << m;
    EXPECT_NE(m.find("line 3"), std::string::npos) << m;
  }
}
