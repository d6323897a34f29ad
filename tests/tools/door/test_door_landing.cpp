// The door in lock-step (link::SimDoor, tools/link/sim_link.hpp; issue 46 section 4): the
// SimLink adaptor seals and opens every message in process with simulation time; a lock-step
// landing with the tracker on the ground, the door in the link's path and rekeying every
// 10 s of simulation time lands exactly as without the door (the same messages on both
// buses, byte for byte, and the same result).
#include <aerie/track_t.hpp>
#include <gtest/gtest.h>

#include <cstring>

#include "air/pilot/pilot_config.hpp"
#include "common/sim/flight/flight_config.hpp"
#include "tools/landing/landing_run.hpp"
#include "tools/link/sim_link.hpp"

using namespace aerie;

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

struct Message {
  link::Side side;
  std::string channel;
  std::vector<uint8_t> bytes;
  bool operator==(const Message&) const = default;
};

landing::RunConfig landing_split(uint64_t seed) {
  landing::RunConfig rc;
  rc.sim = sim::load_flight_config(util::Config::load(AERIE_SOURCE_DIR "/config/sim/landing_room.yaml"));
  rc.sim.seed = seed;
  rc.sim.max_time_s = 60;
  rc.track = track::node_options(util::Config::load(AERIE_SOURCE_DIR "/config/track_landing.yaml"));
  rc.track.tracker = "amcmr-ct";
  rc.pilot = pilot::load_pilot_config(util::Config::load(AERIE_SOURCE_DIR "/config/pilot.yaml"));
  link::Split split;
  split.nodes = {{"track", link::Side::kGround}};  // images down, the tracker's results up
  split.down.channels = "CAM_DOWN|GT_TRACK";
  split.down.delay_ms = 20;
  split.down.jitter_ms = 3;
  split.down.seed = 3;
  split.up.channels = "TRACK|TARGET_POSE";
  split.up.name = "ground->air";
  split.up.delay_ms = 20;
  split.up.seed = 4;
  rc.split = split;
  return rc;
}

// Every message on both buses; TRACK with its processing time (wall clock) zeroed.
std::vector<Message> record(landing::RunConfig rc, landing::RunResult& result) {
  std::vector<Message> out;
  rc.on_message = [&](link::Side side, const std::string& channel, const uint8_t* data, size_t size, int64_t) {
    Message m{side, channel, {data, data + size}};
    if (channel == "TRACK") {
      aerie::track_t t;
      if (t.decode(data, 0, static_cast<int>(size)) > 0) {
        t.processing_ms = 0;
        m.bytes.resize(static_cast<size_t>(t.getEncodedSize()));
        t.encode(m.bytes.data(), 0, static_cast<int>(m.bytes.size()));
      }
    }
    out.push_back(std::move(m));
  };
  result = landing::fly(rc);
  return out;
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
  landing::RunResult plain, sealed;
  const auto a = record(landing_split(2), plain);
  landing::RunConfig rc = landing_split(2);
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
