// The link in simulation time between two in-process buses (tools/link/sim_link.hpp), as the
// lock-step link study uses it: a message delayed by d arrives exactly d later in simulation
// time, the loss rate is the configured one, both directions relay, and the outcome depends
// on the seed alone (never on the machine's load: no wall clock is read).
#include <aerie/pose_t.hpp>
#include <gtest/gtest.h>

#include <vector>

#include "tools/link/sim_link.hpp"

using namespace aerie;
using link::Side;

namespace {

link::Split split(double delay_ms, double loss = 0, uint64_t seed = 1) {
  link::Split s;
  for (auto* d : {&s.down, &s.up}) {
    d->delay_ms = delay_ms;
    d->loss = loss;
    d->seed = d == &s.down ? 2 * seed - 1 : 2 * seed;
    d->queue_bytes = 64 << 20;
  }
  s.down.channels = "DOWN";
  s.up.channels = "UP";
  return s;
}

aerie::pose_t pose(int64_t utime) {
  aerie::pose_t m{};
  m.utime = utime;
  m.seq = utime;
  return m;
}

// Arrival (simulation µs) of each message on `channel` at `side`, by send order; -1 = lost.
struct Arrivals {
  std::vector<int64_t> at;
};

// Sends one message on `channel` from `from` at each of `send_us`, settling every step_us.
Arrivals run(const link::Split& s, Side from, const std::string& channel, const std::vector<int64_t>& send_us,
             int64_t step_us, int64_t end_us) {
  link::SplitBus buses(s);
  Arrivals a;
  a.at.assign(send_us.size(), -1);
  int64_t now = 0;
  buses.on(from == Side::kAir ? Side::kGround : Side::kAir)
      .subscribe<aerie::pose_t>(channel, [&](const aerie::pose_t& m, const bus::ReceiveInfo&) {
        a.at[static_cast<size_t>(m.seq)] = now;
      }, 100000);
  size_t next = 0;
  for (now = 0; now <= end_us; now += step_us) {
    for (; next < send_us.size() && send_us[next] <= now; ++next) {
      aerie::pose_t m = pose(send_us[next]);
      m.seq = static_cast<int64_t>(next);
      buses.on(from).publish(channel, m);
    }
    buses.settle(now);
  }
  return a;
}

}  // namespace

TEST(SimLink, MessageDelayedByDArrivesExactlyDLaterInSimulationTime) {
  for (double d_ms : {0.0, 50.0, 100.0, 500.0}) {
    const std::vector<int64_t> send{0, 1000, 20000, 333000};
    const Arrivals down = run(split(d_ms), Side::kAir, "DOWN", send, 1000, 2'000'000);
    const Arrivals up = run(split(d_ms), Side::kGround, "UP", send, 1000, 2'000'000);
    for (size_t i = 0; i < send.size(); ++i) {
      EXPECT_EQ(down.at[i], send[i] + static_cast<int64_t>(d_ms * 1000)) << "down, delay " << d_ms << " ms, message " << i;
      EXPECT_EQ(up.at[i], send[i] + static_cast<int64_t>(d_ms * 1000)) << "up, delay " << d_ms << " ms, message " << i;
    }
  }
}

TEST(SimLink, OnlyTheDirectionsChannelsCross) {
  const std::vector<int64_t> send{0};
  EXPECT_EQ(run(split(0), Side::kAir, "UP", send, 1000, 10000).at[0], -1);    // UP goes ground->air only
  EXPECT_EQ(run(split(0), Side::kAir, "OTHER", send, 1000, 10000).at[0], -1);
  EXPECT_EQ(run(split(0), Side::kGround, "DOWN", send, 1000, 10000).at[0], -1);
}

TEST(SimLink, LossFollowsTheConfiguredRateWithinOnePointOver10000Messages) {
  std::vector<int64_t> send(10000);
  for (size_t i = 0; i < send.size(); ++i) send[i] = static_cast<int64_t>(i) * 5000;  // 200 Hz, like the IMU
  for (double loss : {0.01, 0.1, 0.3}) {
    for (Side from : {Side::kAir, Side::kGround}) {
      const Arrivals a = run(split(20, loss, 7), from, from == Side::kAir ? "DOWN" : "UP", send, 5000, 50'100'000);
      const auto lost = std::count(a.at.begin(), a.at.end(), -1);
      EXPECT_NEAR(static_cast<double>(lost) / 10000.0, loss, 0.01) << "loss " << loss;
    }
  }
}

TEST(SimLink, SameSeedSameDeliveriesAndCountersInBothDirections) {
  std::vector<int64_t> send(2000);
  for (size_t i = 0; i < send.size(); ++i) send[i] = static_cast<int64_t>(i) * 5000;
  link::Split s = split(100, 0.2, 3);
  s.down.jitter_ms = s.up.jitter_ms = 30;
  const Arrivals a = run(s, Side::kAir, "DOWN", send, 5000, 11'000'000);
  const Arrivals b = run(s, Side::kAir, "DOWN", send, 5000, 11'000'000);
  EXPECT_EQ(a.at, b.at);
  const Arrivals other = run(split(100, 0.2, 4), Side::kAir, "DOWN", send, 5000, 11'000'000);
  EXPECT_NE(a.at, other.at);

  link::SplitBus buses(s);
  buses.on(Side::kAir).publish("DOWN", pose(0));
  buses.on(Side::kGround).publish("UP", pose(0));
  buses.settle(0);
  buses.settle(200000);
  EXPECT_EQ(buses.down_counters().received, 1);
  EXPECT_EQ(buses.up_counters().received, 1);
}

TEST(SimLink, WithoutASplitEveryNodeSharesOneBus) {
  link::SplitBus buses(std::nullopt);
  EXPECT_EQ(&buses.on(Side::kAir), &buses.on(Side::kGround));
  EXPECT_EQ(&buses.of("track"), &buses.on(Side::kAir));
  EXPECT_EQ(buses.link(), nullptr);
  EXPECT_EQ(buses.down_counters().received, 0);
}

TEST(SimLink, BadDirectionIsRefusedNamingTheField) {
  link::Split s = split(-5);
  try {
    link::SplitBus buses(s);
    FAIL() << "a negative delay was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("delay"), std::string::npos) << e.what();
  }
  EXPECT_THROW(link::side_from_name("sky"), std::invalid_argument);
}
