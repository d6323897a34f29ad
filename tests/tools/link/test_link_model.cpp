// The link model in virtual time: delay and jitter distributions, Bernoulli and
// Gilbert-Elliott loss rates, the bandwidth cap and its bounded queue, ordering,
// and determinism for a seed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>

#include "tools/latency/stats.hpp"
#include "tools/link/link_model.hpp"

using namespace aerie::link;
namespace latency = aerie::latency;

namespace {

Packet packet(size_t size = 100, const std::string& channel = "CH") {
  Packet p;
  p.channel = channel;
  p.data.assign(size, 0x5a);
  return p;
}

struct Result {
  std::vector<double> delay_ms;   // of the delivered packets, by delivery order
  std::vector<uint64_t> serials;  // delivered, in delivery order
  std::vector<int64_t> release_us;
  DirectionCounters counters;
};

// Offers n packets every period_us and collects the deliveries.
Result run(DirectionConfig cfg, int n, int64_t period_us, size_t size = 100) {
  LinkDirection d(cfg);
  Result r;
  auto collect = [&](int64_t now) {
    for (auto& p : d.due(now)) {
      r.delay_ms.push_back(static_cast<double>(p.release_us - p.arrival_us) / 1000.0);
      r.serials.push_back(p.serial);
      r.release_us.push_back(p.release_us);
    }
  };
  int64_t t = 0;
  for (int i = 0; i < n; ++i, t += period_us) {
    collect(t);
    d.offer(packet(size), t);
    collect(t);
  }
  while (d.next_event_us() >= 0) collect(t = std::max(t, d.next_event_us()));
  r.counters = d.counters();
  return r;
}

double mean(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size()); }

double stddev(const std::vector<double>& v) {
  const double m = mean(v);
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

}  // namespace

TEST(LinkModel, ZeroConfigurationDeliversEverythingAtOnceInOrder) {
  const Result r = run(DirectionConfig{}, 1000, 1000);
  EXPECT_EQ(r.counters.received, 1000);
  EXPECT_EQ(r.counters.delivered, 1000);
  EXPECT_EQ(r.counters.dropped_loss + r.counters.dropped_queue + r.counters.dropped_other, 0);
  for (double d : r.delay_ms) EXPECT_EQ(d, 0.0);
  EXPECT_TRUE(std::is_sorted(r.serials.begin(), r.serials.end()));
  EXPECT_EQ(r.counters.bytes_delivered, 1000 * wire_bytes("CH", 100));
}

TEST(LinkModel, FixedDelayIsExact) {
  DirectionConfig c;
  c.delay_ms = 37.5;
  const Result r = run(c, 100, 10000);
  ASSERT_EQ(r.delay_ms.size(), 100u);
  for (double d : r.delay_ms) EXPECT_DOUBLE_EQ(d, 37.5);
}

TEST(LinkModel, NormalJitterHasTheConfiguredDistribution) {
  DirectionConfig c;
  c.delay_ms = 20;
  c.jitter_ms = 5;
  c.reorder = true;  // independent delays
  const Result r = run(c, 10000, 2000);
  ASSERT_EQ(r.delay_ms.size(), 10000u);
  EXPECT_NEAR(mean(r.delay_ms), 20.0, 0.2);
  EXPECT_NEAR(stddev(r.delay_ms), 5.0, 0.2);
  EXPECT_NEAR(latency::percentile(r.delay_ms, 0.10), 20.0 - 1.2816 * 5, 0.5);
  EXPECT_NEAR(latency::percentile(r.delay_ms, 0.50), 20.0, 0.5);
  EXPECT_NEAR(latency::percentile(r.delay_ms, 0.90), 20.0 + 1.2816 * 5, 0.5);
  // Jitter larger than the spacing reorders when allowed.
  EXPECT_FALSE(std::is_sorted(r.serials.begin(), r.serials.end()));
}

TEST(LinkModel, UniformAndExponentialJitter) {
  DirectionConfig c;
  c.delay_ms = 30;
  c.jitter_ms = 4;
  c.reorder = true;
  c.jitter = JitterDistribution::Uniform;
  const Result u = run(c, 10000, 2000);
  EXPECT_NEAR(mean(u.delay_ms), 30.0, 0.2);
  EXPECT_NEAR(stddev(u.delay_ms), 4.0, 0.2);
  const double half = 4 * std::sqrt(3.0);
  EXPECT_GE(*std::min_element(u.delay_ms.begin(), u.delay_ms.end()), 30 - half - 1e-3);
  EXPECT_LE(*std::max_element(u.delay_ms.begin(), u.delay_ms.end()), 30 + half + 1e-3);

  c.jitter = JitterDistribution::Exponential;
  const Result e = run(c, 10000, 2000);
  EXPECT_NEAR(mean(e.delay_ms), 34.0, 0.3);  // delay + mean of Exp(jitter)
  EXPECT_NEAR(stddev(e.delay_ms), 4.0, 0.3);
  EXPECT_GE(*std::min_element(e.delay_ms.begin(), e.delay_ms.end()), 30.0 - 1e-3);
  EXPECT_NEAR(latency::percentile(e.delay_ms, 0.5), 30.0 + 4 * std::log(2.0), 0.3);
}

