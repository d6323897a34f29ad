#include <gtest/gtest.h>

#include <aerie/pose_t.hpp>

#include <cstdint>

#include "common/bus/bus.hpp"
#include "common/bus/status.hpp"
#include "common/image/image_message.hpp"

using aerie::bus::Bus;
using aerie::bus::ReceiveInfo;

TEST(Bus, TypedRoundTripOverMemq) {
  Bus bus("memq://");
  std::vector<int64_t> got;
  bus.subscribe<aerie::pose_t>("VO_POSE", [&](const aerie::pose_t& m, const ReceiveInfo& info) {
    got.push_back(m.seq);
    EXPECT_EQ(info.channel, "VO_POSE");
  });
  for (int64_t s : {0, 1, 2, 5}) {  // 3 and 4 are "lost"
    aerie::pose_t p{};
    p.seq = s;
    bus.publish("VO_POSE", p);
  }
  while (bus.handle(0) > 0) {
  }
  EXPECT_EQ(got, (std::vector<int64_t>{0, 1, 2, 5}));
  EXPECT_EQ(bus.subscriptions()[0]->counters().sequence_gaps, 2);
}

TEST(Bus, SequenceGapsOfAPatternSubscriptionAreCountedPerChannel) {
  // STATUS_.* hears every node's status, each with its own seq: interleaved, they are no gaps.
  Bus bus("memq://");
  bus.subscribe<aerie::pose_t>("POSE_.*", [](const aerie::pose_t&, const ReceiveInfo&) {});
  const auto send = [&](const std::string& channel, int64_t seq) {
    aerie::pose_t p{};
    p.seq = seq;
    bus.publish(channel, p);
    while (bus.handle(0) > 0) {
    }
  };
  for (int64_t k = 0; k < 5; ++k) {
    send("POSE_A", k);
    send("POSE_B", 1000 + k);
  }
  EXPECT_EQ(bus.subscriptions()[0]->counters().sequence_gaps, 0);
  send("POSE_A", 8);                      // 5, 6, 7 lost on POSE_A
  send("POSE_B", 1005);
  send("POSE_B", INT64_MAX);              // a hostile seq: counted, no overflow
  send("POSE_B", 0);                      // restarted: resynchronised
  send("POSE_B", 1);
  EXPECT_EQ(bus.subscriptions()[0]->counters().sequence_gaps, 3 + (INT64_MAX - 1005 - 1));
}

TEST(Bus, CorruptPayloadIsCountedNotDelivered) {
  Bus bus("memq://");
  int delivered = 0;
  auto& sub = bus.subscribe<aerie::image_t>("CAM_LEFT", [&](const aerie::image_t&, const ReceiveInfo&) { ++delivered; });
  const uint8_t junk[7] = {1, 2, 3, 4, 5, 6, 7};
  bus.publish_raw("CAM_LEFT", junk, sizeof(junk));
  aerie::pose_t wrong_type{};
  bus.publish("CAM_LEFT", wrong_type);  // fingerprint mismatch
  while (bus.handle(0) > 0) {
  }
  EXPECT_EQ(delivered, 0);
  EXPECT_EQ(sub.counters().malformed, 2);
  EXPECT_NE(sub.last_error().find("image_t"), std::string::npos) << sub.last_error();
}

