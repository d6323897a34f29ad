// Faults in flight (loop/faults.hpp, docs/faults.md): the spec language, the injector's draws, a
// node killed and respawned on the bus, and one short lock-step landing per fault category —
// the vehicle stays safe, reacts as it must, and the fault did what it says — plus a wrong
// calibration refused at start-up.
#include <aerie/pose_t.hpp>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "air/pilot/pilot_config.hpp"
#include "common/flc/flc_io.hpp"
#include "common/sim/flight/flight_config.hpp"
#include "tests/support/test_support.hpp"
#include "loop/avoidance.hpp"
#include "loop/faults.hpp"
#include "loop/landing.hpp"

using namespace aerie;

namespace {

std::string refusal(const std::string& spec) {
  try {
    loop::faults::parse(spec);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// Seed 1 of the room: take-off done at about 5 s, landed at about 21 s without a fault.
loop::landing::RunConfig landing_with(const std::string& faults) {
  loop::landing::RunConfig rc = loop::landing::load_landing_run(
      util::Config::parse("max_time_s: 60\nwind_m_s: 1\n", "test_faults"), 1, AERIE_SOURCE_DIR);
  rc.faults = loop::faults::parse_list(faults);
  return rc;
}

void expect_safe(const loop::landing::RunResult& r) {
  EXPECT_FALSE(r.outcome.collided) << r.outcome.collision;
  EXPECT_TRUE(r.final_state == "LANDED" || r.final_state == "HOLD" || r.final_state == "ABORTED") << r.final_state;
}

}  // namespace

TEST(FaultSpec, EveryKindParsesAndReadsBack) {
  for (const std::string s : {"kill:track@8+1", "kill:pilot@4~16+1", "camera_stall@6+3", "link_drop@6.5+10",
                              "link_degrade@13+300:500:0.3", "burst@8:10000", "nan_pose:TARGET_POSE@9"})
    EXPECT_EQ(loop::faults::to_string(loop::faults::parse(s)), s);
  const loop::faults::Fault f = loop::faults::parse("link_degrade@4~16+300:500:0.3");
  EXPECT_EQ(f.kind, loop::faults::Kind::LinkDegrade);
  EXPECT_DOUBLE_EQ(f.at_s, 4);
  EXPECT_DOUBLE_EQ(f.at_max_s, 16);
  EXPECT_DOUBLE_EQ(f.duration_s, 300);
  EXPECT_DOUBLE_EQ(f.delay_ms, 500);
  EXPECT_DOUBLE_EQ(f.loss, 0.3);
  EXPECT_EQ(loop::faults::parse_list("none").size(), 0u);
  EXPECT_EQ(loop::faults::parse_list("link_drop@8+5 link_degrade@13+300:500:0.3").size(), 2u);
}

TEST(FaultSpec, BadSpecsAreRefusedNamingWhatIsWrong) {
  EXPECT_NE(refusal("kill@8+1").find("needs a node"), std::string::npos);
  EXPECT_NE(refusal("explode@8").find("unknown kind 'explode'"), std::string::npos);
  EXPECT_NE(refusal("camera_stall@8").find("needs a duration"), std::string::npos);
  EXPECT_NE(refusal("burst@8").find("burst@T:COUNT"), std::string::npos);
  EXPECT_NE(refusal("burst@8+1:10").find("takes no duration"), std::string::npos);
  EXPECT_NE(refusal("link_degrade@8+5:500:1.5").find("loss must be in [0, 1]"), std::string::npos);
  EXPECT_NE(refusal("kill:track@-1+1").find("start time must be a number >= 0, got '-1'"), std::string::npos);
  EXPECT_NE(refusal("camera_stall@9~3+1").find("ends before it starts"), std::string::npos);
  EXPECT_NE(refusal("camera_stall:CAM@3+1").find("takes no target"), std::string::npos);
  EXPECT_NE(refusal("kill:track").find("expected KIND[:TARGET]@TIME"), std::string::npos);
  EXPECT_THROW(loop::faults::Injector(loop::faults::parse_list("kill:track@8+2 kill:track@9+1"), 1), std::invalid_argument);
}

TEST(FaultSpec, TimesGivenAsRangesAreDrawnFromTheSeed) {
  auto drawn = [](uint64_t seed) { return loop::faults::Injector(loop::faults::parse_list("kill:track@4~16+1"), seed).faults()[0].at_s; };
  EXPECT_EQ(drawn(3), drawn(3));
  EXPECT_NE(drawn(3), drawn(4));
  for (uint64_t seed = 1; seed <= 50; ++seed) {
    EXPECT_GE(drawn(seed), 4.0);
    EXPECT_LE(drawn(seed), 16.0);
  }
}

TEST(Respawnable, AKilledNodeLeavesTheBusAndComesBackFresh) {
  struct Counter {
    int seen = 0;
    explicit Counter(bus::Bus& b) {
      b.subscribe<aerie::pose_t>("VO_POSE", [this](const aerie::pose_t&, const bus::ReceiveInfo&) { ++seen; });
    }
  };
  bus::Bus bus("memq://");
  int others = 0;
  bus.subscribe<aerie::pose_t>("VO_POSE", [&](const aerie::pose_t&, const bus::ReceiveInfo&) { ++others; });
  loop::faults::Respawnable<Counter> node(bus, [&] { return std::make_unique<Counter>(bus); });
  auto deliver = [&](int n) {
    for (int i = 0; i < n; ++i) bus.publish("VO_POSE", aerie::pose_t{});
    while (bus.handle(0) > 0) {
    }
  };
  deliver(2);
  EXPECT_EQ(node.get()->seen, 2);
  node.kill();
  EXPECT_EQ(node.get(), nullptr);
  deliver(3);  // nobody left to call: the dead node's subscription is gone
  EXPECT_EQ(bus.subscriptions().size(), 1u);
  node.start();
  deliver(1);
  EXPECT_EQ(node.get()->seen, 1);  // a fresh instance
  EXPECT_EQ(others, 6);
}

TEST(FaultsInFlight, AKilledTrackerIsRespawnedThePilotHoldsAndTheLandingCompletes) {
  const loop::landing::RunResult r = loop::landing::fly(landing_with("kill:track@8+1"));
  expect_safe(r);
  EXPECT_EQ(r.faults.counters.kills, 1);
  EXPECT_EQ(r.faults.counters.respawns, 1);
  EXPECT_GE(r.pilot_stale_holds + r.losses, 1);  // no tracker result for 1 s: HOLD
  EXPECT_TRUE(r.score.success) << r.final_state;
  EXPECT_FALSE(r.dead_at_end);
}

TEST(FaultsInFlight, ADeadPilotLeavesTheAutopilotHoldingAndItsRespawnLands) {
  const loop::landing::RunResult r = loop::landing::fly(landing_with("kill:pilot@8+3"));
  expect_safe(r);
  EXPECT_EQ(r.faults.command_timeouts, 1);  // no command for 1 s: the autopilot hovers (offboard loss)
  EXPECT_TRUE(r.score.success) << r.final_state;
}

TEST(FaultsInFlight, AStalledCameraHoldsThePilotUntilFramesReturn) {
  const loop::landing::RunResult r = loop::landing::fly(landing_with("camera_stall@8+3"));
  expect_safe(r);
  EXPECT_EQ(r.faults.stalled_frames, 60);  // 3 s at 20 Hz
  EXPECT_GE(r.pilot_stale_holds, 1);
  EXPECT_TRUE(r.score.success) << r.final_state;
}

TEST(FaultsInFlight, ALinkDropWithTrackingOnTheGroundHoldsTheVehicle) {
  loop::landing::RunConfig rc = landing_with("link_drop@8+5");
  link::Split split;
  split.nodes = {{"track", link::Side::kGround}};  // images down, the tracker's results up
  split.down.channels = "CAM_DOWN|GT_TRACK";
  split.up.channels = "TRACK|TARGET_POSE";
  split.up.name = "ground->air";
  rc.split = split;
  const loop::landing::RunResult r = loop::landing::fly(rc);
  expect_safe(r);
  EXPECT_GT(r.link_down.dropped_outage, 90);  // 5 s of CAM_DOWN and GT_TRACK at 20 Hz, and what was in flight
  EXPECT_GE(r.pilot_stale_holds, 1);
  EXPECT_TRUE(r.score.success) << r.final_state;
}

TEST(FaultsInFlight, AMalformedBurstIsCountedAndTheLandingGoesOn) {
  const loop::landing::RunResult r = loop::landing::fly(landing_with("burst@8:10000"));
  expect_safe(r);
  EXPECT_EQ(r.faults.counters.burst_messages, 10000);
  EXPECT_GT(r.faults.malformed, 1000);  // random, truncated and hostile-length messages refused by the decoders
  EXPECT_TRUE(r.score.success) << r.final_state;
}

TEST(FaultsInFlight, ANanTargetPoseIsRefusedByThePilot) {
  const loop::landing::RunResult r = loop::landing::fly(landing_with("nan_pose:TARGET_POSE@10"));
  expect_safe(r);
  EXPECT_EQ(r.faults.counters.nan_messages, 1);
  EXPECT_EQ(r.pilot_refused, 1);
  EXPECT_TRUE(r.score.success) << r.final_state;
}

TEST(FaultsInFlight, AFaultedFlightIsAsReproducibleAsACleanOne) {
  const loop::landing::RunResult a = loop::landing::fly(landing_with("kill:track@7~9+1 burst@12:2000"));
  const loop::landing::RunResult b = loop::landing::fly(landing_with("kill:track@7~9+1 burst@12:2000"));
  EXPECT_EQ(a.faults.applied, b.faults.applied);
  EXPECT_EQ(a.outcome.touchdown_position, b.outcome.touchdown_position);
  EXPECT_EQ(a.faults.malformed, b.faults.malformed);
  EXPECT_EQ(a.sim_s, b.sim_s);
}

TEST(FaultsInFlight, TheAvoidanceFlightCompletesThroughAVoRestartAndABurst) {
  loop::avoidance::RunConfig rc =
      loop::avoidance::load_avoidance_run(util::Config::load(AERIE_SOURCE_DIR "/config/avoidance.yaml"), AERIE_SOURCE_DIR);
  rc.controller = flc::load_controller(AERIE_SOURCE_DIR "/config/flc/sfmf.yaml");
  rc.faults = loop::faults::parse_list("kill:vo@3+1 burst@7:5000");
  const loop::avoidance::RunResult r = loop::avoidance::fly(rc);
  EXPECT_FALSE(r.collided) << r.collision;
  EXPECT_FALSE(r.entered_danger);
  EXPECT_TRUE(r.completed);  // aerie-nav bridges the VO's restart (a new VO frame is a new anchor)
  EXPECT_EQ(r.faults.counters.kills, 1);
  EXPECT_EQ(r.faults.counters.respawns, 1);
  EXPECT_EQ(r.faults.counters.burst_messages, 5000);
  EXPECT_GT(r.faults.malformed, 500);
  EXPECT_THROW(
      [&] {
        rc.faults = loop::faults::parse_list("kill:track@3+1");  // no tracker in this flight
        loop::avoidance::fly(rc);
      }(),
      std::invalid_argument);
}

TEST(FaultsInFlight, AvoidanceCompletesThroughAControlOrANavRestart) {
  // A respawned aerie-control re-anchored the manoeuvre where it was and a respawned aerie-nav
  // started a new frame: both flew into the wall, then hovered once aerie-control refused them.
  // Now the respawned aerie-control takes the anchor up from its file and the respawned
  // aerie-nav resumes in its frame from its state file: the turn is completed through either.
  loop::avoidance::RunConfig rc =
      loop::avoidance::load_avoidance_run(util::Config::load(AERIE_SOURCE_DIR "/config/avoidance.yaml"), AERIE_SOURCE_DIR);
  rc.controller = flc::load_controller(AERIE_SOURCE_DIR "/config/flc/sfmf.yaml");
  rc.sim.max_time_s = 20;
  for (const char* fault : {"kill:control@5+1", "kill:nav@6+1"}) {
    rc.faults = loop::faults::parse_list(fault);
    const loop::avoidance::RunResult r = loop::avoidance::fly(rc);
    EXPECT_FALSE(r.collided) << fault << ": " << r.collision;
    EXPECT_FALSE(r.entered_danger) << fault;
    EXPECT_TRUE(r.completed) << fault;
    EXPECT_LT(r.heading_rmse_deg, 2.0) << fault;  // settled along the wall (0.93 deg without a fault)
  }
}

TEST(WrongCalibration, IsRefusedAtStartUpNamingTheFile) {
  const auto dir = test::scratch_dir("faults_calibration");
  const std::string track = std::string(AERIE_BINARY_DIR) + "/bin/aerie-track";
  const std::vector<std::pair<std::string, std::string>> files{
      {"missing.yaml", ""},  // not written
      {"not_yaml.yaml", "{{{ this is not a calibration\n"},
      {"negative_focal.yaml", "%YAML:1.0\n---\nimage_width: 376\nimage_height: 240\n"
                              "K1: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n  data: [-200, 0, 188, 0, 200, 120, 0, 0, 1]\n"}};
  for (const auto& [name, text] : files) {
    const auto calib = dir / name;
    if (!text.empty()) std::ofstream(calib) << text;
    const auto config = dir / ("track_" + name);
    std::ofstream(config) << "node: {camera_channel: CAM_DOWN}\ncamera: {calibration: " << calib.string() << "}\n";
    const auto out = dir / (name + ".txt");
    const std::string cmd = track + " --config " + config.string() + " --lcm-url memq:// > " + out.string() + " 2>&1";
    EXPECT_NE(std::system(cmd.c_str()), 0) << name << " was accepted";
    std::stringstream said;
    said << std::ifstream(out).rdbuf();
    EXPECT_NE(said.str().find(name), std::string::npos) << said.str();
  }
}
