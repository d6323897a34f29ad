// Closed-loop landings: lock-step determinism (the same seed gives the same messages, byte
// for byte) and a landing with a tracker of each family.
#include <aerie/track_t.hpp>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/support/lockstep_bytes.hpp"
#include "loop/landing.hpp"
#include "tests/loop/landing/short_landing.hpp"

using namespace aerie;

namespace {

loop::landing::RunConfig config(const std::string& tracker, uint64_t seed) {
  return loop::landing::load_landing_run(
      util::Config::parse("tracker: " + tracker + "\nmax_time_s: 60\n", "test_landing_loop"), seed, AERIE_SOURCE_DIR);
}

struct Message {
  std::string channel;
  std::vector<uint8_t> bytes;
  bool operator==(const Message&) const = default;
};

// Every message of a run; TRACK with its processing time (wall clock) zeroed.
std::vector<Message> record(loop::landing::RunConfig rc, loop::landing::RunResult* result = nullptr) {
  std::vector<Message> out;
  rc.on_message = [&](link::Side, const std::string& channel, const uint8_t* data, size_t size, int64_t) {
    out.push_back(Message{channel, test::comparable_bytes(channel, data, size)});
  };
  const loop::landing::RunResult r = loop::landing::fly(rc);
  if (result) *result = r;
  return out;
}

}  // namespace

TEST(LandingLoop, LockStepRunsWithTheSameSeedGiveTheSameMessages) {
  loop::landing::RunConfig rc = config("amcmr-ct", 5);
  rc.sim.wind.mean_m_s = 1.0;
  rc.sim.vibration.enabled = true;
  loop::landing::RunResult ra, rb;
  const std::vector<Message> a = record(rc, &ra), b = record(rc, &rb);
  ASSERT_TRUE(ra.outcome.ended());
  EXPECT_EQ(ra.lockstep_timeouts, 0);
  ASSERT_EQ(a.size(), b.size());
  size_t first_diff = a.size();
  for (size_t i = 0; i < a.size() && first_diff == a.size(); ++i)
    if (!(a[i] == b[i])) first_diff = i;
  EXPECT_EQ(first_diff, a.size()) << "first difference at message " << first_diff << " on " << a[first_diff].channel;
  EXPECT_EQ(ra.score.touchdown_error_m, rb.score.touchdown_error_m);
  // Every channel of the loop took part.
  for (const char* ch : {"IMU", "CAM_DOWN", "GT_TRACK", "SIM_STATE", "TRACK", "TARGET_POSE", "CTRL_CMD", "PILOT_STATE"}) {
    bool seen = false;
    for (const auto& m : a) seen |= m.channel == ch;
    EXPECT_TRUE(seen) << ch;
  }
}

class LandingPerTracker : public ::testing::TestWithParam<const char*> {};

TEST_P(LandingPerTracker, LandsOnThePad) {
  loop::landing::RunConfig rc = config(GetParam(), 2);
  loop::landing::test::start_close(rc);
  const loop::landing::RunResult r = loop::landing::fly(rc);
  loop::landing::test::expect_landed_on_the_pad(r);
  EXPECT_EQ(r.commands_refused, 0);
}

// One tracker per family: IPSL (hierarchical), CT (AMCMR), MIL (AM3), correlation filter, OpenCV.
INSTANTIATE_TEST_SUITE_P(Families, LandingPerTracker, ::testing::Values("ipsl-mr", "amcmr-ct", "am3", "dcf", "opencv-csrt"),
                         [](const auto& info) {
                           std::string n = info.param;
                           for (char& c : n)
                             if (c == '-') c = '_';
                           return n;
                         });

// The product through MAVLink: aerie-mavlink's node and the simulator's autopilot (PX4 and
// ArduCopter) joined by a signed MAVLink 2 byte stream, in lock-step.
struct ViaCase {
  loop::landing::Via via;
  sim::autopilot::Personality autopilot;
};

class LandingThroughMavlink : public ::testing::TestWithParam<ViaCase> {};

TEST_P(LandingThroughMavlink, LandsOnThePadAndRepeatsItselfExactly) {
  loop::landing::RunConfig rc = config("amcmr-ct", 3);
  rc.sim.wind.mean_m_s = 1.0;
  rc.sim.vibration.enabled = true;
  rc.via = GetParam().via;
  rc.autopilot = GetParam().autopilot;
  loop::landing::RunResult ra, rb;
  const std::vector<Message> a = record(rc, &ra), b = record(rc, &rb);
  EXPECT_TRUE(ra.score.success) << ra.final_state << ", autopilot " << ra.mavlink.autopilot_mode;  // on the pad, in time
  EXPECT_EQ(ra.mavlink.frames_refused, 0);      // every frame of both sides verified
  EXPECT_EQ(ra.mavlink.commands_timed_out, 0);
  EXPECT_GT(ra.mavlink.commands_accepted, 3);   // arm, take-off, mode, land at least
  if (rc.via == loop::landing::Via::MavlinkOffboard) {
    EXPECT_GT(ra.mavlink.setpoints, 100);
  } else {
    EXPECT_GT(ra.mavlink.landing_targets, 5);  // the autopilot landed on Aerie's LANDING_TARGET
  }
  ASSERT_EQ(a.size(), b.size());  // lock-step over MAVLink: the same messages, byte for byte
  EXPECT_TRUE(a == b);
  EXPECT_EQ(ra.score.touchdown_error_m, rb.score.touchdown_error_m);
  bool state_seen = false;
  for (const auto& m : a) state_seen |= m.channel == "AUTOPILOT_STATE";
  EXPECT_TRUE(state_seen);
}

INSTANTIATE_TEST_SUITE_P(
    Paths, LandingThroughMavlink,
    ::testing::Values(ViaCase{loop::landing::Via::MavlinkOffboard, sim::autopilot::Personality::Px4},
                      ViaCase{loop::landing::Via::MavlinkPrecland, sim::autopilot::Personality::Px4},
                      ViaCase{loop::landing::Via::MavlinkOffboard, sim::autopilot::Personality::ArduCopter},
                      ViaCase{loop::landing::Via::MavlinkPrecland, sim::autopilot::Personality::ArduCopter}),
    [](const ::testing::TestParamInfo<ViaCase>& info) {
      return std::string(info.param.via == loop::landing::Via::MavlinkOffboard ? "Offboard" : "Precland") +
             (info.param.autopilot == sim::autopilot::Personality::Px4 ? "Px4" : "ArduCopter");
    });