TEST(Bus, HandlerExceptionIsCountedAndStatusReportsIt) {
  Bus bus("memq://");
  bus.subscribe<aerie::pose_t>("VO_POSE", [](const aerie::pose_t&, const ReceiveInfo&) {
    throw std::runtime_error("boom");
  });
  aerie::process_status_t last{};
  int statuses = 0;
  aerie::bus::StatusReporter status(bus, "test-node");
  EXPECT_EQ(status.channel(), "STATUS_TEST_NODE");
  bus.subscribe<aerie::process_status_t>(status.channel(), [&](const aerie::process_status_t& m, const ReceiveInfo&) {
    last = m;
    ++statuses;
  });
  bus.publish("VO_POSE", aerie::pose_t{});
  while (bus.handle(0) > 0) {
  }
  status.count("frames", 3);
  status.publish_now();
  while (bus.handle(0) > 0) {
  }
  ASSERT_EQ(statuses, 1);
  auto value = [&](const std::string& name) {
    for (int i = 0; i < last.ncounters; ++i)
      if (last.counter_names[i] == name) return last.counter_values[i];
    return int64_t{-1};
  };
  EXPECT_EQ(value("frames"), 3);
  EXPECT_EQ(value("VO_POSE.handler_errors"), 1);
  EXPECT_EQ(value("VO_POSE.received"), 1);
}

TEST(Bus, BadUrlIsAClearError) {
  EXPECT_THROW(Bus("nosuchprovider://x"), std::runtime_error);
}

TEST(Bus, RawSubscriptionSeesAnyTypeAndPeeksUtime) {
  Bus bus("memq://");
  std::vector<std::pair<std::string, int64_t>> got;
  bus.subscribe_raw("VO_.*", [&](const uint8_t* data, size_t size, const ReceiveInfo& info) {
    got.emplace_back(info.channel, aerie::bus::peek_utime(data, size).value_or(-1));
  });
  aerie::pose_t p{};
  p.utime = 1234567890123;
  bus.publish("VO_POSE", p);
  bus.publish("OTHER", p);
  const uint8_t tiny[3] = {1, 2, 3};
  bus.publish_raw("VO_X", tiny, 3);
  while (bus.handle(0) > 0) {
  }
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0], std::make_pair(std::string("VO_POSE"), int64_t{1234567890123}));
  EXPECT_EQ(got[1].second, -1);
}

TEST(Bus, ChannelRegexWithAlternativesMatchesWholeNamesOnly) {
  // LCM anchors a subscription as ^REGEX$; with alternatives that anchors only the first and the
  // last ("^A|B$"), so "TRACK|X" used to take "GT_TRACK" and "TRACK_CMD" too. The bus groups it.
  Bus bus("memq://");
  std::vector<std::string> got;
  bus.subscribe_raw("TRACK|CAM_DOWN", [&](const uint8_t*, size_t, const ReceiveInfo& info) { got.push_back(info.channel); });
  const uint8_t b[16] = {};
  for (const char* ch : {"TRACK", "GT_TRACK", "TRACK_CMD", "CAM_DOWN", "CAM_DOWN2", "XCAM_DOWN"}) bus.publish_raw(ch, b, sizeof b);
  while (bus.handle(0) > 0) {
  }
  EXPECT_EQ(got, (std::vector<std::string>{"TRACK", "CAM_DOWN"}));
}

TEST(Bus, UnsubscribedHandlerIsNeverCalledAgain) {
  // A node killed mid-flight (tools/faults) leaves the bus; the others keep their messages.
  Bus bus("memq://");
  int first = 0, second = 0;
  auto& a = bus.subscribe<aerie::pose_t>("VO_POSE", [&](const aerie::pose_t&, const ReceiveInfo&) { ++first; });
  bus.subscribe<aerie::pose_t>("VO_POSE", [&](const aerie::pose_t&, const ReceiveInfo&) { ++second; });
  aerie::pose_t p{};
  bus.publish("VO_POSE", p);
  bus.unsubscribe(a);  // its queued message is dropped too
  bus.publish("VO_POSE", p);
  while (bus.handle(0) > 0) {
  }
  EXPECT_EQ(first, 0);
  EXPECT_EQ(second, 2);
  ASSERT_EQ(bus.subscriptions().size(), 1u);
  Bus other("memq://");
  auto& foreign = other.subscribe<aerie::pose_t>("VO_POSE", [](const aerie::pose_t&, const ReceiveInfo&) {});
  EXPECT_THROW(bus.unsubscribe(foreign), std::invalid_argument);
}
