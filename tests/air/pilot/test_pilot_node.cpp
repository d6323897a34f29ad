// aerie-pilot's node over memq://: one CTRL_CMD per TRACK with its utime, bad inputs counted
// and dropped, operator commands applied or refused with a count.
#include <aerie/control_cmd_t.hpp>
#include <aerie/imu_t.hpp>
#include <aerie/pilot_cmd_t.hpp>
#include <aerie/target_pose_t.hpp>
#include <aerie/track_t.hpp>
#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "air/pilot/node/pilot_node.hpp"
#include "air/pilot/pilot_config.hpp"

using namespace aerie;

namespace {

// aerie-pilot with the shipped config on memq://, and the commands it publishes.
struct PilotOnBus {
  bus::Bus bus{"memq://"};
  int64_t now_us = 0;  // the node's clock
  pilot::PilotNode node{bus, pilot::load_pilot_config(util::Config::load(AERIE_SOURCE_DIR "/config/pilot.yaml")), {},
                        [this] { return now_us; }};
  std::vector<aerie::control_cmd_t> cmds;
  PilotOnBus() {
    bus.subscribe<aerie::control_cmd_t>("CTRL_CMD", [this](const aerie::control_cmd_t& m, const bus::ReceiveInfo&) {
      cmds.push_back(m);
    });
  }
  void drain() {
    while (bus.handle(0) > 0) {
    }
  }
};

}  // namespace

TEST(PilotNode, AnswersEachTrackAndCountsBadInputs) {
  PilotOnBus p;
  auto& [bus, now_us, node, cmds] = p;
  auto drain = [&] { p.drain(); };
  aerie::track_t t{};
  t.status = aerie::track_t::IDLE;
  for (int k = 1; k <= 3; ++k) {
    t.utime = k * 50000;
    t.seq = k;
    bus.publish("TRACK", t);
    drain();
  }
  ASSERT_EQ(cmds.size(), 3u);
  EXPECT_EQ(cmds.back().utime, 150000);
  EXPECT_EQ(cmds.back().mode, aerie::control_cmd_t::TAKEOFF);

  aerie::target_pose_t bad{};
  bad.utime = 200000;
  bad.position[0] = std::nan("");
  bad.position[2] = 2.0;
  bus.publish("TARGET_POSE", bad);
  t.status = 7;  // unknown
  t.utime = 200000;
  bus.publish("TRACK", t);
  aerie::pilot_cmd_t op{};
  op.command = aerie::pilot_cmd_t::RESUME;  // not in TAKEOFF
  op.source = "test";
  bus.publish("PILOT_CMD", op);
  op.command = 42;
  bus.publish("PILOT_CMD", op);
  op.command = aerie::pilot_cmd_t::ABORT;
  bus.publish("PILOT_CMD", op);
  drain();
  EXPECT_EQ(node.counter("TARGET_POSE_refused"), 1);
  EXPECT_EQ(node.counter("TRACK_refused"), 1);
  EXPECT_EQ(node.counter("operator_refused"), 2);
  EXPECT_EQ(node.counter("operator_accepted"), 1);
  EXPECT_EQ(node.pilot().state(), pilot::State::Abort);
  EXPECT_EQ(cmds.size(), 3u);  // the bad TRACK made no command
}

TEST(PilotNode, OneBogusStampIsHeldAndNeverMovesItsClock) {
  // A corrupt or hostile message stamped far from its source's time (fault campaign: a
  // bit-flipped IMU stamp made the pilot see its tracker silent for 1.4e8 s and abort).
  PilotOnBus p;
  auto& [bus, now_us, node, cmds] = p;
  auto drain = [&] { p.drain(); };
  aerie::track_t t{};
  t.status = aerie::track_t::IDLE;
  aerie::imu_t imu{};
  imu.orientation_valid = true;
  imu.orientation[0] = 1;
  for (int k = 1; k <= 4; ++k) {
    imu.utime = t.utime = k * 50000;
    bus.publish("IMU", imu);
    bus.publish("TRACK", t);
    drain();
  }
  ASSERT_EQ(cmds.size(), 4u);
  imu.utime = t.utime = 200000 + (int64_t{1} << 40);  // one high bit flipped in each
  bus.publish("IMU", imu);
  bus.publish("TRACK", t);
  drain();
  EXPECT_EQ(node.counter("IMU_time_held"), 1);
  EXPECT_EQ(node.counter("TRACK_time_held"), 1);
  EXPECT_EQ(cmds.size(), 4u);  // nothing answered the bogus TRACK, no stale tick from the bogus IMU
  imu.utime = t.utime = 250000;
  bus.publish("IMU", imu);
  bus.publish("TRACK", t);
  drain();
  ASSERT_EQ(cmds.size(), 5u);
  EXPECT_EQ(cmds.back().utime, 250000);
  EXPECT_EQ(node.pilot().state(), pilot::State::Takeoff);
  EXPECT_EQ(node.pilot().status().stale_holds, 0);
}