TEST(LinkModel, WithoutReorderDeliveriesKeepTheArrivalOrder) {
  DirectionConfig c;
  c.delay_ms = 20;
  c.jitter_ms = 10;
  const Result r = run(c, 2000, 1000);
  EXPECT_TRUE(std::is_sorted(r.serials.begin(), r.serials.end()));
  EXPECT_TRUE(std::is_sorted(r.release_us.begin(), r.release_us.end()));
  for (double d : r.delay_ms) EXPECT_GE(d, 0.0);
}

TEST(LinkModel, BernoulliLossRate) {
  for (double p : {0.01, 0.1, 0.3}) {
    DirectionConfig c;
    c.loss = p;
    const Result r = run(c, 10000, 1000);
    const double rate = static_cast<double>(r.counters.dropped_loss) / 10000.0;
    EXPECT_NEAR(rate, p, 0.01) << "p = " << p;
    EXPECT_EQ(r.counters.delivered + r.counters.dropped_loss, 10000);
  }
}

TEST(LinkModel, GilbertElliottLossIsBurstyWithTheStationaryRate) {
  DirectionConfig ge;
  ge.loss_model = LossModel::GilbertElliott;
  ge.gilbert_elliott = {0.02, 0.25, 0.01, 0.8};
  const double expected = ge.gilbert_elliott.mean_loss();
  EXPECT_NEAR(expected, (0.25 * 0.01 + 0.02 * 0.8) / 0.27, 1e-12);

  auto loss_runs = [](const Result& r, int n) {
    std::vector<bool> lost(static_cast<size_t>(n), true);
    for (uint64_t s : r.serials) lost[s] = false;
    int runs = 0, lost_total = 0;
    for (int i = 0; i < n; ++i) {
      if (!lost[static_cast<size_t>(i)]) continue;
      ++lost_total;
      if (i == 0 || !lost[static_cast<size_t>(i - 1)]) ++runs;
    }
    return static_cast<double>(lost_total) / std::max(runs, 1);  // mean burst length
  };
  double rate_sum = 0;
  double burst_ge = 0, burst_bern = 0;
  for (uint64_t seed = 1; seed <= 3; ++seed) {
    ge.seed = seed;
    const Result r = run(ge, 10000, 1000);
    const double rate = static_cast<double>(r.counters.dropped_loss) / 10000.0;
    EXPECT_NEAR(rate, expected, 0.01) << "seed " << seed;
    rate_sum += rate;
    burst_ge += loss_runs(r, 10000);
    DirectionConfig b;
    b.loss = expected;
    b.seed = seed;
    burst_bern += loss_runs(run(b, 10000, 1000), 10000);
  }
  // Bursts: ~1/(1 - 0.8 * 0.75) = 2.5 packets in Bad state vs ~1.07 independent.
  EXPECT_GT(burst_ge / 3, 1.5 * burst_bern / 3);
}

TEST(LinkModel, SameSeedSameOutcomeOtherSeedOtherOutcome) {
  DirectionConfig c;
  c.delay_ms = 10;
  c.jitter_ms = 3;
  c.loss = 0.2;
  c.reorder = true;
  c.seed = 7;
  const Result a = run(c, 3000, 1500), b = run(c, 3000, 1500);
  EXPECT_EQ(a.serials, b.serials);
  EXPECT_EQ(a.release_us, b.release_us);
  // Losses depend only on the packet order: another spacing, the same packets lost.
  const Result slower = run(c, 3000, 7000);
  EXPECT_EQ(std::set<uint64_t>(a.serials.begin(), a.serials.end()),
            std::set<uint64_t>(slower.serials.begin(), slower.serials.end()));
  c.seed = 8;
  const Result other = run(c, 3000, 1500);
  EXPECT_NE(std::set<uint64_t>(a.serials.begin(), a.serials.end()),
            std::set<uint64_t>(other.serials.begin(), other.serials.end()));
}

