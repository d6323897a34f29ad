// aerie-mavlink's node on memq:// with in-memory endpoints: routing between the autopilot and a
// ground station (whole frames up, bytes down), AUTOPILOT_STATE on link-up, the setpoint for a
// CTRL_CMD written at once, and a lost link in status.
#include <aerie/autopilot_state_t.hpp>
#include <aerie/control_cmd_t.hpp>
#include <aerie/process_status_t.hpp>
#include <gtest/gtest.h>

#include <vector>

#include "air/mavlink/node/mavlink_node.hpp"
#include "common/mavlink/frame.hpp"

namespace aerie::bridge {
namespace {

namespace mav = aerie::mavlink;

struct Rig {
  bus::Bus bus{"memq://"};
  int64_t now = 1'000'000;
  std::unique_ptr<mav::Endpoint> autopilot, gcs;
  std::unique_ptr<MavlinkNode> node;
  std::vector<aerie::autopilot_state_t> states;
  Rig() {
    auto [ap_bridge, ap_far] = mav::memory_pipe("autopilot");
    auto [gcs_bridge, gcs_far] = mav::memory_pipe("gcs");
    autopilot = std::move(ap_far);
    gcs = std::move(gcs_far);
    BridgeConfig cfg;
    cfg.imu_rate_hz = cfg.attitude_rate_hz = cfg.local_position_rate_hz = cfg.extended_state_rate_hz =
        cfg.battery_rate_hz = 0;
    std::vector<std::unique_ptr<mav::Endpoint>> ground;
    ground.push_back(std::move(gcs_bridge));
    node = std::make_unique<MavlinkNode>(bus, AutopilotLink(cfg), std::move(ap_bridge), std::move(ground),
                                         MavlinkNodeOptions{}, [this] { return now; });
    bus.subscribe<aerie::autopilot_state_t>("AUTOPILOT_STATE", [this](const aerie::autopilot_state_t& m,
                                                                      const bus::ReceiveInfo&) { states.push_back(m); });
  }
  void settle() {
    while (bus.handle(0) > 0) {
    }
  }
  std::vector<mav::Frame> frames_at(mav::Endpoint& e) {
    std::vector<uint8_t> bytes;
    e.read(bytes);
    return mav::Parser().feed(bytes);
  }
};

std::vector<uint8_t> px4_heartbeat(bool armed, uint8_t seq) {
  mav::Heartbeat hb;
  hb.type = mav::mav_type::kQuadrotor;
  hb.autopilot = mav::mav_autopilot::kPx4;
  hb.base_mode = mav::mav_mode_flag::kCustomModeEnabled | (armed ? mav::mav_mode_flag::kSafetyArmed : 0);
  hb.custom_mode = mav::px4::custom_mode(mav::px4::kOffboard);
  hb.mavlink_version = 3;
  return mav::encode(hb, {1, 1, seq});
}

TEST(MavlinkNode, RoutesTheAutopilotToTheGroundStationAndOnlyWholeFramesBack) {
  Rig r;
  const auto hb = px4_heartbeat(true, 0);
  r.autopilot->write(hb);
  r.node->step();
  std::vector<uint8_t> down;
  r.gcs->read(down);
  EXPECT_EQ(down, hb);  // byte for byte
  r.settle();
  ASSERT_FALSE(r.states.empty());
  EXPECT_EQ(r.states.back().link, aerie::autopilot_state_t::LINK_OK);
  EXPECT_EQ(r.states.back().mode, "OFFBOARD");
  EXPECT_TRUE(r.states.back().armed);
  EXPECT_TRUE(r.states.back().aerie_in_control);
  EXPECT_EQ(r.states.back().estimator_flags, -1);  // none heard yet
  EXPECT_FALSE(r.states.back().local_position_valid);

  // The autopilot's estimate reaches AUTOPILOT_STATE: its flags, local position and attitude.
  mav::AttitudeQuaternion att;
  att.q1 = 1;
  mav::LocalPositionNed lp;
  lp.x = 1.5f;
  lp.z = -2.0f;
  lp.vy = 0.25f;
  mav::EstimatorStatus est;
  est.flags = 0x0433;  // attitude, velocity, positions: what EKF2 reports when it is healthy
  std::vector<uint8_t> more = mav::encode(att, {1, 1, 1});
  for (const auto& f : {mav::encode(lp, {1, 1, 2}), mav::encode(est, {1, 1, 3})}) more.insert(more.end(), f.begin(), f.end());
  r.autopilot->write(more);
  r.node->step();
  r.settle();
  const auto& st = r.states.back();
  EXPECT_EQ(st.estimator_flags, 0x0433);
  ASSERT_TRUE(st.local_position_valid);
  EXPECT_FLOAT_EQ(st.position_ned[0], 1.5f);
  EXPECT_FLOAT_EQ(st.position_ned[2], -2.0f);
  EXPECT_FLOAT_EQ(st.velocity_ned[1], 0.25f);
  EXPECT_FLOAT_EQ(st.attitude[0], 1.0f);
  r.gcs->read(down);  // routed to the ground station too

  // The ground station's command reaches the autopilot whole; the garbage around it does not.
  mav::CommandLong cmd;
  cmd.command = mav::mav_cmd::kComponentArmDisarm;
  cmd.target_system = 1;
  const auto frame = mav::encode(cmd, {255, 190, 7});
  std::vector<uint8_t> up = {0x01, 0x02, 0xFD, 0x03};
  up.insert(up.end(), frame.begin(), frame.end());
  up.push_back(0x55);
  r.gcs->write(up);
  r.node->step();
  const auto at_autopilot = r.frames_at(*r.autopilot);
  int routed = 0;
  for (const auto& f : at_autopilot)
    if (f.sysid == 255 && f.msgid == mav::CommandLong::kId) ++routed;
  EXPECT_EQ(routed, 1);
  EXPECT_EQ(r.node->status().counter("routed_up"), 1);
}

TEST(MavlinkNode, ACommandLeavesAsASetpointAtOnceAndALostLinkIsAnError) {
  Rig r;
  r.autopilot->write(px4_heartbeat(true, 0));
  r.node->step();
  r.frames_at(*r.autopilot);  // our heartbeat
  aerie::control_cmd_t c{};
  c.utime = r.now - 40'000;  // the camera frame it derives from, 40 ms ago
  c.mode = aerie::control_cmd_t::ACTIVE;
  c.velocity_body[0] = 0.7f;
  r.bus.publish("CTRL_CMD", c);
  r.settle();
  int setpoints = 0;
  for (const auto& f : r.frames_at(*r.autopilot))
    if (f.msgid == mav::SetPositionTargetLocalNed::kId) {
      ++setpoints;
      EXPECT_FLOAT_EQ(mav::decode<mav::SetPositionTargetLocalNed>(f).vx, 0.7f);
    }
  EXPECT_EQ(setpoints, 1);
  EXPECT_EQ(r.node->frame_to_wire_us(0.5), 40'000);

  r.now += 3'100'000;  // no heartbeat for 3.1 s
  r.node->step();
  EXPECT_EQ(r.node->status().counter("link_losses"), 1);
  r.settle();
  EXPECT_EQ(r.states.back().link, aerie::autopilot_state_t::LINK_LOST);
}

}  // namespace
}  // namespace aerie::bridge