TEST(PilotNode, AgesEachTrackOnItsOwnClockWhenTheClocksAreComparable) {
  // A frame 0.5 s old (a delayed link) is aged; one stamped 2 minutes from the node's clock
  // is from another time base (a lock-step simulation, a replay) and is not.
  PilotOnBus p;
  auto& [bus, now_us, node, cmds] = p;
  aerie::track_t t{};
  t.status = aerie::track_t::IDLE;
  for (int k = 1; k <= 3; ++k) {
    t.utime = 1'000'000'000 + k * 50000;
    now_us = t.utime + 500000;
    bus.publish("TRACK", t);
    p.drain();
  }
  EXPECT_EQ(node.pilot().status().aged_results, 3);
  for (int k = 4; k <= 6; ++k) {
    t.utime = 1'000'000'000 + k * 50000;
    now_us = t.utime + 120'000'000;
    bus.publish("TRACK", t);
    p.drain();
  }
  EXPECT_EQ(node.pilot().status().aged_results, 3);
  t.utime += 50000;
  now_us = t.utime + 100000;  // 0.1 s: within the limit
  bus.publish("TRACK", t);
  p.drain();
  EXPECT_EQ(node.pilot().status().aged_results, 3);
  EXPECT_EQ(cmds.size(), 7u);  // every TRACK answered, aged or not (lock-step)
}

TEST(PilotNode, ReplayedTracksAreAgedOnTheLogsTimeNotTheWallClock) {
  // Issue 49: a log replayed 7.5 s after it was recorded; on the wall clock every TRACK is 7.5 s
  // old (HOLD); aerie-pilot --replay ages it against the newest tracker time seen.
  const auto config = pilot::load_pilot_config(util::Config::load(AERIE_SOURCE_DIR "/config/pilot.yaml"));
  for (const bool replay : {false, true}) {
    bus::Bus bus("memq://");
    pilot::PilotNodeOptions opt;
    opt.message_clock = replay;
    pilot::PilotNode node(bus, config, opt, util::wall_utime);
    aerie::track_t t{};
    t.status = aerie::track_t::IDLE;
    const int64_t t0 = util::wall_utime() - 7'500'000;
    for (int k = 0; k < 3; ++k) {
      t.utime = t0 + k * 50'000;
      bus.publish("TRACK", t);
      while (bus.handle(0) > 0) {
      }
    }
    EXPECT_EQ(node.pilot().status().aged_results, replay ? 0 : 3) << replay;
    if (!replay) continue;
    t.utime = t0 + 100'000 - 500'000;  // 0.5 s behind the newest: late on the log's time too
    bus.publish("TRACK", t);
    while (bus.handle(0) > 0) {
    }
    EXPECT_EQ(node.pilot().status().aged_results, 1);
  }
}

namespace {
// The default logger's output in a string while it lives.
struct CapturedLog {
  std::ostringstream text;
  std::shared_ptr<spdlog::logger> previous = spdlog::default_logger();
  CapturedLog() {
    auto logger = std::make_shared<spdlog::logger>("capture", std::make_shared<spdlog::sinks::ostream_sink_mt>(text));
    logger->set_pattern("%l %v");
    logger->set_level(spdlog::level::info);
    spdlog::set_default_logger(logger);
  }
  ~CapturedLog() { spdlog::set_default_logger(previous); }
};
}  // namespace

// Issue 46: the pilot logged PILOT_CMD's `source`, which the sender chooses, as if it named the
// operator. Until commands come through the sealed link, the log says it is unauthenticated,
// and a source cannot forge log lines.
TEST(PilotNode, OperatorCommandsAreLoggedWithAnUnauthenticatedSource) {
  CapturedLog log;
  {
    PilotOnBus p;
    aerie::track_t t{};  // the first TRACK starts the mission (TAKEOFF): ABORT then applies
    t.status = aerie::track_t::IDLE;
    t.utime = 50000;
    p.bus.publish("TRACK", t);
    p.drain();
    aerie::pilot_cmd_t op{};
    op.command = aerie::pilot_cmd_t::ABORT;
    op.source = "x";
    p.bus.publish("PILOT_CMD", op);
    op.command = aerie::pilot_cmd_t::LAND;
    op.source = "ground\ninfo PILOT_CMD ABORT (source \"operator\") ok";
    p.bus.publish("PILOT_CMD", op);
    op.command = 9;
    op.source = std::string(100, 'y');
    p.bus.publish("PILOT_CMD", op);
    p.drain();
    EXPECT_GE(p.node.counter("operator_accepted"), 1);  // the ABORT (and the LAND, which applies after it)
    EXPECT_EQ(p.node.counter("operator_accepted") + p.node.counter("operator_refused"), 3);
  }
  const std::string text = log.text.str();
  EXPECT_NE(text.find("info PILOT_CMD ABORT (source \"x\", unauthenticated) accepted: "), std::string::npos) << text;
  EXPECT_NE(text.find("PILOT_CMD LAND (source \"ground\\x0ainfo PILOT_CMD ABORT (source \\\"operator\\\") ok\", "
                      "unauthenticated) "),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("warning PILOT_CMD 9 (source \"" + std::string(64, 'y') + "...\", unauthenticated): unknown command"),
            std::string::npos)
      << text;
  // One line per command: the newline in the forged source did not start a line of its own.
  int lines = 0;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines += line.find("unauthenticated)") != std::string::npos;
  EXPECT_EQ(lines, 3) << text;
  EXPECT_EQ(text.find("\ninfo PILOT_CMD ABORT (source \"operator\""), std::string::npos) << text;
}