TEST(LinkModel, BandwidthCapIsRespected) {
  DirectionConfig c;
  c.bandwidth_bps = 100'000;
  c.queue_bytes = 20'000;
  const int64_t wire = wire_bytes("CH", 1000);
  // Offered at twice the cap for 20 s.
  const int64_t period_us = wire * 8 * 1'000'000 / 200'000;
  LinkDirection d(c);
  int64_t delivered_bytes_window = 0;
  int64_t max_queue = 0;
  for (int64_t t = 0; t < 20'000'000; t += period_us) {
    for (auto& p : d.due(t))
      if (p.release_us >= 5'000'000) delivered_bytes_window += wire;
    d.offer(packet(1000), t);
    max_queue = std::max(max_queue, d.queue_bytes());
  }
  const double achieved = static_cast<double>(delivered_bytes_window) * 8.0 / 15.0;
  EXPECT_NEAR(achieved, 100'000.0, 0.05 * 100'000.0);
  EXPECT_LE(max_queue, c.queue_bytes);
  EXPECT_GT(d.counters().dropped_queue, 0);
}

TEST(LinkModel, QueuePoliciesDropTheOldestOrTheNewest) {
  DirectionConfig c;
  c.bandwidth_bps = 80'000;  // ~10 packets/s of 1000 bytes
  c.queue_bytes = 5 * wire_bytes("CH", 1000);
  // A burst of 50 packets at once.
  auto burst = [&](QueuePolicy policy) {
    c.queue_policy = policy;
    LinkDirection d(c);
    for (int i = 0; i < 50; ++i) d.offer(packet(1000), 0);
    std::vector<uint64_t> got;
    for (int64_t t = 0; t < 10'000'000; t += 10'000)
      for (auto& p : d.due(t)) got.push_back(p.serial);
    EXPECT_EQ(d.counters().dropped_queue, 44) << "one in the transmitter, five waiting";
    return got;
  };
  EXPECT_EQ(burst(QueuePolicy::DropNewest), (std::vector<uint64_t>{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(burst(QueuePolicy::DropOldest), (std::vector<uint64_t>{0, 45, 46, 47, 48, 49}));
}

TEST(LinkModel, OversizedPacketIsDroppedNotStuck) {
  DirectionConfig c;
  c.bandwidth_bps = 1e6;
  c.queue_bytes = 1000;
  LinkDirection d(c);
  d.offer(packet(5000), 0);
  d.offer(packet(100), 0);
  EXPECT_EQ(d.counters().dropped_other, 1);
  EXPECT_EQ(d.due(1'000'000).size(), 1u);
}

TEST(LinkModel, WireBytes) {
  EXPECT_EQ(wire_bytes("ABC", 100), 100 + 4 + 8 + 28);
  const int64_t big = wire_bytes("CAM", 300'000);
  EXPECT_EQ(big, 300'000 + 4 + 5 * (20 + 28));
}

TEST(LinkModel, InvalidSettingsNameTheField) {
  auto message = [](DirectionConfig c) {
    try {
      c.validate();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("valid");
  };
  DirectionConfig c;
  c.loss = 1.5;
  EXPECT_NE(message(c).find("loss must be a probability"), std::string::npos);
  c = {};
  c.delay_ms = -1;
  EXPECT_NE(message(c).find("delay_ms"), std::string::npos);
  c = {};
  c.gilbert_elliott.p_bad_to_good = -0.1;
  EXPECT_NE(message(c).find("gilbert_elliott.p_bad_to_good"), std::string::npos);
  c = {};
  c.jpeg_quality = 0;
  EXPECT_NE(message(c).find("jpeg.quality"), std::string::npos);
  EXPECT_THROW(jitter_from_string("gauss"), std::invalid_argument);
  EXPECT_THROW(queue_policy_from_string("oldest"), std::invalid_argument);
  EXPECT_THROW(loss_model_from_string("ge"), std::invalid_argument);
}

TEST(LinkModel, ADownLinkLosesWhatIsInFlightAndWhatIsSentThenImpairmentApplies) {
  DirectionConfig c;
  c.delay_ms = 100;
  LinkDirection d(c);
  std::vector<Packet> got;
  // 0..9 ms: 10 packets in flight; down at 50 ms (nothing delivered yet): all lost.
  for (int i = 0; i < 10; ++i) d.offer(packet(), i * 1000);
  d.set_down(true);
  for (int i = 0; i < 5; ++i) d.offer(packet(), 60000 + i * 1000);
  for (auto& p : d.due(400000)) got.push_back(std::move(p));
  EXPECT_TRUE(got.empty());
  EXPECT_EQ(d.counters().dropped_outage, 15);
  // Up again, at 500 ms delay and 30 % loss.
  d.set_down(false);
  d.impair(500, 0.3);
  for (int i = 0; i < 2000; ++i) d.offer(packet(), 500000 + i * 1000);
  for (auto& p : d.due(3000000)) {
    EXPECT_EQ(p.release_us - p.arrival_us, 500000);
    got.push_back(std::move(p));
  }
  EXPECT_NEAR(static_cast<double>(got.size()) / 2000.0, 0.7, 0.04);
  EXPECT_EQ(d.counters().dropped_outage, 15);
  EXPECT_THROW(d.impair(500, 1.5), std::invalid_argument);
}
