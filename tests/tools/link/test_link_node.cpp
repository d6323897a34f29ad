// aerie-link as a process between two LCM networks (two multicast groups on the
// loopback of a network namespace the test creates): the measured delay
// distribution, loss rate and bandwidth against the configuration, echo
// suppression, JPEG re-encoding, LINK_STATS, and determinism for a seed.
#include <aerie/link_stats_t.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numeric>
#include <thread>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "common/bus/bus.hpp"
#include "common/image/image_message.hpp"
#include "common/util/time.hpp"
#include "procman/testbed.hpp"
#include "tests/support/test_support.hpp"
#include "tools/latency/stats.hpp"
#include "tools/link/link_model.hpp"
#include "tools/link/probe.hpp"

using namespace aerie;
using namespace std::chrono_literals;
namespace testbed = aerie::procman::testbed;

namespace {

const std::string kAir = "udpm://239.255.76.67:7667?ttl=0";
const std::string kGround = "udpm://239.255.76.68:7668?ttl=0";

class LinkNode : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const auto why = testbed::namespaces_unavailable(); !why.empty()) GTEST_SKIP() << why;
    ns_ = std::make_unique<testbed::NetNamespace>(testbed::unique_name("link"));
    dir_ = test::scratch_dir("link");
  }
  void TearDown() override {
    if (link_) {
      EXPECT_EQ(link_->stop(SIGINT, 5s), 0) << link_->log();
      link_.reset();
    }
  }

  // Starts aerie-link with this YAML (URLs and a 0.25 s stats period added) and
  // waits for its first LINK_STATS: from then on it relays.
  void start_link(const std::string& yaml) {
    const auto cfg = dir_ / "link.yaml";
    std::ofstream(cfg) << "air_url: \"" << kAir << "\"\nground_url: \"" << kGround
                       << "\"\nstats: {period_s: 0.25}\n" << yaml;
    auto argv = ns_->exec_prefix();
    // Real-time scheduling for the link and the probe: the figures are the link's,
    // not the scheduler's on a loaded test machine.
    argv.insert(argv.end(), {(test::binary_dir() / "bin" / "aerie-link").string(), "--config", cfg.string(),
                             "--realtime-priority", "10"});
    link_ = std::make_unique<testbed::Process>(argv, (dir_ / "link.log").string());
    testbed::EnterNamespace inside(*ns_);
    bus::Bus ground(kGround);
    bool up = false;
    ground.subscribe<aerie::link_stats_t>("LINK_STATS", [&](const auto&, const auto&) { up = true; });
    const auto until = std::chrono::steady_clock::now() + 20s;
    while (!up && link_->running() && std::chrono::steady_clock::now() < until) ground.handle(50);
    ASSERT_TRUE(up) << "aerie-link did not start: " << link_->log();
  }

  testbed::RealtimePriority realtime_;  // the probe (and its LCM threads)
  std::unique_ptr<testbed::NetNamespace> ns_;
  std::unique_ptr<testbed::Process> link_;
  std::filesystem::path dir_;
};

}  // namespace

TEST_F(LinkNode, DelayAndJitterMatchTheConfigurationWithin2ms) {
  start_link(R"(
air_to_ground: {channels: "PROBE", delay_ms: 20, jitter_ms: 5, jitter_distribution: normal, reorder: true}
)");
  testbed::EnterNamespace inside(*ns_);
  bus::Bus air(kAir), ground(kGround);
  link::Probe probe(air, ground, "PROBE");
  probe.run(1000, 200, 200, 500);
  const auto d = probe.delays_ms();
  ASSERT_EQ(d.size(), 1000u) << link_->log();
  // Normal(20, 5): quantiles 20 -/+ 1.2816 * 5 at 10 % / 90 %.
  EXPECT_NEAR(latency::percentile(d, 0.10), 20.0 - 1.2816 * 5, 2.0);
  EXPECT_NEAR(latency::percentile(d, 0.50), 20.0, 2.0);
  EXPECT_NEAR(latency::percentile(d, 0.90), 20.0 + 1.2816 * 5, 2.0);
  EXPECT_NEAR(std::accumulate(d.begin(), d.end(), 0.0) / static_cast<double>(d.size()), 20.0, 2.0);
}

