// aerie-pilot's node over memq://: one CTRL_CMD per TRACK with its utime, bad inputs counted
// and dropped, operator commands applied or refused with a count.
#include <aerie/control_cmd_t.hpp>
#include <aerie/imu_t.hpp>
#include <aerie/pilot_cmd_t.hpp>
#include <aerie/target_pose_t.hpp>
#include <aerie/track_t.hpp>
#include <gtest/gtest.h>

#include <cmath>
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
