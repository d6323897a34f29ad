// aerie-nav with source: mono over memq://: the mono channel is subscribed (VO_POSE is not),
// NAV_STATE says SCALE_UNKNOWN while the vehicle has not accelerated, INITIALISING / LOST poses
// are not measurements, bad poses are refused and counted; nav.yaml's source and mono.* keys.
#include <aerie/imu_t.hpp>
#include <aerie/nav_state_t.hpp>
#include <aerie/pose_t.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "air/nav/nav_config.hpp"
#include "air/nav/node/mono_nav_node.hpp"
#include "tests/support/test_support.hpp"

using namespace aerie;

namespace {

aerie::imu_t still_imu(int64_t utime) {
  aerie::imu_t m{};
  m.utime = utime;
  m.angular_velocity[0] = 0.003;
  m.linear_acceleration[2] = 9.81;
  m.orientation[0] = 1.0;
  return m;
}

aerie::pose_t mono_pose(int64_t utime, int8_t state) {
  aerie::pose_t p{};
  p.utime = utime;
  p.orientation[0] = 1.0;
  p.position[0] = 0.5;
  p.status = static_cast<int8_t>(state | aerie::pose_t::SCALE_ARBITRARY);
  return p;
}

}  // namespace

TEST(MonoNavNode, SaysScaleUnknownWithoutAccelerationAndCountsBadPoses) {
  bus::Bus bus("memq://");
  nav::NavConfig cfg = nav::load_nav_config(util::Config::parse("source: mono\n", "nav-mono.yaml"));
  ASSERT_EQ(cfg.source, nav::NavConfig::Source::Mono);
  nav::MonoNavNode node(bus, cfg);
  std::vector<aerie::nav_state_t> states;
  bus.subscribe<aerie::nav_state_t>("NAV_STATE", [&](const aerie::nav_state_t& m, const bus::ReceiveInfo&) { states.push_back(m); });
  auto drain = [&] {
    while (bus.handle(0) > 0) {
    }
  };
  int64_t t = 1'000'000;
  for (int k = 0; k < 210; ++k) {
    bus.publish("IMU", still_imu(t += 5000));
    drain();
  }
  ASSERT_EQ(states.size(), 210u);
  EXPECT_EQ(states.back().status, aerie::nav_state_t::SCALE_UNKNOWN);  // aligned, no scale
  bus.publish("MONO_POSE", mono_pose(t - 2500, aerie::pose_t::INITIALISING));  // no map yet
  bus.publish("VO_POSE", mono_pose(t - 2400, aerie::pose_t::OK));              // not subscribed in mono mode
  for (int k = 0; k < 20; ++k) {
    bus.publish("MONO_POSE", mono_pose(t - 2500, aerie::pose_t::OK));
    for (int j = 0; j < 10; ++j) bus.publish("IMU", still_imu(t += 5000));
    drain();
  }
  aerie::pose_t nan = mono_pose(t - 2500, aerie::pose_t::OK);
  nan.position[1] = std::nan("");
  aerie::pose_t skew = mono_pose(t - 2000, aerie::pose_t::OK);
  skew.orientation[0] = 1.2;
  aerie::pose_t lost = mono_pose(t - 1500, aerie::pose_t::LOST);
  for (const auto& p : {nan, skew, lost}) bus.publish("MONO_POSE", p);
  bus.publish("IMU", still_imu(t += 5000));
  drain();

  EXPECT_EQ(node.counter("mono_initialising"), 1);
  EXPECT_EQ(node.counter("vo"), 20);
  EXPECT_EQ(node.counter("vo_refused"), 2);
  EXPECT_EQ(node.counter("vo_not_tracking"), 1);
  EXPECT_EQ(node.filter().counters().vo_invalid, 2);
  EXPECT_EQ(node.filter().counters().vo_not_unit, 1);
  EXPECT_EQ(node.filter().counters().vo_anchors, 1);  // the first OK pose after INITIALISING set the frame
  EXPECT_EQ(node.filter().counters().vision_resets, 0);
  EXPECT_EQ(node.filter().counters().vo_applied, 19);
  EXPECT_EQ(node.filter().scale_status(), nav::ScaleStatus::Unknown);
  const aerie::nav_state_t& s = states.back();
  EXPECT_EQ(s.status, aerie::nav_state_t::SCALE_UNKNOWN);
  EXPECT_NE(s.reason.find("SCALE_UNKNOWN"), std::string::npos) << s.reason;
  EXPECT_NE(s.reason.find("acceleration"), std::string::npos) << s.reason;
  EXPECT_EQ(s.vo_applied, 19);
  EXPECT_NEAR(s.position[0], 0.0, 1e-3);  // still: the poses agree with the anchor

  // A RESET (a new map) re-anchors and resets the scale.
  bus.publish("MONO_POSE", mono_pose(t - 2500, aerie::pose_t::RESET));
  bus.publish("IMU", still_imu(t += 5000));
  drain();
  EXPECT_EQ(node.filter().counters().vision_resets, 1);
  EXPECT_NEAR(node.filter().log_scale_sigma(), cfg.mono.scale_prior_sigma, 1e-9);
}

