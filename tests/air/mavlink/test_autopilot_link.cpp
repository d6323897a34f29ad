// The bridge's logic against a scripted autopilot: link up and lost, a second autopilot refused,
// arming and take-off, the offboard entry only after a second of setpoints, a refusal shown
// with its reason, retries with the confirmation counter, a stale control_cmd_t stopping the
// stream, odometry and landing targets, and signing both ways.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "air/mavlink/autopilot_link.hpp"
#include "common/mavlink/modes.hpp"

namespace aerie::bridge {
namespace {

namespace mav = aerie::mavlink;
constexpr int64_t kMs = 1000;

// The frames of `bytes` (several frames back to back), decoded by a parser of our own.
std::vector<mav::Frame> frames_of(const std::vector<std::vector<uint8_t>>& out, mav::Parser& parser) {
  std::vector<mav::Frame> frames;
  for (const auto& b : out)
    parser.feed(b, [&](const mav::Frame& f) { frames.push_back(f); });
  return frames;
}

template <class Msg>
std::vector<Msg> only(const std::vector<mav::Frame>& frames) {
  std::vector<Msg> out;
  for (const auto& f : frames)
    if (f.msgid == Msg::kId) out.push_back(mav::decode<Msg>(f));
  return out;
}

// A scripted PX4 on system 1, component 1.
struct FakePx4 {
  uint8_t seq = 0;
  bool armed = false;
  uint32_t custom_mode = mav::px4::custom_mode(mav::px4::kPosctl);
  template <class Msg>
  std::vector<uint8_t> frame(const Msg& m, uint8_t sysid = 1) {
    return mav::encode(m, {sysid, 1, seq++});
  }
  std::vector<uint8_t> heartbeat(uint8_t sysid = 1) {
    mav::Heartbeat hb;
    hb.type = mav::mav_type::kQuadrotor;
    hb.autopilot = mav::mav_autopilot::kPx4;
    hb.base_mode = mav::mav_mode_flag::kCustomModeEnabled | (armed ? mav::mav_mode_flag::kSafetyArmed : 0);
    hb.custom_mode = custom_mode;
    hb.system_status = mav::mav_state::kStandby;
    hb.mavlink_version = 3;
    return frame(hb, sysid);
  }
  std::vector<uint8_t> ack(uint16_t command, uint8_t result) {
    mav::CommandAck a;
    a.command = command;
    a.result = result;
    return frame(a);
  }
  std::vector<uint8_t> text(const std::string& s) {
    mav::Statustext st;
    st.severity = 4;
    std::copy(s.begin(), s.begin() + std::min<size_t>(s.size(), 50), st.text.begin());
    return frame(st);
  }
};

struct Fixture : ::testing::Test {
  BridgeConfig cfg;
  FakePx4 px4;
  mav::Parser wire;  // what the autopilot would read
  std::unique_ptr<AutopilotLink> link;
  int64_t now = 0;
  // Stream-rate requests left out (one test has them): the other tests script every answer.
  void SetUp() override {
    cfg.imu_rate_hz = cfg.attitude_rate_hz = cfg.local_position_rate_hz = cfg.extended_state_rate_hz =
        cfg.battery_rate_hz = 0;
    link = std::make_unique<AutopilotLink>(cfg);
  }
  std::vector<mav::Frame> poll() { return frames_of(link->poll(now), wire); }
  void hear(const std::vector<uint8_t>& bytes) { link->receive(bytes, now); }
  ControlInput control(int mode, Eigen::Vector3d v = Eigen::Vector3d::Zero()) {
    ControlInput c;
    c.utime = now;
    c.mode = mode;
    c.velocity = v;
    return c;
  }
};

TEST_F(Fixture, HeartbeatsAsAnOnboardControllerAndTheLinkComesUpAndIsLost) {
  link = std::make_unique<AutopilotLink>(BridgeConfig{});
  auto out = poll();
  auto hbs = only<mav::Heartbeat>(out);
  ASSERT_EQ(hbs.size(), 1u);
  EXPECT_EQ(hbs[0].type, mav::mav_type::kOnboardController);
  EXPECT_EQ(hbs[0].autopilot, mav::mav_autopilot::kInvalid);
  EXPECT_EQ(out[0].compid, 191);
  EXPECT_EQ(link->view().link, AutopilotView::Link::None);

  hear(px4.heartbeat());
  EXPECT_EQ(link->view().link, AutopilotView::Link::Ok);
  EXPECT_EQ(link->view().autopilot, mav::Autopilot::Px4);
  EXPECT_EQ(link->view().mode, "POSCTL");
  hear(px4.heartbeat(/*sysid=*/7));  // a second autopilot on the link
  EXPECT_EQ(link->counters().foreign_autopilot, 1);
  EXPECT_EQ(link->view().system_id, 1);

  // The five stream rates go out one after the other, each acknowledged.
  std::vector<float> intervals;
  for (int k = 0; k < 5; ++k) {
    for (const auto& c : only<mav::CommandLong>(poll())) {
      EXPECT_EQ(c.command, mav::mav_cmd::kSetMessageInterval);
      intervals.push_back(c.param1);
      hear(px4.ack(c.command, mav::mav_result::kAccepted));
    }
  }
  EXPECT_EQ(intervals, (std::vector<float>{105, 31, 32, 245, 147}));

  now += 2900 * kMs;
  poll();
  EXPECT_EQ(link->view().link, AutopilotView::Link::Ok);
  now += 200 * kMs;  // 3.1 s without a heartbeat
  poll();
  EXPECT_EQ(link->view().link, AutopilotView::Link::Lost);
  EXPECT_EQ(link->counters().link_losses, 1);
  hear(px4.heartbeat());
  poll();
  EXPECT_EQ(link->view().link, AutopilotView::Link::Ok);
}

TEST_F(Fixture, TakeoffArmsThenTakesOffAndOffboardIsAskedForOnlyAfterASecondOfSetpoints) {
  hear(px4.heartbeat());
  link->on_control(control(3), now);  // TAKEOFF
  auto cmds = only<mav::CommandLong>(poll());
  ASSERT_EQ(cmds.size(), 1u);
  EXPECT_EQ(cmds[0].command, mav::mav_cmd::kComponentArmDisarm);
  EXPECT_EQ(cmds[0].param1, 1.0f);
  hear(px4.ack(cmds[0].command, mav::mav_result::kAccepted));
  px4.armed = true;
  hear(px4.heartbeat());
  now += 50 * kMs;
  link->on_control(control(3), now);
  cmds = only<mav::CommandLong>(poll());
  ASSERT_EQ(cmds.size(), 1u);
  EXPECT_EQ(cmds[0].command, mav::mav_cmd::kNavTakeoff);
  EXPECT_FLOAT_EQ(cmds[0].param7, 2.5f);
  hear(px4.ack(cmds[0].command, mav::mav_result::kAccepted));

  // The pilot flies: setpoints at 20 Hz, DO_SET_MODE OFFBOARD once they have run for 1 s.
  int setpoints = 0;
  int64_t mode_asked_at = -1;
  const int64_t stream_start = now + 50 * kMs;
  for (int k = 0; k < 40; ++k) {
    now += 50 * kMs;
    link->on_control(control(1, {0.5, 0, 0}), now);
    const auto out = poll();
    for (const auto& sp : only<mav::SetPositionTargetLocalNed>(out)) {
      ++setpoints;
      EXPECT_EQ(sp.coordinate_frame, mav::mav_frame::kBodyNed);
      EXPECT_FLOAT_EQ(sp.vx, 0.5f);
    }
    for (const auto& c : only<mav::CommandLong>(out)) {
      ASSERT_EQ(c.command, mav::mav_cmd::kDoSetMode);
      EXPECT_EQ(c.param2, mav::px4::kOffboard);
      if (mode_asked_at < 0) mode_asked_at = now;
      hear(px4.ack(c.command, mav::mav_result::kAccepted));
      px4.custom_mode = mav::px4::custom_mode(mav::px4::kOffboard);
      hear(px4.heartbeat());
    }
  }
  EXPECT_EQ(setpoints, 40);
  EXPECT_EQ(mode_asked_at - stream_start, 1000 * kMs);
  EXPECT_TRUE(link->view().in_companion_mode);
  EXPECT_EQ(link->view().mode, "OFFBOARD");

  // The pilot falls silent: the stream stops after control_timeout_s, so PX4's failsafe acts.
  int after = 0;
  for (int k = 0; k < 20; ++k) {
    now += 50 * kMs;
    after += static_cast<int>(only<mav::SetPositionTargetLocalNed>(poll()).size());
  }
  EXPECT_EQ(after, 10);  // 0.5 s more of the last command (control_timeout_s), then nothing
  EXPECT_EQ(link->counters().control_stale, 1);
}

TEST_F(Fixture, ARefusalIsShownWithTheAutopilotsReasonAndAnUnansweredCommandTimesOut) {
  hear(px4.heartbeat());
  link->request_arm(true, now);
  auto cmds = only<mav::CommandLong>(poll());
  std::erase_if(cmds, [](const auto& c) { return c.command != mav::mav_cmd::kComponentArmDisarm; });
  ASSERT_EQ(cmds.size(), 1u);
  hear(px4.text("Arming denied: system health failures"));
  hear(px4.ack(mav::mav_cmd::kComponentArmDisarm, mav::mav_result::kDenied));
  EXPECT_EQ(link->view().last_command, "MAV_CMD_COMPONENT_ARM_DISARM");
  EXPECT_EQ(link->view().last_result, "DENIED (Arming denied: system health failures)");
  EXPECT_EQ(link->counters().commands_refused, 1);
  const auto log = link->take_log();
  EXPECT_NE(std::find(log.begin(), log.end(),
                      "command MAV_CMD_COMPONENT_ARM_DISARM: DENIED (Arming denied: system health failures)"),
            log.end());

  // No answer: sent three times with confirmation 0, 1, 2, then reported.
  link->request_mode("AUTO.LAND", now);
  std::vector<int> confirmations;
  for (int k = 0; k < 40; ++k) {
    now += 100 * kMs;
    if (k % 10 == 0) hear(px4.heartbeat());
    for (const auto& c : only<mav::CommandLong>(poll()))
      if (c.command == mav::mav_cmd::kDoSetMode) {
        confirmations.push_back(c.confirmation);
        EXPECT_EQ(c.param2, mav::px4::kAuto);
        EXPECT_EQ(c.param3, mav::px4::kAutoLand);
      }
  }
  EXPECT_EQ(confirmations, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(link->counters().commands_timed_out, 1);
  EXPECT_EQ(link->view().last_result, "no COMMAND_ACK (timed out)");
  EXPECT_THROW(link->request_mode("GUIDED", now), std::invalid_argument);  // not a PX4 mode
}

TEST_F(Fixture, OdometryOnlyWhileTheFilterIsOkAtItsRateAndLandingTargetsInPx4sFrame) {
  hear(px4.heartbeat());
  NavSample s;
  s.valid = true;
  int sent = 0;
  for (int k = 0; k < 200; ++k) {  // 1 s of a 200 Hz filter
    now += 5 * kMs;
    s.utime = now;
    link->on_nav(s, now);
    sent += static_cast<int>(only<mav::Odometry>(poll()).size());
  }
  EXPECT_EQ(sent, 30);
  s.valid = false;
  link->on_nav(s, now + 40 * kMs);
  EXPECT_TRUE(only<mav::Odometry>(poll()).empty());

  link->on_target({now, {0, 0, 2}}, now);
  EXPECT_TRUE(only<mav::LandingTarget>(poll()).empty());  // PX4's position not known yet
  mav::AttitudeQuaternion att;
  att.q1 = 1;
  hear(px4.frame(att));
  mav::LocalPositionNed lp;
  lp.x = 3;
  lp.z = -2;
  hear(px4.frame(lp));
  link->on_target({now, {0, 0, 2}}, now);
  const auto targets = only<mav::LandingTarget>(poll());
  ASSERT_EQ(targets.size(), 1u);
  EXPECT_EQ(targets[0].frame, mav::mav_frame::kLocalNed);
  EXPECT_NEAR(targets[0].x, 3, 1e-5);
  EXPECT_NEAR(targets[0].z, 0, 1e-5);  // straight below a vehicle 2 m up: on the ground
}

TEST_F(Fixture, SignedBothWaysAndUnsignedFramesOfTheAutopilotRefused) {
  mav::Key key{};
  key.fill(0x42);
  link->enable_signing(key, 1, 0);
  wire.set_signing(key, true, [this] { return static_cast<uint64_t>(now / 10); });
  now = 5'000'000;
  const auto out = poll();
  ASSERT_FALSE(out.empty());
  EXPECT_TRUE(out[0].signature.has_value());
  EXPECT_EQ(wire.counters().bad_signature, 0u);

  mav::CommandAck ack;  // unsigned: refused (only HEARTBEAT and RADIO_STATUS pass unsigned)
  hear(px4.heartbeat());
  EXPECT_EQ(link->view().link, AutopilotView::Link::Ok);
  hear(px4.frame(ack));
  EXPECT_EQ(link->parser_counters().unsigned_refused, 1u);
  mav::Key other{};
  other.fill(0x17);
  mav::Signer wrong(other, 0, 0, [this] { return static_cast<uint64_t>(now / 10); });
  hear(mav::encode(ack, {1, 1, 9}, wrong));
  EXPECT_EQ(link->parser_counters().bad_signature, 1u);
}

TEST_F(Fixture, ThePrecisionLandingIsAskedForAtTheDescentAndTheTouchdownDoesNotReplaceIt) {
  cfg.landing_path = LandingPath::Autopilot;
  link = std::make_unique<AutopilotLink>(cfg);
  px4.armed = true;
  px4.custom_mode = mav::px4::custom_mode(mav::px4::kOffboard);
  hear(px4.heartbeat());
  auto lands = [&] {
    std::vector<mav::CommandLong> out;
    for (const auto& c : only<mav::CommandLong>(poll()))
      if (c.command == mav::mav_cmd::kNavLand) out.push_back(c);
    return out;
  };
  link->on_pilot_state(4, now);  // APPROACH: the pilot flies
  link->on_control(control(1, {0.2, 0, 0}), now);
  EXPECT_TRUE(lands().empty());
  now += 50 * kMs;
  link->on_pilot_state(5, now);  // DESCEND: the autopilot lands on LANDING_TARGET
  link->on_control(control(1, {0, 0, -0.3}), now);
  const auto first = lands();
  ASSERT_EQ(first.size(), 1u);
  EXPECT_EQ(first[0].param2, 2.0f);  // precision landing required: AUTO.PRECLAND
  hear(px4.ack(mav::mav_cmd::kNavLand, mav::mav_result::kAccepted));
  for (int k = 0; k < 10; ++k) {  // TOUCHDOWN: the pilot's LAND must not turn it into a plain AUTO.LAND
    now += 50 * kMs;
    link->on_pilot_state(6, now);
    link->on_control(control(4), now);
    EXPECT_TRUE(lands().empty());
  }
}

TEST_F(Fixture, TheAutopilotsImuComesOutInAeriesBodyFrame) {
  hear(px4.heartbeat());
  mav::AttitudeQuaternion att;  // facing east: +90 deg about NED's z (down)
  att.q1 = static_cast<float>(std::cos(M_PI / 4));
  att.q4 = static_cast<float>(std::sin(M_PI / 4));
  hear(px4.frame(att));
  mav::HighresImu imu;  // at rest, level: the specific force points up, -z in FRD; turning right
  imu.zacc = -9.81f;
  imu.xacc = 0.5f;   // accelerating forward
  imu.yacc = 0.25f;  // and to the right
  imu.zgyro = 0.1f;  // yawing clockwise seen from above
  hear(px4.frame(imu));
  const auto s = link->take_imu();
  ASSERT_TRUE(s);
  EXPECT_NEAR((s->linear_acceleration - Eigen::Vector3d(0.5, -0.25, 9.81)).norm(), 0, 1e-5);  // FLU
  EXPECT_NEAR((s->angular_velocity - Eigen::Vector3d(0, 0, -0.1)).norm(), 0, 1e-6);  // counter-clockwise positive
  ASSERT_TRUE(s->orientation);
  // The nose (body x) points east: in the z-up world (north, west, up) that is -y.
  const Eigen::Vector3d nose = *s->orientation * Eigen::Vector3d::UnitX();
  EXPECT_NEAR((nose - Eigen::Vector3d(0, -1, 0)).norm(), 0, 1e-6);
  const Eigen::Vector3d up = *s->orientation * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR((up - Eigen::Vector3d(0, 0, 1)).norm(), 0, 1e-6);
  EXPECT_FALSE(link->take_imu());  // taken once
}

TEST(BridgeConfig, RefusesValuesOutsideTheirRangeNamingTheKey) {
  BridgeConfig c;
  c.setpoint_rate_hz = 2;
  EXPECT_THROW(c.validate(), std::invalid_argument);
  try {
    load_bridge(util::Config::parse("setpoint_rate_hz: 1\n", "mavlink.yaml"));
    FAIL();
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("setpoint_rate_hz"), std::string::npos);
  }
  EXPECT_THROW(load_bridge(util::Config::parse("landing_path: magic\n", "mavlink.yaml")), std::invalid_argument);
  EXPECT_THROW(load_bridge(util::Config::parse("setpoint_hz: 20\n", "mavlink.yaml")), std::runtime_error);  // unknown key
  EXPECT_EQ(load_bridge(util::Config::parse("landing_path: autopilot\n", "m")).landing_path, LandingPath::Autopilot);
}

}  // namespace
}  // namespace aerie::bridge
