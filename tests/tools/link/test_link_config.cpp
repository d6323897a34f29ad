#include <gtest/gtest.h>

#include "tests/support/test_support.hpp"
#include "tools/link/link_config.hpp"
#include "tools/link/relay.hpp"

using namespace aerie::link;

TEST(LinkConfig, ReadsEveryKey) {
  const auto cfg = load_link_config(aerie::util::Config::parse(R"(
air_url: "udpm://239.255.76.67:7667?ttl=1"
ground_url: "udpm://239.255.76.68:7668?ttl=1"
seed: 5
stats: {channel: MY_STATS, period_s: 0.5, publish_on: [ground]}
air_to_ground:
  channels: "CAM_.*|STATUS_.*"
  delay_ms: 25
  jitter_ms: 4
  jitter_distribution: uniform
  reorder: true
  loss: {model: gilbert_elliott, p_good_to_bad: 0.01, p_bad_to_good: 0.3, loss_good: 0.001, loss_bad: 0.6}
  bandwidth_kbps: 2000
  queue_bytes: 100000
  queue_policy: drop_newest
  jpeg: {channels: "CAM_.*", quality: 40}
ground_to_air:
  channels: "TRACK_CMD"
  loss: {probability: 0.05}
)", "link.yaml"));
  EXPECT_EQ(cfg.air_url, "udpm://239.255.76.67:7667?ttl=1");
  EXPECT_EQ(cfg.stats_channel, "MY_STATS");
  EXPECT_DOUBLE_EQ(cfg.stats_period_s, 0.5);
  EXPECT_FALSE(cfg.stats_on_air);
  EXPECT_TRUE(cfg.stats_on_ground);
  const auto& a = cfg.air_to_ground;
  EXPECT_EQ(a.channels, "CAM_.*|STATUS_.*");
  EXPECT_DOUBLE_EQ(a.delay_ms, 25);
  EXPECT_DOUBLE_EQ(a.jitter_ms, 4);
  EXPECT_EQ(a.jitter, JitterDistribution::Uniform);
  EXPECT_TRUE(a.reorder);
  EXPECT_EQ(a.loss_model, LossModel::GilbertElliott);
  EXPECT_DOUBLE_EQ(a.gilbert_elliott.p_bad_to_good, 0.3);
  EXPECT_DOUBLE_EQ(a.gilbert_elliott.loss_bad, 0.6);
  EXPECT_DOUBLE_EQ(a.bandwidth_bps, 2e6);
  EXPECT_EQ(a.queue_bytes, 100000);
  EXPECT_EQ(a.queue_policy, QueuePolicy::DropNewest);
  EXPECT_EQ(a.jpeg_channels, "CAM_.*");
  EXPECT_EQ(a.jpeg_quality, 40);
  EXPECT_EQ(a.seed, 9u);
  EXPECT_EQ(cfg.ground_to_air.seed, 10u);
  EXPECT_EQ(cfg.ground_to_air.loss_model, LossModel::Bernoulli);
  EXPECT_DOUBLE_EQ(cfg.ground_to_air.loss, 0.05);
  EXPECT_DOUBLE_EQ(cfg.ground_to_air.bandwidth_bps, 0);
}

TEST(LinkConfig, ErrorsNameTheFileAndKey) {
  auto message = [](const std::string& yaml) {
    try {
      load_link_config(aerie::util::Config::parse(yaml, "bad.yaml"));
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message("air_to_ground: {loss: {probability: 2}}").find("bad.yaml: air_to_ground: "), std::string::npos);
  EXPECT_NE(message("air_to_ground: {loss: {probability: 2}}").find("loss must be a probability"), std::string::npos);
  EXPECT_NE(message("ground_to_air: {jitter_distribution: pareto}").find("bad.yaml: ground_to_air.jitter_distribution"),
            std::string::npos);
  EXPECT_NE(message("air_to_ground: {delay_ms: soon}").find("'delay_ms' has the wrong type"), std::string::npos);
  EXPECT_NE(message("stats: {publish_on: [moon]}").find("stats.publish_on"), std::string::npos);
  EXPECT_NE(message("air_url: memq://\nground_url: memq://").find("same network"), std::string::npos);
}

TEST(LinkConfig, ShippedConfigLoads) {
  const auto cfg = load_link_config(aerie::util::Config::load((aerie::test::source_dir() / "config/link.yaml").string()));
  EXPECT_NE(cfg.air_url, cfg.ground_url);
  // Issue 46: the operator's safety commands cross up by default; no procman channel crosses
  // either way unless named (docs/link.md "Channels").
  ChannelMatcher up(cfg.ground_to_air.channels), down(cfg.air_to_ground.channels);
  for (const char* c : {"PILOT_CMD", "TRACK_CMD", "FLC_PARAMS", "MAP_RESPONSE"}) EXPECT_TRUE(up(c)) << c;
  for (const char* c : {"CAM_LEFT", "TRACK", "TARGET_POSE", "VO_POSE", "STATUS_TRACK", "MAP_QUERY"}) EXPECT_TRUE(down(c)) << c;
  for (const char* c : {"PMD_ORDERS2", "PMD_INFO2", "PMD_PRINTF", "PMD_DISCOVER", "PMD_ORDERS", "PMD_INFO"}) {
    EXPECT_FALSE(up(c)) << c;
    EXPECT_FALSE(down(c)) << c;
  }
  EXPECT_FALSE(down("PILOT_CMD"));  // commands go up only
}
