// The door in lock-step (link::SimDoor, tools/link/sim_link.hpp; issue 46 section 4): the
// SimLink adaptor seals and opens every message in process with simulation time; a lock-step
// landing with the tracker on the ground, the door in the link's path and rekeying every
// 10 s of simulation time lands exactly as without the door (the same messages on both
// buses, byte for byte, and the same result).
#include <aerie/track_t.hpp>
#include <gtest/gtest.h>

#include <cstring>

#include "tests/tools/door/split_landing.hpp"

using namespace aerie;
using door_test::landing_split;
using door_test::Message;
using door_test::record;

namespace {

link::SimDoor door_every_10s() {
  link::SimDoor d;
  d.key = std::make_shared<const seal::SecretKey>(seal::SecretKey::generate());
  d.rekey.seconds = 10;
  d.overlap_s = 5;
  // The operator's role as aerie-link's halves have it: the commands going up are signed.
  d.operator_channels = link::kDefaultOperatorChannels;
  d.operator_key = std::make_shared<const seal::OperatorKey>(seal::OperatorKey::generate());
  return d;
}


}  // namespace

TEST(SimDoor, SealsAndOpensEveryMessageAndRekeysOnSimulationTime) {
  link::Split split;
  split.down.channels = "VO_POSE|CAM_STEREO";
  split.up.channels = "PILOT_CMD";
  split.door = door_every_10s();
  link::SplitBus buses(split);
  int got = 0, frames = 0;
  std::vector<uint8_t> frame(752 * 480 * 2 + 64);
  for (size_t i = 0; i < frame.size(); ++i) frame[i] = static_cast<uint8_t>(i * 7);
  buses.on(link::Side::kGround).subscribe_raw("VO_POSE", [&](const uint8_t*, size_t, const bus::ReceiveInfo&) { ++got; }, 10000);
  buses.on(link::Side::kGround).subscribe_raw("CAM_STEREO", [&](const uint8_t* d, size_t n, const bus::ReceiveInfo&) {
    frames += n == frame.size() && std::memcmp(d, frame.data(), n) == 0;
  }, 100);
  const uint8_t pose[40] = {1, 2, 3};
  for (int i = 0; i < 600; ++i) {  // 60 s at 10 Hz
    const int64_t t = i * 100'000;
    buses.settle(t);
    buses.on(link::Side::kAir).publish_raw("VO_POSE", pose, sizeof(pose));
    if (i % 100 == 0) buses.on(link::Side::kAir).publish_raw("CAM_STEREO", frame.data(), frame.size());
    buses.settle(t);
  }
  buses.settle(61'000'000);
  EXPECT_EQ(got, 600);
  EXPECT_EQ(frames, 6);
  const auto* down = buses.link()->door(true);
  ASSERT_NE(down, nullptr);
  EXPECT_EQ(down->receiver.counters().delivered, 606u);
  EXPECT_EQ(down->receiver.counters().opener.refused_total(), 0u);
  EXPECT_GT(down->receiver.counters().fragments, 6u * 10u);
  EXPECT_EQ(down->sender.epoch(), 5u);  // 0 s, 10 s, ..., 50 s (the last message at 59.9 s)
  EXPECT_EQ(down->receiver.peer_epoch(), 5);
}

TEST(SimDoor, ALockStepLandingWithTheDoorRekeyingEvery10sLandsExactlyAsWithout) {
  loop::landing::RunResult plain, sealed;
  const auto a = record(landing_split(2), plain);
  loop::landing::RunConfig rc = landing_split(2);
  rc.split->door = door_every_10s();
  const auto b = record(rc, sealed);

  ASSERT_TRUE(plain.outcome.landed) << plain.final_state;
  EXPECT_GT(plain.sim_s, 20.0) << "long enough for two rekeyings";
  EXPECT_TRUE(sealed.outcome.landed) << sealed.final_state;
  EXPECT_EQ(sealed.final_state, plain.final_state);
  EXPECT_EQ(sealed.score.success, plain.score.success);
  EXPECT_EQ(sealed.score.touchdown_error_m, plain.score.touchdown_error_m);
  EXPECT_EQ(sealed.score.yaw_error_deg, plain.score.yaw_error_deg);
  EXPECT_EQ(sealed.sim_s, plain.sim_s);
  EXPECT_EQ(sealed.descent.size(), plain.descent.size());
  EXPECT_EQ(sealed.target_poses, plain.target_poses);
  EXPECT_EQ(sealed.lockstep_timeouts, plain.lockstep_timeouts);
  EXPECT_EQ(sealed.link_down.delivered, plain.link_down.delivered);
  EXPECT_EQ(sealed.link_up.delivered, plain.link_up.delivered);
  EXPECT_GT(plain.link_up.delivered, 100);
  ASSERT_EQ(a.size(), b.size());
  size_t first_diff = a.size();
  for (size_t i = 0; i < a.size() && first_diff == a.size(); ++i)
    if (!(a[i] == b[i])) first_diff = i;
  EXPECT_EQ(first_diff, a.size()) << "first difference at message " << first_diff << " on "
                                  << (first_diff < a.size() ? a[first_diff].channel : "");
}