TEST(MonoNavNode, ConfigReadsSourceAndMonoKeysAndIsStrict) {
  const nav::NavConfig file = nav::load_nav_config(util::Config::load(AERIE_SOURCE_DIR "/config/nav.yaml"));
  const nav::NavConfig defaults = nav::load_nav_config(util::Config());
  EXPECT_EQ(file.source, nav::NavConfig::Source::Stereo);
  EXPECT_EQ(file.mono_channel, "MONO_POSE");
  EXPECT_EQ(file.mono.scale_prior, defaults.mono.scale_prior);
  EXPECT_EQ(file.mono.scale_prior_sigma, defaults.mono.scale_prior_sigma);
  EXPECT_EQ(file.mono.scale_sigma_ok, defaults.mono.scale_sigma_ok);
  EXPECT_EQ(file.mono.min_velocity_change_m_s, defaults.mono.min_velocity_change_m_s);
  EXPECT_EQ(file.mono.jump_poses, defaults.mono.jump_poses);
  EXPECT_NEAR(file.mono.rotation_sigma_rad, defaults.mono.rotation_sigma_rad, 1e-15);
  EXPECT_EQ(file.mono.position_sigma_m, defaults.mono.position_sigma_m);
  EXPECT_EQ(file.mono.noise, defaults.mono.noise);
  const nav::NavConfig m = nav::load_nav_config(util::Config::parse(
      "source: mono\nmono: {channel: CAM_MONO_POSE, scale_prior: 2.5, scale_sigma_ok: 0.05, noise: message}\n", "m.yaml"));
  EXPECT_EQ(m.mono_channel, "CAM_MONO_POSE");
  EXPECT_EQ(m.mono.scale_prior, 2.5);
  EXPECT_EQ(m.mono.scale_sigma_ok, 0.05);
  EXPECT_EQ(m.mono.noise, nav::VoNoise::Message);
  auto refused = [](const std::string& yaml, const std::string& needle) {
    try {
      nav::load_nav_config(util::Config::parse(yaml, "bad.yaml"));
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
      return true;
    }
    return false;
  };
  EXPECT_TRUE(refused("source: lidar\n", "source must be stereo or mono"));
  EXPECT_TRUE(refused("mono: {scale_prior: -1}\n", "mono.scale_prior"));
  EXPECT_TRUE(refused("mono: {scale_sigma: 0.1}\n", "scale_sigma"));  // unknown key
  EXPECT_TRUE(refused("mono: {noise: guess}\n", "mono.noise"));
  EXPECT_TRUE(refused("mono: {jump_poses: 0}\n", "mono.jump_poses"));
  EXPECT_TRUE(refused("source: mono\nresume: {state_file: /tmp/x.state}\n", "stereo only"));
}