TEST_F(LinkNode, FixedDelayWithoutJitter) {
  start_link(R"(
air_to_ground: {channels: "PROBE", delay_ms: 50}
)");
  testbed::EnterNamespace inside(*ns_);
  bus::Bus air(kAir), ground(kGround);
  link::Probe probe(air, ground, "PROBE");
  probe.run(200, 100, 100, 300);
  const auto d = probe.delays_ms();
  ASSERT_EQ(d.size(), 200u);
  EXPECT_GE(*std::min_element(d.begin(), d.end()), 50.0);
  EXPECT_NEAR(latency::percentile(d, 0.5), 50.0, 2.0);
  EXPECT_NEAR(latency::percentile(d, 0.9), 50.0, 2.0);
}

TEST_F(LinkNode, LossRateWithinOnePointOver10000Messages) {
  start_link(R"(
seed: 3
air_to_ground: {channels: "PROBE", loss: {model: bernoulli, probability: 0.1}}
)");
  testbed::EnterNamespace inside(*ns_);
  bus::Bus air(kAir), ground(kGround);
  int64_t link_received = 0, link_lost = 0;
  ground.subscribe<aerie::link_stats_t>("LINK_STATS", [&](const aerie::link_stats_t& s, const auto&) {
    link_received = s.directions.at(0).received;
    link_lost = s.directions.at(0).dropped_loss;
  });
  link::Probe probe(air, ground, "PROBE");
  probe.run(10000, 2500, 100, 1500);
  const double rate = static_cast<double>(probe.lost().size()) / 10000.0;
  EXPECT_NEAR(rate, 0.1, 0.01) << link_->log();
  EXPECT_EQ(probe.duplicates(), 0);
  // The link's own account, from LINK_STATS.
  ASSERT_GT(link_received, 9900);
  EXPECT_NEAR(static_cast<double>(link_lost) / static_cast<double>(link_received), 0.1, 0.01);
}

TEST_F(LinkNode, BandwidthCapWithin5Percent) {
  start_link(R"(
air_to_ground: {channels: "PROBE", bandwidth_kbps: 400, queue_bytes: 50000, queue_policy: drop_oldest}
)");
  testbed::EnterNamespace inside(*ns_);
  bus::Bus air(kAir), ground(kGround);
  link::Probe probe(air, ground, "PROBE");
  const size_t payload = 1000;
  probe.run(600, 100, payload, 1500);  // ~2x the cap for 6 s
  const auto& r = probe.received();
  ASSERT_GT(r.size(), 100u);
  // Throughput in wire bytes over the steady part (after the queue filled).
  const int64_t t0 = r.front().recv_utime;
  int64_t first = -1, last = 0, bytes = 0;
  for (const auto& s : r) {
    if (s.recv_utime - t0 < 1'000'000) continue;
    if (first < 0) {
      first = s.recv_utime;
      continue;  // count what arrives after the first in the window
    }
    last = s.recv_utime;
    bytes += link::wire_bytes("PROBE", s.payload_bytes);
  }
  const double kbps = static_cast<double>(bytes) * 8.0 / (static_cast<double>(last - first) * 1e-6) / 1000.0;
  EXPECT_NEAR(kbps, 400.0, 20.0);
  EXPECT_GT(probe.lost().size(), 100u);  // the rest was dropped from the full queue
}

