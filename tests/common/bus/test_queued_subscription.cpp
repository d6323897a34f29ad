// Queued subscriptions (Bus::subscribe_queued): every message that reaches the subscription is
// either handed to the handler or counted as a queue overflow, exactly; sequence gaps count only
// what never reached it; the status names both.
#include <gtest/gtest.h>

#include <aerie/pose_t.hpp>
#include <aerie/process_status_t.hpp>

#include <map>
#include <vector>

#include "common/bus/bus.hpp"
#include "common/bus/status.hpp"

namespace {

// Any message with a seq does (image_t, as bot_core's, has none).
aerie::pose_t frame(int64_t seq) {
  aerie::pose_t m{};
  m.utime = 1000 + seq;
  m.seq = seq;
  m.position[0] = static_cast<double>(seq);
  return m;
}

void drain(aerie::bus::Bus& bus) {
  while (bus.handle(0) > 0) {
  }
}

}  // namespace

TEST(QueuedSubscription, ABurstLargerThanTheQueueIsCountedExactlyAndTheLatestKept) {
  aerie::bus::Bus bus("memq://");
  std::vector<int64_t> got;
  auto& sub = bus.subscribe_queued<aerie::pose_t>(
      "CAM", [&](const aerie::pose_t& m, const aerie::bus::ReceiveInfo&) { got.push_back(m.seq); }, 4);
  for (int64_t s = 0; s < 10; ++s) bus.publish("CAM", frame(s));
  drain(bus);
  EXPECT_EQ(got, (std::vector<int64_t>{6, 7, 8, 9}));
  EXPECT_EQ(sub.counters().received, 10);
  EXPECT_EQ(sub.counters().queue_overflows, 6);
  EXPECT_EQ(sub.counters().sequence_gaps, 0);  // nothing was lost before the subscription
  EXPECT_EQ(sub.queued(), 0u);
}

TEST(QueuedSubscription, DropNewestKeepsTheFirstMessages) {
  aerie::bus::Bus bus("memq://");
  std::vector<int64_t> got;
  auto& sub = bus.subscribe_queued<aerie::pose_t>(
      "CAM", [&](const aerie::pose_t& m, const aerie::bus::ReceiveInfo&) { got.push_back(m.seq); }, 3,
      aerie::bus::Overflow::kDropNewest);
  for (int64_t s = 0; s < 8; ++s) bus.publish("CAM", frame(s));
  drain(bus);
  EXPECT_EQ(got, (std::vector<int64_t>{0, 1, 2}));
  EXPECT_EQ(sub.counters().queue_overflows, 5);
}

TEST(QueuedSubscription, ASlowConsumerLosesOnlyCountedMessagesAndUpstreamGapsStaySeparate) {
  // A consumer that takes one message per loop while three arrive: 60 published, with seq
  // 30..34 never published (lost upstream).
  aerie::bus::Bus bus("memq://");
  int64_t delivered = 0;
  auto& sub = bus.subscribe_queued<aerie::pose_t>(
      "CAM", [&](const aerie::pose_t&, const aerie::bus::ReceiveInfo&) { ++delivered; }, 4);
  int64_t published = 0;
  for (int64_t s = 0; s < 65; ++s) {
    if (s >= 30 && s < 35) continue;
    bus.publish("CAM", frame(s));
    ++published;
    if (s % 3 == 2) bus.handle(0);
  }
  drain(bus);
  EXPECT_EQ(published, 60);
  EXPECT_EQ(sub.counters().received, 60);
  EXPECT_GT(sub.counters().queue_overflows, 0);
  EXPECT_EQ(delivered + sub.counters().queue_overflows, published);
  EXPECT_EQ(sub.counters().sequence_gaps, 5);
}

TEST(QueuedSubscription, OtherSubscriptionsStillGetEveryMessageAndMalformedIsCounted) {
  aerie::bus::Bus bus("memq://");
  int plain = 0, queued = 0;
  bus.subscribe<aerie::pose_t>("OTHER", [&](const aerie::pose_t&, const aerie::bus::ReceiveInfo&) { ++plain; });
  auto& sub = bus.subscribe_queued<aerie::pose_t>(
      "CAM", [&](const aerie::pose_t&, const aerie::bus::ReceiveInfo&) { ++queued; }, 2);
  const uint8_t junk[5] = {1, 2, 3, 4, 5};
  bus.publish_raw("CAM", junk, sizeof junk);
  for (int64_t s = 0; s < 50; ++s) bus.publish("OTHER", frame(s));
  bus.publish("CAM", frame(0));
  drain(bus);
  EXPECT_EQ(plain, 50);
  EXPECT_EQ(queued, 1);
  EXPECT_EQ(sub.counters().malformed, 1);
  EXPECT_EQ(sub.counters().queue_overflows, 0);  // a malformed message never takes a place
}

TEST(QueuedSubscription, StatusNamesOverflowsAndWaitingMessages) {
  aerie::bus::Bus bus("memq://");
  aerie::bus::StatusReporter status(bus, "probe");
  bus.subscribe_queued<aerie::pose_t>("CAM", [](const aerie::pose_t&, const aerie::bus::ReceiveInfo&) {}, 2);
  bus.subscribe<aerie::pose_t>("PLAIN", [](const aerie::pose_t&, const aerie::bus::ReceiveInfo&) {});
  std::map<std::string, int64_t> counters;
  bus.subscribe<aerie::process_status_t>("STATUS_PROBE", [&](const aerie::process_status_t& m, const auto&) {
    for (int i = 0; i < m.ncounters; ++i) counters[m.counter_names[i]] = m.counter_values[i];
  });
  for (int64_t s = 0; s < 7; ++s) bus.publish("CAM", frame(s));
  bus.handle(0);  // takes all 7 (5 overflow), hands one on: one still waits
  status.publish_now();
  drain(bus);
  EXPECT_EQ(counters.at("CAM.received"), 7);
  EXPECT_EQ(counters.at("CAM.queue_overflows"), 5);
  EXPECT_EQ(counters.at("CAM.queued"), 1);
  EXPECT_EQ(counters.at("CAM.sequence_gaps"), 0);
  EXPECT_EQ(counters.count("PLAIN.queue_overflows"), 0u);  // plain subscriptions keep their fields
}

TEST(QueuedSubscription, AZeroCapacityIsRefused) {
  aerie::bus::Bus bus("memq://");
  try {
    bus.subscribe_queued<aerie::pose_t>("CAM", [](const aerie::pose_t&, const aerie::bus::ReceiveInfo&) {}, 0);
    FAIL() << "capacity 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("CAM: queue capacity must be >= 1"), std::string::npos) << e.what();
  }
}
