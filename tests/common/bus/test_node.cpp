// bus::Node: subscriptions that end with the node, the status channel's name, tick() and its
// exceptions counted, not fatal.
#include <gtest/gtest.h>

#include <aerie/pose_t.hpp>
#include <aerie/process_status_t.hpp>

#include <memory>
#include <stdexcept>

#include "common/bus/node.hpp"

namespace aerie::bus {
namespace {

class Counter final : public Node {
 public:
  explicit Counter(Bus& bus) : Node(bus, "pose-counter") {
    subscribe<aerie::pose_t>("VO_POSE", [this](const aerie::pose_t&, const ReceiveInfo&) { ++poses; });
  }
  void tick(int64_t now_us) override {
    ++ticks;
    last_now = now_us;
    if (ticks == 2) throw std::runtime_error("the second tick failed");
  }
  bool running() const override { return ticks < 3; }
  int poses = 0, ticks = 0;
  int64_t last_now = 0;
};

void publish_pose(Bus& bus) {
  aerie::pose_t p{};
  bus.publish("VO_POSE", p);
}

TEST(Node, SubscriptionsEndWithTheNode) {
  Bus bus("memq://");
  auto node = std::make_unique<Counter>(bus);
  ASSERT_EQ(bus.subscriptions().size(), 1u);
  publish_pose(bus);
  while (bus.handle(0) > 0) {
  }
  EXPECT_EQ(node->poses, 1);
  node.reset();
  EXPECT_TRUE(bus.subscriptions().empty());
  publish_pose(bus);  // no handler of the dead node is called (it would touch freed memory)
  EXPECT_EQ(bus.handle(0), 0);
}

TEST(Node, StatusChannelIsNamedAfterTheNode) {
  Bus bus("memq://");
  Counter node(bus);
  EXPECT_EQ(node.name(), "pose-counter");
  EXPECT_EQ(node.status().channel(), "STATUS_POSE_COUNTER");
}

TEST(Node, RunTicksCountsAFailedTickAndStopsWhenTheNodeHasFinished) {
  Bus bus("memq://");
  Counter node(bus);
  int statuses = 0;
  bus.subscribe<aerie::process_status_t>("STATUS_POSE_COUNTER",
                                         [&](const aerie::process_status_t&, const ReceiveInfo&) { ++statuses; });
  run(node, 0);
  EXPECT_EQ(node.ticks, 3);
  EXPECT_GT(node.last_now, 0);
  EXPECT_EQ(node.status().counter("loop_errors"), 1);
  EXPECT_EQ(node.status().message(), "the second tick failed");
  while (bus.handle(0) > 0) {
  }
  EXPECT_GE(statuses, 1);  // the last status, published on the way out
}

TEST(Node, UnsubscribeRefusesASubscriptionItDidNotMake) {
  Bus bus("memq://");
  Counter node(bus);
  auto& other = bus.subscribe<aerie::pose_t>("OTHER", [](const aerie::pose_t&, const ReceiveInfo&) {});
  struct Peek : Node {
    using Node::Node;
    using Node::unsubscribe;
  } peek(bus, "peek");
  EXPECT_THROW(peek.unsubscribe(other), std::invalid_argument);
}

}  // namespace
}  // namespace aerie::bus