TEST_F(LinkNode, SameSeedLosesTheSameMessages) {
  const std::string yaml = R"(
seed: 11
air_to_ground: {channels: "PROBE", loss: {probability: 0.3}}
)";
  std::vector<std::vector<int64_t>> lost;
  for (int run = 0; run < 2; ++run) {
    start_link(yaml);
    {
      testbed::EnterNamespace inside(*ns_);
      bus::Bus air(kAir), ground(kGround);
      link::Probe probe(air, ground, "PROBE");
      probe.run(400, 400, 100, 300);
      lost.push_back(probe.lost());
    }
    EXPECT_EQ(link_->stop(SIGINT, 5s), 0);
    link_.reset();
  }
  EXPECT_GT(lost[0].size(), 60u);
  EXPECT_EQ(lost[0], lost[1]);
}

TEST_F(LinkNode, RelaysBothWaysWithoutEchoReencodesImagesAndPublishesStats) {
  start_link(R"(
air_to_ground: {channels: "BOTH|CAM_LEFT", jpeg: {channels: "CAM_.*", quality: 50}}
ground_to_air: {channels: "BOTH|UP"}
)");
  testbed::EnterNamespace inside(*ns_);
  bus::Bus air(kAir), ground(kGround);
  // BOTH is relayed in both directions: each side must see each message once.
  link::Probe both(air, ground, "BOTH");
  int on_air = 0;
  air.subscribe_raw("BOTH", [&](const uint8_t*, size_t, const bus::ReceiveInfo&) { ++on_air; });
  both.run(20, 100, 50, 500);
  EXPECT_EQ(both.received().size(), 20u);
  EXPECT_EQ(both.duplicates(), 0);
  EXPECT_EQ(on_air, 20);  // our own 20, nothing echoed back
  // Up-link only.
  link::Probe up(ground, air, "UP");
  up.run(10, 100, 50, 300);
  EXPECT_EQ(up.received().size(), 10u);

  // Camera images are re-encoded as JPEG on the way down.
  cv::Mat img(240, 320, CV_8UC1);
  cv::randu(img, 0, 30);
  cv::circle(img, {160, 120}, 70, cv::Scalar(220), -1);
  const size_t raw_size = static_cast<size_t>(image::to_message(img, 0, 0).getEncodedSize());
  std::vector<std::pair<std::string, size_t>> cams;
  ground.subscribe<aerie::image_t>("CAM_LEFT", [&](const aerie::image_t& m, const bus::ReceiveInfo& info) {
    cams.emplace_back(image::pixel_format_name(m.pixelformat), info.bytes);
  });
  for (int i = 0; i < 5; ++i) {
    air.publish("CAM_LEFT", image::to_message(img, util::wall_utime(), i));
    both.pump(20);
  }
  // LINK_STATS on both networks.
  std::vector<aerie::link_stats_t> stats_ground, stats_air;
  ground.subscribe<aerie::link_stats_t>("LINK_STATS", [&](const auto& s, const auto&) { stats_ground.push_back(s); });
  air.subscribe<aerie::link_stats_t>("LINK_STATS", [&](const auto& s, const auto&) { stats_air.push_back(s); });
  both.pump(1000);
  ASSERT_EQ(cams.size(), 5u);
  for (const auto& [format, bytes] : cams) {
    EXPECT_EQ(format, "MJPEG");
    EXPECT_LT(bytes, raw_size / 4);
  }
  ASSERT_FALSE(stats_ground.empty());
  ASSERT_FALSE(stats_air.empty());
  const auto& s = stats_ground.back();
  ASSERT_EQ(s.ndirections, 2);
  EXPECT_EQ(s.directions[0].name, "air->ground");
  EXPECT_EQ(s.directions[0].received, 25);
  EXPECT_EQ(s.directions[0].delivered, 25);
  EXPECT_EQ(s.directions[0].reencoded, 5);
  EXPECT_EQ(s.directions[1].name, "ground->air");
  EXPECT_EQ(s.directions[1].received, 10);
  EXPECT_DOUBLE_EQ(s.period_s, 0.25);
}
