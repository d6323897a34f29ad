// util::MessageClock, the message-time policy of every node: jumps, outliers, re-synchronisation,
// staleness; and bus::InputClock, which reports it in a node's status. Message time only.
#include <gtest/gtest.h>

#include <limits>

#include "common/bus/input_clock.hpp"
#include "common/util/message_clock.hpp"

using aerie::util::MessageClock;
using aerie::util::MessageClockConfig;
using V = MessageClock::Verdict;

namespace {

constexpr int64_t kS = 1'000'000;

MessageClockConfig config() {
  MessageClockConfig c;
  c.max_jump_us = 10 * kS;
  c.resync_messages = 3;
  c.stale_timeout_us = 2 * kS;
  return c;
}

}  // namespace

TEST(MessageClock, AcceptsSmallStepsEitherWayAndKeepsTheNewest) {
  MessageClock c("CAM", config());
  EXPECT_EQ(c.observe(100 * kS, 0).verdict, V::kAccepted);  // the first message sets the time base
  EXPECT_EQ(c.observe(100 * kS + 50'000, 0).verdict, V::kAccepted);
  EXPECT_EQ(c.observe(99 * kS, 0).verdict, V::kAccepted);  // 1 s back: reordering, not a restart
  EXPECT_EQ(c.observe(110 * kS + 50'000, 0).verdict, V::kAccepted);  // exactly the bound ahead
  EXPECT_EQ(c.newest(), 110 * kS + 50'000);
  EXPECT_EQ(c.held(), 0);
}

TEST(MessageClock, OneOutlierIsHeldAndNeverMovesTheClock) {
  MessageClock c("VO_POSE", config());
  c.observe(1 * kS, 0);
  for (int64_t bogus : {std::numeric_limits<int64_t>::max(), std::numeric_limits<int64_t>::min(), -20 * kS, int64_t{0}}) {
    if (bogus == 0) bogus = c.newest() + 10 * kS + 1;  // just beyond the bound
    const auto r = c.observe(bogus, 0);
    EXPECT_EQ(r.verdict, V::kHeld) << bogus;
    EXPECT_NE(r.reason.find("VO_POSE utime " + std::to_string(bogus) + " jumps"), std::string::npos) << r.reason;
    EXPECT_NE(r.reason.find("1 of 3"), std::string::npos) << r.reason;
    // The real messages after it continue the old time base at once.
    EXPECT_EQ(c.observe(c.newest() + 33'333, 0).verdict, V::kAccepted);
  }
  EXPECT_NE(c.observe(std::numeric_limits<int64_t>::max(), 0).reason.find("forwards"), std::string::npos);
  EXPECT_EQ(c.held(), 5);
  EXPECT_EQ(c.resyncs(), 0);
  EXPECT_EQ(c.newest(), 1 * kS + 4 * 33'333);
}

TEST(MessageClock, AJumpForwardsResynchronisesAfterNConsistentMessages) {
  MessageClock c("CAM", config());
  c.observe(1 * kS, 0);
  // The camera comes back after 25 s: messages 1 and 2 of the new time are held, the 3rd re-synchronises.
  EXPECT_EQ(c.observe(26 * kS, 0).verdict, V::kHeld);
  EXPECT_EQ(c.observe(26 * kS + 33'333, 0).verdict, V::kHeld);
  const auto r = c.observe(26 * kS + 66'666, 0);
  EXPECT_EQ(r.verdict, V::kResynced);
  EXPECT_NE(r.reason.find("forwards 25.0667 s"), std::string::npos) << r.reason;
  EXPECT_EQ(c.newest(), 26 * kS + 66'666);
  EXPECT_EQ(c.observe(26 * kS + 99'999, 0).verdict, V::kAccepted);
  EXPECT_EQ(c.resyncs(), 1);
  EXPECT_EQ(c.held(), 2);
}

TEST(MessageClock, ABackwardsJumpIsARestartAndResynchronises) {
  MessageClock c("CAM", config());
  for (int k = 0; k < 10; ++k) c.observe(500 * kS + k * 50'000, 0);
  // The source restarts from t = 0.
  EXPECT_EQ(c.observe(0, 0).verdict, V::kHeld);
  EXPECT_NE(c.observe(50'000, 0).reason.find("backwards"), std::string::npos);
  EXPECT_EQ(c.observe(100'000, 0).verdict, V::kResynced);
  EXPECT_EQ(c.observe(150'000, 0).verdict, V::kAccepted);
  EXPECT_EQ(c.newest(), 150'000);
}

TEST(MessageClock, AnInterruptedConfirmationStartsAgain) {
  MessageClock c("CAM", config());
  c.observe(1 * kS, 0);
  EXPECT_EQ(c.observe(100 * kS, 0).verdict, V::kHeld);
  EXPECT_EQ(c.observe(200 * kS, 0).verdict, V::kHeld);  // another time again: 1 of 3 once more
  EXPECT_EQ(c.observe(200 * kS + 1, 0).verdict, V::kHeld);
  EXPECT_EQ(c.observe(1 * kS + 1, 0).verdict, V::kAccepted);  // the old base: outliers forgotten
  EXPECT_EQ(c.observe(200 * kS + 2, 0).verdict, V::kHeld);
  MessageClockConfig one = config();
  one.resync_messages = 1;  // N = 1: re-synchronise at once
  MessageClock d("CAM", one);
  d.observe(1 * kS, 0);
  EXPECT_EQ(d.observe(100 * kS, 0).verdict, V::kResynced);
}

TEST(MessageClock, StaleOnTheNodeClockAfterTheTimeoutOnceReported) {
  MessageClock c("CAM", config());
  EXPECT_FALSE(c.stale(100 * kS));  // nothing received yet: not an outage
  c.observe(7, 10 * kS);
  EXPECT_FALSE(c.stale(12 * kS));
  EXPECT_FALSE(c.stale_change(12 * kS));
  EXPECT_TRUE(c.stale(12 * kS + 1));
  const auto went = c.stale_change(13 * kS);
  ASSERT_TRUE(went);
  EXPECT_EQ(*went, "CAM stale: no message for 3 s (timeout 2 s)");
  EXPECT_FALSE(c.stale_change(20 * kS));  // reported once
  c.observe(25 * kS, 30 * kS);            // held (a jump) does not end the outage...
  EXPECT_TRUE(c.stale(30 * kS));
  c.observe(30, 30 * kS);                 // ...an accepted message does
  const auto back = c.stale_change(30 * kS);
  ASSERT_TRUE(back);
  EXPECT_EQ(*back, "");
}

TEST(MessageClock, ConfigHasRangesAndStrictKeys) {
  using aerie::util::Config;
  const auto c = MessageClockConfig::from_config(
      Config::parse("message_time:\n  max_jump_s: 5\n  resync_messages: 4\n  stale_timeout_s: 0.5\n", "n.yaml")
          .section("message_time"));
  EXPECT_EQ(c.max_jump_us, 5 * kS);
  EXPECT_EQ(c.resync_messages, 4);
  EXPECT_EQ(c.stale_timeout_us, 500'000);
  const auto d = MessageClockConfig::from_config(Config().section("message_time"));
  EXPECT_EQ(d.max_jump_us, 10 * kS);
  auto refusal = [](const std::string& text) {
    try {
      MessageClockConfig::from_config(Config::parse(text, "n.yaml").section("message_time"));
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(refusal("message_time:\n  max_jump_s: 1e308\n").find("max_jump_s"), std::string::npos);
  EXPECT_NE(refusal("message_time:\n  max_jump_s: 0\n").find("valid range"), std::string::npos);
  EXPECT_NE(refusal("message_time:\n  stale_timeout_s: .nan\n").find("stale_timeout_s"), std::string::npos);
  EXPECT_NE(refusal("message_time:\n  resync_messages: 0\n").find("resync_messages"), std::string::npos);
  EXPECT_NE(refusal("message_time:\n  max_jmp_s: 3\n").find("max_jmp_s"), std::string::npos);
}

TEST(InputClock, ReportsJumpsResyncsAndOutagesInTheStatus) {
  aerie::bus::Bus bus("memq://");
  aerie::bus::StatusReporter status(bus, "node");
  aerie::bus::InputClock clock(status, "CAM_LEFT", config());
  EXPECT_EQ(status.counter("CAM_LEFT.stale"), 0);
  clock.observe(1 * kS, 1 * kS);
  clock.check(2 * kS);
  EXPECT_EQ(status.counter("CAM_LEFT.stale"), 0);
  clock.check(27 * kS);  // 25 s outage
  EXPECT_EQ(status.counter("CAM_LEFT.stale"), 1);
  EXPECT_EQ(status.counter("CAM_LEFT.outages"), 1);
  EXPECT_EQ(status.message(), "CAM_LEFT stale: no message for 26 s (timeout 2 s)");
  EXPECT_FALSE(clock.observe(26 * kS, 27 * kS).accepted());
  EXPECT_EQ(status.counter("CAM_LEFT.time_jumps"), 1);
  EXPECT_FALSE(clock.observe(26 * kS + 1, 27 * kS).accepted());
  EXPECT_TRUE(clock.observe(26 * kS + 2, 27 * kS).accepted());
  EXPECT_EQ(status.counter("CAM_LEFT.time_resyncs"), 1);
  EXPECT_EQ(status.counter("CAM_LEFT.stale"), 0);
  EXPECT_NE(status.message().find("CAM_LEFT re-synchronised"), std::string::npos) << status.message();
}

// |a - b| <= limit over the whole int64 range: the subtraction a hostile stamp overflowed
// (docs/fuzz.md, finding 6).
TEST(Within, ExactAtTheLimitAndOverflowFreeAtTheExtremes) {
  constexpr int64_t lo = std::numeric_limits<int64_t>::min(), hi = std::numeric_limits<int64_t>::max();
  EXPECT_TRUE(aerie::util::within(1000, 1020, 20));
  EXPECT_TRUE(aerie::util::within(1020, 1000, 20));
  EXPECT_FALSE(aerie::util::within(1000, 1021, 20));
  EXPECT_FALSE(aerie::util::within(1021, 1000, 20));
  EXPECT_FALSE(aerie::util::within(lo, 0, 20000));
  EXPECT_FALSE(aerie::util::within(0, lo, 20000));
  EXPECT_FALSE(aerie::util::within(lo, hi, 20000));
  EXPECT_FALSE(aerie::util::within(hi, lo, hi));  // 2^64 - 1 apart: beyond any int64 limit
  EXPECT_TRUE(aerie::util::within(lo, lo + 5, 5));
  EXPECT_TRUE(aerie::util::within(hi, hi - 5, 5));
  EXPECT_TRUE(aerie::util::within(-1, hi - 1, hi));
}
