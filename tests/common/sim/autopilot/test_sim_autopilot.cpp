// SimAutopilot driven in simulation time with a real Multirotor: what a companion computer
// sees of PX4 / ArduCopter over MAVLink (docs/mavlink.md ("The simulator's autopilot")).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <string>
#include <vector>

#include "common/mavlink/modes.hpp"
#include "common/sim/autopilot/sim_autopilot.hpp"

namespace ap = aerie::sim::autopilot;
namespace mv = aerie::mavlink;
using aerie::sim::AutopilotCommand;
using aerie::sim::Multirotor;
using aerie::sim::MultirotorParams;
using aerie::sim::MultirotorState;
using Eigen::Vector3d;

namespace {

constexpr double kDt = 0.01;
constexpr uint8_t kCompanionSys = 1, kCompanionComp = 191;

std::string text_of(const mv::Statustext& s) {
  size_t n = 0;
  while (n < s.text.size() && s.text[n] != '\0') ++n;
  return std::string(s.text.data(), n);
}

MultirotorParams vehicle_params() {
  MultirotorParams p = MultirotorParams::by_name("ardrone");
  p.hold_drift_m_per_sqrt_s = 0;  // the autopilot's estimate is the only position error here
  return p;
}

// The autopilot, the vehicle and a companion computer that streams vision (truth + bias).
struct Rig {
  ap::SimAutopilot ap;
  Multirotor mr;
  double t = 0;
  std::vector<ap::Outbound> sent;  // everything the autopilot sent
  bool vision_on = false;
  Vector3d vision_bias = Vector3d::Zero();  // world ENU, m
  double next_vision = 0;
  double yaw0;

  explicit Rig(ap::Personality p, const ap::Params& params = {}, double yaw = 0.0)
      : ap(p, params), mr(vehicle_params(), initial(yaw)), yaw0(yaw) {}

  static MultirotorState initial(double yaw) {
    MultirotorState s;
    s.yaw = yaw;
    return s;
  }

  void receive(const mv::Message& m) { ap.receive(m, kCompanionSys, kCompanionComp, t); }

  ap::StepOutput step() {
    if (vision_on && t + 1e-9 >= next_vision) {  // ODOMETRY at 30 Hz, MAV_FRAME_LOCAL_FRD
      const Vector3d p = ap::enu_to_ned(mr.state().position + vision_bias);
      mv::Odometry o;
      o.time_usec = static_cast<uint64_t>(t * 1e6);
      o.frame_id = mv::mav_frame::kLocalFrd;
      o.child_frame_id = mv::mav_frame::kBodyFrd;
      o.x = static_cast<float>(p.x());
      o.y = static_cast<float>(p.y());
      o.z = static_cast<float>(p.z());
      o.q = {1, 0, 0, 0};
      receive(o);
      next_vision += 1.0 / 30.0;
    }
    ap::StepOutput out = ap.step(t, mr.state());
    sent.insert(sent.end(), out.messages.begin(), out.messages.end());
    mr.command(t, out.command);
    mr.step(t, kDt, Vector3d::Zero());
    if (mr.state().position.z() <= 0) mr.set_contact(0);
    t += kDt;
    return out;
  }
  void run(double seconds) {
    const int n = static_cast<int>(std::lround(seconds / kDt));
    for (int i = 0; i < n; ++i) step();
  }
  template <class Pred>
  bool run_until(Pred pred, double max_s) {
    const double end = t + max_s;
    while (t < end) {
      step();
      if (pred()) return true;
    }
    return false;
  }

  // Sends a COMMAND_LONG, steps once and returns its COMMAND_ACK result (-1 if none).
  int command(uint16_t cmd, std::array<float, 7> p, uint8_t confirmation = 0) {
    mv::CommandLong c;
    c.target_system = 1;
    c.target_component = 1;
    c.command = cmd;
    c.confirmation = confirmation;
    c.param1 = p[0], c.param2 = p[1], c.param3 = p[2], c.param4 = p[3];
    c.param5 = p[4], c.param6 = p[5], c.param7 = p[6];
    const size_t mark = sent.size();
    receive(c);
    step();
    for (size_t i = mark; i < sent.size(); ++i)
      if (auto* a = std::get_if<mv::CommandAck>(&sent[i].msg); a && a->command == cmd) {
        EXPECT_EQ(sent[i].target_component, kCompanionComp);
        return a->result;
      }
    return -1;
  }
  int arm(bool force = false) { return command(mv::mav_cmd::kComponentArmDisarm, {1, force ? 21196.0f : 0, 0, 0, 0, 0, 0}); }
  int disarm(bool force = false) {
    return command(mv::mav_cmd::kComponentArmDisarm, {0, force ? 21196.0f : 0, 0, 0, 0, 0, 0});
  }
  int px4_mode(uint8_t main, uint8_t sub = 0) {
    return command(mv::mav_cmd::kDoSetMode, {1, float(main), float(sub), 0, 0, 0, 0});
  }
  int copter_mode(uint8_t mode) { return command(mv::mav_cmd::kDoSetMode, {1, float(mode), 0, 0, 0, 0, 0}); }
  int takeoff(float alt) { return command(mv::mav_cmd::kNavTakeoff, {0, 0, 0, 0, 0, 0, alt}); }

  void setpoint(const Vector3d& v, uint8_t frame = mv::mav_frame::kLocalNed, uint16_t mask = 0x05C7,
                float yaw_rate = 0) {
    mv::SetPositionTargetLocalNed s;
    s.target_system = 1;
    s.target_component = 1;
    s.coordinate_frame = frame;
    s.type_mask = mask;
    s.vx = float(v.x()), s.vy = float(v.y()), s.vz = float(v.z());
    s.yaw_rate = yaw_rate;
    receive(s);
  }

  template <class M>
  std::vector<M> all(size_t from = 0) const {
    std::vector<M> r;
    for (size_t i = from; i < sent.size(); ++i)
      if (auto* m = std::get_if<M>(&sent[i].msg)) r.push_back(*m);
    return r;
  }
  // STATUSTEXTs, long ones reassembled from their chunks (id != 0, chunk_seq; a NUL ends one).
  std::vector<std::string> texts(size_t from = 0) const {
    std::vector<std::string> r;
    std::string partial;
    int expect_seq = 0;
    for (const auto& s : all<mv::Statustext>(from)) {
      const std::string piece = text_of(s);
      if (s.id == 0) {
        r.push_back(piece);
        continue;
      }
      EXPECT_EQ(s.chunk_seq, expect_seq);
      partial += piece;
      ++expect_seq;
      if (piece.size() < s.text.size()) {
        r.push_back(partial);
        partial.clear();
        expect_seq = 0;
      }
    }
    return r;
  }
  bool said(const std::string& part, size_t from = 0) const {
    for (const auto& s : texts(from))
      if (s.find(part) != std::string::npos) return true;
    return false;
  }
  mv::Heartbeat last_heartbeat() const { return all<mv::Heartbeat>().back(); }

  // Vision on for a second (the estimate converges), armed, up at `alt` and settled.
  void airborne_px4(float alt = 2.5f) {
    vision_on = true;
    run(0.5);
    ASSERT_EQ(arm(), mv::mav_result::kAccepted);
    ASSERT_EQ(takeoff(alt), mv::mav_result::kAccepted);
    ASSERT_TRUE(run_until([&] { return ap.mode() == ap::FlightMode::Hold; }, 20));
    run(3.0);
  }
  void airborne_copter(float alt = 2.5f) {
    mv::SetGpsGlobalOrigin o;
    o.target_system = 1;
    o.latitude = 473977420;
    o.longitude = 85455940;
    receive(o);
    vision_on = true;
    run(0.5);
    ASSERT_EQ(copter_mode(mv::copter::kGuided), mv::mav_result::kAccepted);
    ASSERT_EQ(arm(), mv::mav_result::kAccepted);
    ASSERT_EQ(takeoff(alt), mv::mav_result::kAccepted);
    ASSERT_TRUE(run_until([&] { return ap.mode() == ap::FlightMode::Guided; }, 20));
    run(3.0);
  }
};

}  // namespace

// --- frames ------------------------------------------------------------------------------------

TEST(SimAutopilotFrames, NedToHeadingBothWays) {
  // Facing east (ENU yaw 0): north = left, east = forward, down = -up.
  Vector3d h = ap::ned_to_heading({1, 0, 0}, 0.0);
  EXPECT_NEAR(h.x(), 0, 1e-12);
  EXPECT_NEAR(h.y(), 1, 1e-12);
  EXPECT_NEAR(h.z(), 0, 1e-12);
  h = ap::ned_to_heading({0, 1, 0.5}, 0.0);
  EXPECT_TRUE(h.isApprox(Vector3d(1, 0, -0.5), 1e-12));
  // Facing north (ENU yaw 90 deg): north = forward, east = right (-left).
  h = ap::ned_to_heading({1, 2, 0}, std::numbers::pi / 2);
  EXPECT_TRUE(h.isApprox(Vector3d(1, -2, 0), 1e-12)) << h.transpose();
  // And back, for any heading.
  for (double yaw : {-3.0, -1.0, 0.3, 2.5}) {
    const Vector3d v(0.3, -1.2, 0.7);
    EXPECT_TRUE(ap::heading_to_ned(ap::ned_to_heading(v, yaw), yaw).isApprox(v, 1e-12));
    EXPECT_TRUE(ap::ned_to_heading(ap::heading_to_ned(v, yaw), yaw).isApprox(v, 1e-12));
  }
  EXPECT_TRUE(ap::heading_to_ned({0, 1, 0}, 0.0).isApprox(Vector3d(1, 0, 0), 1e-12));  // left = north facing east
  EXPECT_TRUE(ap::body_ned_to_heading({1, 0.5, -0.2}).isApprox(Vector3d(1, -0.5, 0.2), 1e-12));
  // FRD -> NED for a level vehicle facing east: forward = east, right = south, down = down.
  const Eigen::Matrix3d R = ap::ned_from_frd(0, 0, 0);
  EXPECT_TRUE((R * Vector3d(1, 0, 0)).isApprox(Vector3d(0, 1, 0), 1e-12));
  EXPECT_TRUE((R * Vector3d(0, 1, 0)).isApprox(Vector3d(-1, 0, 0), 1e-12));
  EXPECT_TRUE((R * Vector3d(0, 0, 1)).isApprox(Vector3d(0, 0, 1), 1e-12));
}

TEST(SimAutopilotFrames, OffboardSetpointsReachTheVehicleInItsHeadingFrame) {
  Rig r(ap::Personality::Px4);  // facing east
  r.airborne_px4();
  for (int i = 0; i < 30; ++i) {  // stream for 1.5 s at 20 Hz
    r.setpoint({0, 0, 0});
    r.run(0.05);
  }
  ASSERT_EQ(r.px4_mode(mv::px4::kOffboard), mv::mav_result::kAccepted);
  const double yaw = r.mr.state().yaw;
  // NED north 1 m/s with the vehicle facing east = ENU +y = heading-frame left.
  r.setpoint({1, 0, 0}, mv::mav_frame::kLocalNed, 0x05C7, 0.2f);
  AutopilotCommand c = r.step().command;
  ASSERT_EQ(c.mode, AutopilotCommand::Mode::Velocity);
  const Vector3d expect_local = ap::ned_to_heading({1, 0, 0}, yaw);
  EXPECT_NEAR(c.velocity.x(), expect_local.x(), 1e-9);
  EXPECT_NEAR(c.velocity.y(), expect_local.y(), 1e-9);
  EXPECT_NEAR(c.velocity.y(), 1.0, 0.02);  // yaw ~0
  EXPECT_NEAR(c.yaw_rate_deg_s, 0.2 * 180 / std::numbers::pi, 1e-4);  // NED yaw rate = clockwise
  // BODY_NED forward 1, up 0.5 (z -0.5) = heading forward, up.
  r.setpoint({1, 0, -0.5}, mv::mav_frame::kBodyNed);
  c = r.step().command;
  EXPECT_NEAR(c.velocity.x(), 1.0, 1e-4);
  EXPECT_NEAR(c.velocity.y(), 0.0, 1e-4);
  EXPECT_NEAR(c.velocity.z(), 0.5, 1e-6);
  // Frames and masks PX4 does not fly here are refused (counted) and change nothing.
  const auto refused = r.ap.setpoints_refused();
  r.setpoint({5, 0, 0}, 12 /* BODY_FRD */);
  r.setpoint({5, 0, 0}, mv::mav_frame::kLocalNed, 0x0FF8 /* position */);
  EXPECT_EQ(r.ap.setpoints_refused(), refused + 2);
  c = r.step().command;
  EXPECT_NEAR(c.velocity.x(), 1.0, 1e-3);
  // The vehicle flies it: 2 s of north at 1 m/s moves it north.
  const double y0 = r.mr.state().position.y();
  for (int i = 0; i < 40; ++i) {
    r.setpoint({1, 0, 0});
    r.run(0.05);
  }
  EXPECT_GT(r.mr.state().position.y() - y0, 1.4);
  EXPECT_NEAR(r.mr.state().position.x(), 0, 0.3);
}

// --- heartbeat, arming, modes ------------------------------------------------------------------

TEST(SimAutopilot, HeartbeatAt1HzWithPersonalityAndModes) {
  Rig px(ap::Personality::Px4), ac(ap::Personality::ArduCopter);
  px.run(3.0);
  ac.run(3.0);
  const auto h = px.all<mv::Heartbeat>();
  ASSERT_EQ(h.size(), 3u);  // t = 0, 1, 2
  EXPECT_EQ(h[0].type, mv::mav_type::kQuadrotor);
  EXPECT_EQ(h[0].autopilot, mv::mav_autopilot::kPx4);
  EXPECT_EQ(h[0].custom_mode, mv::px4::custom_mode(mv::px4::kPosctl));
  EXPECT_EQ(h[0].custom_mode, 3u << 16);
  EXPECT_TRUE(h[0].base_mode & mv::mav_mode_flag::kCustomModeEnabled);
  EXPECT_FALSE(h[0].base_mode & mv::mav_mode_flag::kSafetyArmed);
  EXPECT_EQ(h[0].system_status, mv::mav_state::kStandby);
  EXPECT_EQ(h[0].mavlink_version, 3);
  const auto a = ac.all<mv::Heartbeat>();
  ASSERT_EQ(a.size(), 3u);
  EXPECT_EQ(a[0].autopilot, mv::mav_autopilot::kArdupilotmega);
  EXPECT_EQ(a[0].custom_mode, 0u);  // STABILIZE
  EXPECT_EQ(ac.ap.mode_name(), "STABILIZE");
  EXPECT_EQ(ap::SimAutopilot::kSystemId, 1);
  EXPECT_EQ(px.sent[0].target_system, 0);  // broadcast
}

TEST(SimAutopilot, ArmRefusedWithoutPositionThenAccepted) {
  Rig r(ap::Personality::Px4);
  r.run(0.2);
  EXPECT_EQ(r.arm(), mv::mav_result::kTemporarilyRejected);
  EXPECT_TRUE(r.said("Arming denied: no valid local position, required by POSCTL")) << r.texts().back();
  EXPECT_FALSE(r.ap.armed());
  // With the RC required (COM_RC_IN_MODE 0..3) it is refused for that reason even with vision.
  ap::Params rc;
  rc.COM_RC_IN_MODE = 0;
  Rig q(ap::Personality::Px4, rc);
  q.vision_on = true;
  q.run(0.3);
  EXPECT_EQ(q.arm(), mv::mav_result::kTemporarilyRejected);
  EXPECT_TRUE(q.said("no manual control input"));
  // Vision arrives: the local position is valid and arming is accepted.
  r.vision_on = true;
  r.run(0.3);
  EXPECT_TRUE(r.ap.position_valid());
  EXPECT_EQ(r.arm(), mv::mav_result::kAccepted);
  EXPECT_TRUE(r.ap.armed());
  r.run(1.0);
  const auto h = r.last_heartbeat();
  EXPECT_TRUE(h.base_mode & mv::mav_mode_flag::kSafetyArmed);
  EXPECT_EQ(h.system_status, mv::mav_state::kActive);
  // Disarm on the ground is accepted.
  EXPECT_EQ(r.disarm(), mv::mav_result::kAccepted);
  EXPECT_FALSE(r.ap.armed());
}

TEST(SimAutopilot, DisarmRefusedInFlightUnlessForced) {
  Rig r(ap::Personality::Px4);
  r.airborne_px4();
  EXPECT_EQ(r.disarm(), mv::mav_result::kDenied);
  EXPECT_TRUE(r.said("Disarming denied: not landed"));
  EXPECT_TRUE(r.ap.armed());
  EXPECT_EQ(r.disarm(true), mv::mav_result::kAccepted);
  EXPECT_FALSE(r.ap.armed());
}

TEST(SimAutopilot, ArduCopterNeedsOriginBeforeExternalNav) {
  Rig r(ap::Personality::ArduCopter);
  r.vision_on = true;
  r.run(0.5);
  EXPECT_FALSE(r.ap.position_valid());  // vision ignored without an origin
  EXPECT_EQ(r.copter_mode(mv::copter::kGuided), mv::mav_result::kFailed);
  EXPECT_TRUE(r.said("Mode change to GUIDED failed: requires position"));
  mv::SetGpsGlobalOrigin o;
  o.target_system = 1;
  o.latitude = 1;
  r.receive(o);
  r.run(0.3);
  EXPECT_TRUE(r.ap.position_valid());
  EXPECT_TRUE(r.said("EKF3 IMU0 is using external nav data"));
  EXPECT_EQ(r.all<mv::GpsGlobalOrigin>().size(), 1u);
  EXPECT_EQ(r.copter_mode(mv::copter::kGuided), mv::mav_result::kAccepted);
  EXPECT_EQ(r.last_heartbeat().custom_mode, 0u);  // the heartbeat of the next second says GUIDED
  r.run(1.0);
  EXPECT_EQ(r.last_heartbeat().custom_mode, 4u);
  EXPECT_EQ(r.copter_mode(3 /* AUTO: not modelled */), mv::mav_result::kFailed);
  EXPECT_EQ(r.arm(), mv::mav_result::kAccepted);
}

TEST(SimAutopilot, UnknownCommandIsUnsupportedAndTakeoffNeedsArming) {
  Rig r(ap::Personality::Px4);
  r.vision_on = true;
  r.run(0.3);
  EXPECT_EQ(r.command(31000, {0, 0, 0, 0, 0, 0, 0}), mv::mav_result::kUnsupported);
  EXPECT_EQ(r.takeoff(3), mv::mav_result::kTemporarilyRejected);
  EXPECT_TRUE(r.said("Takeoff denied: disarmed"));
  EXPECT_EQ(r.px4_mode(mv::px4::kAuto, 7), mv::mav_result::kDenied);
  EXPECT_EQ(r.arm(), mv::mav_result::kAccepted);
  EXPECT_EQ(r.takeoff(3), mv::mav_result::kAccepted);
  EXPECT_EQ(r.ap.mode_name(), "AUTO.TAKEOFF");
  ASSERT_TRUE(r.run_until([&] { return r.ap.mode() == ap::FlightMode::Hold; }, 15));
  EXPECT_NEAR(r.mr.state().position.z(), 3.0, 0.35);
  EXPECT_TRUE(r.said("Takeoff complete"));
  r.run(3);
  EXPECT_NEAR(r.mr.state().position.z(), 3.0, 0.05);
}

TEST(SimAutopilot, CommandRetryIsNotExecutedTwice) {
  Rig r(ap::Personality::Px4);
  const std::array<float, 7> p{float(mv::AutopilotVersion::kId), 0, 0, 0, 0, 0, 0};
  EXPECT_EQ(r.command(mv::mav_cmd::kRequestMessage, p, 0), mv::mav_result::kAccepted);
  EXPECT_EQ(r.command(mv::mav_cmd::kRequestMessage, p, 1), mv::mav_result::kAccepted);  // retry
  EXPECT_EQ(r.command(mv::mav_cmd::kRequestMessage, p, 2), mv::mav_result::kAccepted);  // retry
  EXPECT_EQ(r.all<mv::AutopilotVersion>().size(), 1u);
  EXPECT_EQ(r.ap.commands_executed(), 1);
  EXPECT_EQ(r.all<mv::CommandAck>().size(), 3u);
  // A new command (confirmation 0) executes again.
  EXPECT_EQ(r.command(mv::mav_cmd::kRequestMessage, p, 0), mv::mav_result::kAccepted);
  EXPECT_EQ(r.all<mv::AutopilotVersion>().size(), 2u);
  const auto v = r.all<mv::AutopilotVersion>()[0];
  EXPECT_TRUE(v.capabilities & 8192u);  // MAVLINK2
  EXPECT_TRUE(v.capabilities & 128u);   // SET_POSITION_TARGET_LOCAL_NED
  EXPECT_TRUE(v.capabilities & 16u);    // PX4: PARAM_ENCODE_BYTEWISE
  EXPECT_EQ(v.flight_sw_version >> 24, 1u);
  // A retried arm is acknowledged once executed: one "Armed" text, not two.
  r.vision_on = true;
  r.run(0.3);
  const size_t mark = r.sent.size();
  EXPECT_EQ(r.command(mv::mav_cmd::kComponentArmDisarm, {1, 0, 0, 0, 0, 0, 0}, 0), mv::mav_result::kAccepted);
  EXPECT_EQ(r.command(mv::mav_cmd::kComponentArmDisarm, {1, 0, 0, 0, 0, 0, 0}, 1), mv::mav_result::kAccepted);
  int armed_texts = 0;
  for (const auto& s : r.texts(mark)) armed_texts += s == "Armed by external command";
  EXPECT_EQ(armed_texts, 1);
}

TEST(SimAutopilot, ParamRequestReadIsAnswered) {
  ap::Params params;
  params.PLD_MAX_SRCH = 4;
  Rig r(ap::Personality::Px4, params);
  auto request = [&](const std::string& name, int16_t index = -1) {
    mv::ParamRequestRead q;
    q.target_system = 1;
    q.target_component = 1;
    std::memcpy(q.param_id.data(), name.data(), std::min<size_t>(name.size(), 16));
    q.param_index = index;
    const size_t mark = r.sent.size();
    r.receive(q);
    r.step();
    return r.all<mv::ParamValue>(mark);
  };
  auto v = request("COM_OF_LOSS_T");
  ASSERT_EQ(v.size(), 1u);
  EXPECT_EQ(std::string(v[0].param_id.data(), 13), "COM_OF_LOSS_T");
  EXPECT_FLOAT_EQ(v[0].param_value, 1.0f);
  EXPECT_EQ(v[0].param_type, 9);  // REAL32
  EXPECT_EQ(v[0].param_count, r.ap.param_count());
  EXPECT_EQ(v[0].param_index, 0);
  v = request("PLD_MAX_SRCH");  // INT32, PX4 encodes it bytewise
  ASSERT_EQ(v.size(), 1u);
  EXPECT_EQ(v[0].param_type, 6);
  int32_t iv = 0;
  std::memcpy(&iv, &v[0].param_value, 4);
  EXPECT_EQ(iv, 4);
  const uint16_t idx = v[0].param_index;
  v = request("", static_cast<int16_t>(idx));  // by index
  ASSERT_EQ(v.size(), 1u);
  EXPECT_EQ(std::string(v[0].param_id.data(), 12), "PLD_MAX_SRCH");
  EXPECT_TRUE(request("NO_SUCH_PARAM").empty());
  EXPECT_TRUE(request("GUID_TIMEOUT").empty());  // not a PX4 parameter
  EXPECT_NEAR(r.ap.param("PLD_HACC_RAD")->value, 0.2, 1e-12);

  Rig c(ap::Personality::ArduCopter);
  EXPECT_NEAR(c.ap.param("GUID_TIMEOUT")->value, 3.0, 1e-12);
  EXPECT_FALSE(c.ap.param("COM_OF_LOSS_T"));
  mv::ParamRequestRead q;
  q.target_system = 1;
  q.target_component = 1;
  std::memcpy(q.param_id.data(), "PLND_TYPE", 9);
  q.param_index = -1;
  c.receive(q);
  c.step();
  const auto cv = c.all<mv::ParamValue>();
  ASSERT_EQ(cv.size(), 1u);
  EXPECT_FLOAT_EQ(cv[0].param_value, 1.0f);  // ArduPilot: C cast
  EXPECT_EQ(cv[0].param_count, c.ap.param_count());
}

TEST(SimAutopilot, ParamsValidateNamesTheField) {
  ap::Params p;
  p.COM_OBL_RC_ACT = 7;
  try {
    p.validate();
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("COM_OBL_RC_ACT"), std::string::npos) << e.what();
  }
  ap::Params q;
  q.PLD_HACC_RAD = -1;
  EXPECT_THROW(ap::SimAutopilot(ap::Personality::Px4, q), std::invalid_argument);
  EXPECT_NO_THROW(ap::Params{}.validate());
}

// --- offboard ----------------------------------------------------------------------------------

TEST(SimAutopilotOffboard, RefusedBeforeOneSecondOfSetpointsAcceptedAfter) {
  Rig r(ap::Personality::Px4);
  r.airborne_px4();
  EXPECT_EQ(r.px4_mode(mv::px4::kOffboard), mv::mav_result::kTemporarilyRejected);
  EXPECT_TRUE(r.said("Switching to OFFBOARD rejected: no setpoints"));
  for (int i = 0; i < 10; ++i) {  // 0.5 s at 20 Hz
    r.setpoint({0, 0, 0});
    r.run(0.05);
  }
  EXPECT_EQ(r.px4_mode(mv::px4::kOffboard), mv::mav_result::kTemporarilyRejected);
  // A 1 Hz stream never qualifies (> 2 Hz needed).
  Rig slow(ap::Personality::Px4);
  slow.airborne_px4();
  for (int i = 0; i < 3; ++i) {
    slow.setpoint({0, 0, 0});
    slow.run(1.0);
  }
  slow.setpoint({0, 0, 0});
  EXPECT_EQ(slow.px4_mode(mv::px4::kOffboard), mv::mav_result::kTemporarilyRejected);
  for (int i = 0; i < 12; ++i) {  // 1.1 s in all
    r.setpoint({0, 0, 0});
    r.run(0.05);
  }
  EXPECT_EQ(r.px4_mode(mv::px4::kOffboard), mv::mav_result::kAccepted);
  for (int i = 0; i < 20; ++i) {
    r.setpoint({0, 0, 0});
    r.run(0.05);
  }
  EXPECT_EQ(r.last_heartbeat().custom_mode, 6u << 16);
  EXPECT_EQ(r.ap.mode_name(), "OFFBOARD");
}

TEST(SimAutopilotOffboard, LossTakesComOblRcActAfterComOfLossT) {
  for (int action : {0, 4}) {
    ap::Params params;
    params.COM_OBL_RC_ACT = action;
    Rig r(ap::Personality::Px4, params);
    r.airborne_px4();
    for (int i = 0; i < 30; ++i) {
      r.setpoint({0.3, 0, 0});
      r.run(0.05);
    }
    ASSERT_EQ(r.px4_mode(mv::px4::kOffboard), mv::mav_result::kAccepted);
    r.setpoint({0.3, 0, 0});
    const double t_last = r.t;
    const size_t mark = r.sent.size();
    double t_switch = -1;
    while (r.t < t_last + 3) {
      const double t = r.t;
      r.step();
      if (t_switch < 0 && r.ap.mode() != ap::FlightMode::Offboard) t_switch = t;
    }
    ASSERT_GT(t_switch, 0);
    EXPECT_GT(t_switch, t_last + params.COM_OF_LOSS_T);
    EXPECT_LE(t_switch, t_last + params.COM_OF_LOSS_T + kDt + 1e-9);
    if (action == 0) {
      EXPECT_EQ(r.ap.mode_name(), "POSCTL");
      EXPECT_TRUE(r.said("Failsafe: offboard control lost, switching to POSCTL", mark));
      // Position hold: the vehicle stops where it is.
      const Vector3d p = r.mr.state().position;
      r.run(3);
      EXPECT_LT((r.mr.state().position - p).norm(), 0.3);
      EXPECT_LT(r.mr.state().velocity.norm(), 0.05);
    } else {
      EXPECT_EQ(r.ap.mode_name(), "AUTO.LAND");
      EXPECT_TRUE(r.said("switching to AUTO.LAND", mark));
      ASSERT_TRUE(r.run_until([&] { return !r.ap.armed(); }, 15));
      EXPECT_NEAR(r.mr.state().position.z(), 0, 1e-6);
    }
  }
}

// --- ArduCopter GUIDED -------------------------------------------------------------------------

TEST(SimAutopilotGuided, StopsAfterGuidTimeout) {
  Rig r(ap::Personality::ArduCopter);
  r.airborne_copter();
  EXPECT_EQ(r.ap.mode_name(), "GUIDED");
  // Velocity-only mask 0x0DC7 east at 1 m/s for 2 s.
  for (int i = 0; i < 40; ++i) {
    r.setpoint({0, 1, 0}, mv::mav_frame::kLocalNed, 0x0DC7);
    r.run(0.05);
  }
  const double t_last = r.t - 0.05;
  EXPECT_NEAR(r.mr.state().velocity.x(), 1.0, 0.1);
  r.run(2.0);  // still flying the last setpoint 2 s later
  EXPECT_NEAR(r.mr.state().velocity.x(), 1.0, 0.05);
  // The command stops at the first step later than GUID_TIMEOUT after the last setpoint.
  double t_stop = -1;
  while (r.t < t_last + 4) {
    const double t = r.t;
    const AutopilotCommand c = r.step().command;
    if (c.velocity.norm() < 1e-9) {
      t_stop = t;
      break;
    }
    EXPECT_NEAR(c.velocity.norm(), 1.0, 1e-6);  // the last setpoint until then
  }
  ASSERT_GT(t_stop, 0);
  EXPECT_GT(t_stop, t_last + r.ap.params().GUID_TIMEOUT);
  EXPECT_LE(t_stop, t_last + r.ap.params().GUID_TIMEOUT + kDt + 1e-9);
  r.run(4.0);
  EXPECT_LT(r.mr.state().velocity.norm(), 0.05);
  EXPECT_EQ(r.ap.mode_name(), "GUIDED");
  // Setpoints outside GUIDED, or with other masks, are refused.
  const auto refused = r.ap.setpoints_refused();
  r.setpoint({0, 1, 0}, mv::mav_frame::kLocalNed, 0x0FF8);
  EXPECT_EQ(r.ap.setpoints_refused(), refused + 1);
  ASSERT_EQ(r.copter_mode(mv::copter::kLoiter), mv::mav_result::kAccepted);
  r.setpoint({0, 1, 0}, mv::mav_frame::kLocalNed, 0x0DC7);
  EXPECT_EQ(r.ap.setpoints_refused(), refused + 2);
}

// --- vision in the estimator -------------------------------------------------------------------

TEST(SimAutopilotVision, PositionHoldFollowsABiasedVisionEstimate) {
  Rig r(ap::Personality::Px4);
  r.airborne_px4();
  const Vector3d p0 = r.mr.state().position;
  // Vision now reads 0.5 m north and 0.3 m east of the truth: the autopilot holds its estimate,
  // so the real vehicle moves 0.5 m south and 0.3 m west.
  r.vision_bias = Vector3d(0.3, 0.5, 0);
  r.run(8.0);
  const Vector3d d = r.mr.state().position - p0;
  EXPECT_NEAR(d.x(), -0.3, 0.03);
  EXPECT_NEAR(d.y(), -0.5, 0.03);
  EXPECT_NEAR(d.z(), 0.0, 0.03);
  // ... while the local position it reports stays on the hold point.
  const auto lp = r.all<mv::LocalPositionNed>().back();
  EXPECT_NEAR(lp.x, p0.y(), 0.03);  // north
  EXPECT_NEAR(lp.y, p0.x(), 0.03);  // east
  EXPECT_NEAR(lp.z, -p0.z(), 0.03);
  EXPECT_NEAR((r.ap.estimate() - r.mr.state().position - r.vision_bias).norm(), 0, 0.02);
}

TEST(SimAutopilotVision, VisionDelayIsCompensatedWithEkf2EvDelay) {
  // Vision that arrives 100 ms late: with EKF2_EV_DELAY = 100 the estimate matches the truth
  // while flying; with 0 it lags by speed * delay.
  for (double delay_ms : {0.0, 100.0}) {
    ap::Params params;
    params.EKF2_EV_DELAY = delay_ms;
    Rig r(ap::Personality::Px4, params);
    r.airborne_px4();
    for (int i = 0; i < 30; ++i) {
      r.setpoint({0, 0, 0});
      r.run(0.05);
    }
    ASSERT_EQ(r.px4_mode(mv::px4::kOffboard), mv::mav_result::kAccepted);
    // From now on the companion's vision is of the truth 100 ms ago.
    std::deque<std::pair<double, Vector3d>> history;
    r.vision_on = false;
    double next = r.t;
    for (int i = 0; i < 400; ++i) {
      history.emplace_back(r.t, r.mr.state().position);
      if (r.t + 1e-9 >= next) {
        while (history.size() > 1 && history[1].first <= r.t - 0.1 + 1e-9) history.pop_front();
        const Vector3d p = ap::enu_to_ned(history.front().second);
        mv::VisionPositionEstimate v;
        v.x = float(p.x()), v.y = float(p.y()), v.z = float(p.z());
        r.receive(v);
        next += 1.0 / 30.0;
      }
      if (i % 5 == 0) r.setpoint({0, 1, 0});  // 1 m/s east
      r.step();
    }
    const double err = (r.ap.estimate() - r.mr.state().position).norm();
    if (delay_ms == 0) EXPECT_NEAR(err, 0.1, 0.03);
    else EXPECT_LT(err, 0.02);
  }
}

TEST(SimAutopilotVision, VisionLossFailsafeDescends) {
  Rig r(ap::Personality::Px4);
  r.airborne_px4();
  r.vision_on = false;
  const double t_stop = r.t;  // last sample sent just before
  const size_t mark = r.sent.size();
  ASSERT_TRUE(r.run_until([&] { return !r.ap.position_valid(); }, 3));
  EXPECT_NEAR(r.t - t_stop, 1.0, 0.05);
  r.step();
  EXPECT_TRUE(r.said("Vision data stopped: local position estimate invalid", mark));
  EXPECT_TRUE(r.said("Failsafe: no local position, switching to Descend", mark));
  EXPECT_EQ(r.ap.mode_name(), "AUTO.LAND");
  EXPECT_TRUE(r.ap.descending_without_position());
  const size_t after = r.sent.size();
  r.run(1.2);
  EXPECT_TRUE(r.all<mv::LocalPositionNed>(after).empty());  // no valid local position reported
  EXPECT_EQ(r.last_heartbeat().system_status, mv::mav_state::kCritical);
  ASSERT_TRUE(r.run_until([&] { return !r.ap.armed(); }, 15));
  EXPECT_NEAR(r.mr.state().position.z(), 0, 1e-6);

  // ArduCopter: the EKF failsafe lands.
  Rig c(ap::Personality::ArduCopter);
  c.airborne_copter();
  c.vision_on = false;
  const size_t cmark = c.sent.size();
  ASSERT_TRUE(c.run_until([&] { return c.ap.mode() == ap::FlightMode::Land; }, 3));
  EXPECT_TRUE(c.said("EKF3 IMU0 stopped aiding", cmark));
  EXPECT_TRUE(c.said("EKF Failsafe: changed to LAND mode", cmark));
  ASSERT_TRUE(c.run_until([&] { return !c.ap.armed(); }, 15));
}

// --- precision landing -------------------------------------------------------------------------

namespace {
// The companion's LANDING_TARGET for PX4: the target's position in the local NED frame.
mv::LandingTarget px4_target(const Vector3d& target_enu) {
  const Vector3d n = ap::enu_to_ned(target_enu);
  mv::LandingTarget m;
  m.frame = mv::mav_frame::kLocalNed;
  m.x = float(n.x()), m.y = float(n.y()), m.z = float(n.z());
  m.position_valid = 1;
  return m;
}
}  // namespace

TEST(SimAutopilotPrecLand, LandsOnTheTargetFromFiveMetres) {
  Rig r(ap::Personality::Px4);
  r.airborne_px4(5.0f);
  const Vector3d target(1.5, -1.0, 0.0);
  r.receive(px4_target(target));
  ASSERT_EQ(r.command(mv::mav_cmd::kNavLand, {0, 2, 0, 0, 0, 0, 0}), mv::mav_result::kAccepted);
  EXPECT_EQ(r.ap.mode_name(), "AUTO.PRECLAND");
  std::vector<ap::PrecLandState> states{r.ap.precland_state()};
  double next = 0;
  double touchdown = -1;
  Vector3d touch_pos = Vector3d::Zero();
  while (r.t < 60 && r.ap.armed()) {
    if (r.t >= next) {
      r.receive(px4_target(target));
      next = r.t + 0.1;
    }
    r.step();
    if (states.back() != r.ap.precland_state()) states.push_back(r.ap.precland_state());
    if (touchdown < 0 && r.mr.state().on_ground) touchdown = r.t, touch_pos = r.mr.state().position;
  }
  ASSERT_FALSE(r.ap.armed());
  using S = ap::PrecLandState;
  const std::vector<S> expect{S::HorizontalApproach, S::DescendAboveTarget, S::FinalApproach, S::Done};
  EXPECT_EQ(states, expect);
  ASSERT_GT(touchdown, 0);
  EXPECT_LT((touch_pos.head<2>() - target.head<2>()).norm(), r.ap.params().PLD_HACC_RAD);
  EXPECT_LT((r.mr.state().position.head<2>() - target.head<2>()).norm(), r.ap.params().PLD_HACC_RAD);
  EXPECT_TRUE(r.said("Disarmed by landing"));
  EXPECT_EQ(r.all<mv::Heartbeat>().back().custom_mode, mv::px4::custom_mode(mv::px4::kAuto, mv::px4::kAutoPrecland));
}

TEST(SimAutopilotPrecLand, TargetLostSearchesThenFallsBack) {
  Rig r(ap::Personality::Px4);
  r.airborne_px4(5.0f);
  const Vector3d target(12.0, 0.0, 0.0);  // too far to reach within PLD_BTOUT
  r.receive(px4_target(target));
  const double t_seen = r.t;
  ASSERT_EQ(r.px4_mode(mv::px4::kAuto, mv::px4::kAutoPrecland), mv::mav_result::kAccepted);  // required
  EXPECT_EQ(r.ap.precland_state(), ap::PrecLandState::HorizontalApproach);
  // No more target: after PLD_BTOUT the state machine restarts and, required, searches.
  double t_search = -1;
  while (r.t < t_seen + 8) {
    const double t = r.t;
    r.step();
    if (r.ap.precland_state() == ap::PrecLandState::Search) {
      t_search = t;
      break;
    }
  }
  ASSERT_GT(t_search, 0);
  EXPECT_GT(t_search, t_seen + r.ap.params().PLD_BTOUT);
  EXPECT_LE(t_search, t_seen + r.ap.params().PLD_BTOUT + kDt + 1e-9);
  EXPECT_TRUE(r.said("Lost landing target while landing (horizontal approach)."));
  EXPECT_TRUE(r.said("Climbing to search altitude."));
  EXPECT_EQ(r.ap.precland_searches(), 1);
  // It climbs towards PLD_SRCH_ALT; without a target for PLD_SRCH_TOUT it falls back to a land.
  r.run(8);
  EXPECT_GT(r.mr.state().position.z(), 8.0);
  ASSERT_TRUE(r.run_until([&] { return r.ap.precland_state() == ap::PrecLandState::Fallback; }, 3));
  EXPECT_NEAR(r.t - t_search, r.ap.params().PLD_SRCH_TOUT, 0.03);
  EXPECT_TRUE(r.said("Search timed out."));
  EXPECT_TRUE(r.said("Falling back to normal land."));
  const Vector3d p = r.mr.state().position;
  ASSERT_TRUE(r.run_until([&] { return !r.ap.armed(); }, 30));
  EXPECT_LT((r.mr.state().position.head<2>() - p.head<2>()).norm(), 0.1);  // landed where it was

  // A target seen again during the search resumes the approach.
  Rig s(ap::Personality::Px4);
  s.airborne_px4(3.0f);
  ASSERT_EQ(s.command(mv::mav_cmd::kNavLand, {0, 2, 0, 0, 0, 0, 0}), mv::mav_result::kAccepted);
  EXPECT_EQ(s.ap.precland_state(), ap::PrecLandState::Search);  // never seen: required -> search
  s.run(2);
  s.receive(px4_target({0.5, 0.5, 0}));
  s.step();
  EXPECT_EQ(s.ap.precland_state(), ap::PrecLandState::HorizontalApproach);
}

TEST(SimAutopilotPrecLand, OpportunisticWithoutTargetLandsNormally) {
  Rig r(ap::Personality::Px4);
  r.airborne_px4(3.0f);
  const Vector3d p = r.mr.state().position;
  ASSERT_EQ(r.command(mv::mav_cmd::kNavLand, {0, 1, 0, 0, 0, 0, 0}), mv::mav_result::kAccepted);
  EXPECT_EQ(r.ap.precland_state(), ap::PrecLandState::Fallback);
  EXPECT_TRUE(r.said("Falling back to normal land."));
  ASSERT_TRUE(r.run_until([&] { return !r.ap.armed(); }, 20));
  EXPECT_EQ(r.ap.precland_state(), ap::PrecLandState::Done);
  EXPECT_LT((r.mr.state().position.head<2>() - p.head<2>()).norm(), 0.1);
  // Other frames of LANDING_TARGET are ignored by PX4.
  const auto ignored = r.ap.ignored();
  mv::LandingTarget body;
  body.frame = mv::mav_frame::kBodyFrd;
  body.angle_x = 0.1f;
  r.receive(body);
  EXPECT_EQ(r.ap.ignored(), ignored + 1);
}

TEST(SimAutopilotPrecLand, ArduCopterLandsOnBodyFrameAngles) {
  Rig r(ap::Personality::ArduCopter);
  r.airborne_copter(5.0f);
  const Vector3d target(-1.2, 1.0, 0.0);
  ASSERT_EQ(r.copter_mode(mv::copter::kLand), mv::mav_result::kAccepted);
  double next = 0;
  int sent = 0;
  while (r.t < 60 && r.ap.armed()) {
    if (r.t >= next && r.mr.state().position.z() > 0.3) {
      // The companion's camera: the target's direction in body FRD, as angles (ArduPilot's
      // MAVLink precland backend), no distance (the autopilot uses its range finder).
      const auto& s = r.mr.state();
      const Eigen::Matrix3d R = ap::ned_from_frd(s.roll, s.pitch, s.yaw);
      const Vector3d rel = R.transpose() * ap::enu_to_ned(target - s.position);
      mv::LandingTarget m;
      m.frame = mv::mav_frame::kBodyFrd;
      m.angle_x = float(std::atan2(rel.x(), rel.z()));
      m.angle_y = float(std::atan2(rel.y(), rel.z()));
      m.distance = 0;
      r.receive(m);
      ++sent;
      next = r.t + 0.1;
    }
    r.step();
  }
  ASSERT_FALSE(r.ap.armed());
  EXPECT_GT(sent, 50);
  EXPECT_LT((r.mr.state().position.head<2>() - target.head<2>()).norm(), 0.2);
  EXPECT_TRUE(r.said("Disarming motors"));
}

TEST(SimAutopilotPrecLand, ArduCopterDropsTheTargetAfterTwoSeconds) {
  Rig r(ap::Personality::ArduCopter);
  r.airborne_copter(5.0f);
  ASSERT_EQ(r.copter_mode(mv::copter::kLand), mv::mav_result::kAccepted);
  const Vector3d p = r.mr.state().position;
  // One position (x/y/z, position_valid 1) 2 m ahead in body FRD, then nothing.
  mv::LandingTarget m;
  m.frame = mv::mav_frame::kBodyFrd;
  m.position_valid = 1;
  m.x = 2.0f, m.y = 0, m.z = float(r.mr.state().position.z());
  r.receive(m);
  r.run(1.9);
  const double moved = (r.mr.state().position - p).head<2>().norm();
  EXPECT_GT(moved, 0.5);  // tracking the target
  r.run(0.2);             // > 2 s: target dropped, LAND holds where it is
  const Vector3d q = r.mr.state().position;
  r.run(1.5);
  EXPECT_LT((r.mr.state().position - q).head<2>().norm(), 0.25);
}

// --- telemetry ---------------------------------------------------------------------------------

TEST(SimAutopilotTelemetry, StreamsRatesAndContent) {
  Rig r(ap::Personality::Px4);
  r.vision_on = true;
  r.run(1.0);
  EXPECT_EQ(r.all<mv::HighresImu>().size(), 50u);
  EXPECT_EQ(r.all<mv::AttitudeQuaternion>().size(), 50u);
  EXPECT_EQ(r.all<mv::ExtendedSysState>().size(), 5u);
  EXPECT_EQ(r.all<mv::DistanceSensor>().size(), 10u);
  // Resting, facing east: gravity on FRD z, FRD->NED = yaw 90 deg about down.
  const auto imu = r.all<mv::HighresImu>().back();
  EXPECT_NEAR(imu.zacc, -9.81, 1e-4);
  EXPECT_NEAR(imu.xacc, 0, 1e-4);
  const auto q = r.all<mv::AttitudeQuaternion>().back();
  EXPECT_NEAR(q.q1, std::cos(std::numbers::pi / 4), 1e-6);
  EXPECT_NEAR(q.q4, std::sin(std::numbers::pi / 4), 1e-6);
  EXPECT_EQ(r.all<mv::ExtendedSysState>().back().landed_state, mv::mav_landed_state::kOnGround);
  // SET_MESSAGE_INTERVAL: 10 Hz, then off, then default.
  ASSERT_EQ(r.command(mv::mav_cmd::kSetMessageInterval, {float(mv::HighresImu::kId), 100000, 0, 0, 0, 0, 0}),
            mv::mav_result::kAccepted);
  EXPECT_NEAR(r.ap.stream_interval(mv::HighresImu::kId), 0.1, 1e-9);
  size_t mark = r.sent.size();
  r.run(1.0);
  EXPECT_EQ(r.all<mv::HighresImu>(mark).size(), 10u);
  ASSERT_EQ(r.command(mv::mav_cmd::kSetMessageInterval, {float(mv::HighresImu::kId), -1, 0, 0, 0, 0, 0}),
            mv::mav_result::kAccepted);
  mark = r.sent.size();
  r.run(1.0);
  EXPECT_TRUE(r.all<mv::HighresImu>(mark).empty());
  EXPECT_EQ(r.command(mv::mav_cmd::kSetMessageInterval, {float(mv::Odometry::kId), 1000, 0, 0, 0, 0, 0}),
            mv::mav_result::kDenied);
  // TIMESYNC: tc1 = our time in ns for a request (tc1 == 0); ts1 echoed.
  mv::Timesync ts;
  ts.tc1 = 0;
  ts.ts1 = 123456789;
  const double t_req = r.t;
  mark = r.sent.size();
  r.receive(ts);
  r.step();
  const auto reply = r.all<mv::Timesync>(mark);
  ASSERT_EQ(reply.size(), 1u);
  EXPECT_EQ(reply[0].ts1, 123456789);
  EXPECT_EQ(reply[0].tc1, static_cast<int64_t>(std::llround(t_req * 1e9)));
  // In flight: range finder height, IN_AIR, battery draining.
  ASSERT_EQ(r.arm(), mv::mav_result::kAccepted);
  ASSERT_EQ(r.takeoff(2.0f), mv::mav_result::kAccepted);
  r.run(1.0);
  EXPECT_EQ(r.all<mv::ExtendedSysState>().back().landed_state, mv::mav_landed_state::kTakeoff);
  ASSERT_TRUE(r.run_until([&] { return r.ap.mode() == ap::FlightMode::Hold; }, 15));
  r.run(3.0);
  EXPECT_EQ(r.all<mv::ExtendedSysState>().back().landed_state, mv::mav_landed_state::kInAir);
  EXPECT_NEAR(r.all<mv::DistanceSensor>().back().current_distance, 200, 3);
  const auto lp = r.all<mv::LocalPositionNed>().back();
  EXPECT_NEAR(lp.z, -2.0, 0.05);
  const auto b = r.all<mv::BatteryStatus>();
  ASSERT_GE(b.size(), 2u);
  EXPECT_GT(b.back().current_consumed, b.front().current_consumed);
  EXPECT_LE(b.back().battery_remaining, b.front().battery_remaining);
  EXPECT_GT(r.all<mv::SysStatus>().back().voltage_battery, 14000);
}

TEST(SimAutopilotTelemetry, CompanionHeartbeatTrackedAndLost) {
  Rig r(ap::Personality::Px4);
  mv::Heartbeat h;
  h.type = mv::mav_type::kOnboardController;
  h.autopilot = mv::mav_autopilot::kInvalid;
  for (int i = 0; i < 3; ++i) {
    r.receive(h);
    r.run(1.0);
  }
  EXPECT_TRUE(r.ap.companion_alive());
  EXPECT_TRUE(r.said("Onboard computer connected"));
  r.run(r.ap.params().COM_OBC_LOSS_T - 1.0 + 0.05);
  EXPECT_FALSE(r.ap.companion_alive());
  EXPECT_TRUE(r.said("Onboard computer lost"));
  // A message from another system is not for us.
  mv::CommandLong c;
  c.target_system = 2;
  c.command = mv::mav_cmd::kComponentArmDisarm;
  c.param1 = 1;
  const auto ignored = r.ap.ignored();
  r.receive(c);
  EXPECT_EQ(r.ap.ignored(), ignored + 1);
}

// --- more modes, estimator resets, bad input ---------------------------------------------------

TEST(SimAutopilot, Px4RefusesPositionModesWithoutLocalPosition) {
  Rig r(ap::Personality::Px4);
  r.run(0.2);
  ASSERT_EQ(r.px4_mode(mv::px4::kAltctl), mv::mav_result::kAccepted);  // needs no position
  EXPECT_EQ(r.px4_mode(mv::px4::kPosctl), mv::mav_result::kTemporarilyRejected);
  EXPECT_TRUE(r.said("Switching to POSCTL rejected: no valid local position"));
  EXPECT_EQ(r.px4_mode(mv::px4::kAuto, mv::px4::kAutoLoiter), mv::mav_result::kTemporarilyRejected);
  EXPECT_EQ(r.ap.mode_name(), "ALTCTL");
  r.vision_on = true;
  r.run(0.2);
  EXPECT_EQ(r.px4_mode(mv::px4::kPosctl), mv::mav_result::kAccepted);
  // Garbage parameters are refused, not undefined behaviour.
  EXPECT_EQ(r.command(mv::mav_cmd::kDoSetMode, {std::nanf(""), 3, 0, 0, 0, 0, 0}), mv::mav_result::kDenied);
  EXPECT_EQ(r.command(mv::mav_cmd::kDoSetMode, {1, 1e30f, 0, 0, 0, 0, 0}), mv::mav_result::kDenied);
  EXPECT_EQ(r.command(mv::mav_cmd::kSetMessageInterval, {-5, 1000, 0, 0, 0, 0, 0}), mv::mav_result::kDenied);
  EXPECT_EQ(r.command(mv::mav_cmd::kRequestMessage, {std::nanf(""), 0, 0, 0, 0, 0, 0}), mv::mav_result::kDenied);
  EXPECT_EQ(r.command(mv::mav_cmd::kNavLand, {0, 1e9f, 0, 0, 0, 0, 0}), mv::mav_result::kDenied);
  EXPECT_EQ(r.ap.mode_name(), "POSCTL");
}

TEST(SimAutopilot, AutoDisarmComDisarmLandAfterLandDetection) {
  Rig r(ap::Personality::Px4);
  r.airborne_px4(2.0f);
  ASSERT_EQ(r.command(mv::mav_cmd::kNavLand, {0, 0, 0, 0, 0, 0, 0}), mv::mav_result::kAccepted);
  EXPECT_EQ(r.ap.mode_name(), "AUTO.LAND");
  ASSERT_TRUE(r.run_until([&] { return r.ap.landed(); }, 10));
  const double t_landed = r.t;
  EXPECT_TRUE(r.ap.armed());
  ASSERT_TRUE(r.run_until([&] { return !r.ap.armed(); }, 5));
  EXPECT_NEAR(r.t - t_landed, r.ap.params().COM_DISARM_LAND, kDt + 1e-9);
  EXPECT_TRUE(r.said("Landing detected"));
  EXPECT_TRUE(r.said("Disarmed by landing"));
  EXPECT_FALSE(r.mr.state().armed);  // motors off
}

TEST(SimAutopilot, ArduCopterRtlFliesHomeAndLands) {
  Rig r(ap::Personality::ArduCopter);
  r.airborne_copter(3.0f);
  for (int i = 0; i < 60; ++i) {  // 3 s north-east at 1 m/s
    r.setpoint({0.7, 0.7, 0}, mv::mav_frame::kLocalNed, 0x0DC7);
    r.run(0.05);
  }
  EXPECT_GT(r.mr.state().position.head<2>().norm(), 2.0);
  ASSERT_EQ(r.copter_mode(mv::copter::kRtl), mv::mav_result::kAccepted);
  EXPECT_EQ(r.ap.mode_name(), "RTL");
  ASSERT_TRUE(r.run_until([&] { return !r.ap.armed(); }, 30));
  EXPECT_LT(r.mr.state().position.head<2>().norm(), 0.35);
  EXPECT_EQ(r.last_heartbeat().custom_mode, 9u);  // ended in LAND
}

TEST(SimAutopilotVision, ResetCounterResetsTheEstimateAtOnce) {
  Rig r(ap::Personality::Px4);
  r.airborne_px4();
  auto odom = [&](const Vector3d& p_enu, uint8_t reset) {
    const Vector3d n = ap::enu_to_ned(p_enu);
    mv::Odometry o;
    o.frame_id = mv::mav_frame::kLocalFrd;
    o.x = float(n.x()), o.y = float(n.y()), o.z = float(n.z());
    o.reset_counter = reset;
    r.receive(o);
    r.step();
  };
  r.vision_on = false;
  const Vector3d jump(1.0, 0, 0);
  odom(r.mr.state().position, 0);
  odom(r.mr.state().position + jump, 0);  // same counter: one complementary-filter step
  EXPECT_NEAR((r.ap.estimate() - r.mr.state().position).x(), 0.3, 0.02);
  odom(r.mr.state().position + 2 * jump, 1);  // re-anchored: the estimate takes it at once
  EXPECT_NEAR((r.ap.estimate() - r.mr.state().position).x(), 2.0, 0.02);
  EXPECT_EQ(r.ap.vision_resets(), 1);
}

TEST(SimAutopilotOffboard, ArmInOffboardOnTheGroundAndClimbOnSetpoints) {
  // The "Aerie flies" path: stream, OFFBOARD, arm, climb on velocity setpoints, then stop
  // streaming: the failsafe holds position.
  Rig r(ap::Personality::Px4);
  r.vision_on = true;
  for (int i = 0; i < 25; ++i) {
    r.setpoint({0, 0, 0});
    r.run(0.05);
  }
  ASSERT_EQ(r.px4_mode(mv::px4::kOffboard), mv::mav_result::kAccepted);
  ASSERT_EQ(r.arm(), mv::mav_result::kAccepted);
  for (int i = 0; i < 60; ++i) {  // 3 s up at 0.8 m/s (NED z negative)
    r.setpoint({0, 0, -0.8});
    r.run(0.05);
  }
  EXPECT_GT(r.mr.state().position.z(), 1.8);
  EXPECT_FALSE(r.ap.landed());
  const double z = r.mr.state().position.z();
  r.run(1.5);  // stale: COM_OF_LOSS_T, then POSCTL holds
  EXPECT_EQ(r.ap.mode_name(), "POSCTL");
  r.run(3);
  EXPECT_NEAR(r.mr.state().position.z(), z + 0.8, 0.3);  // kept climbing for COM_OF_LOSS_T, then held
  EXPECT_LT(std::abs(r.mr.state().velocity.z()), 0.05);
}

TEST(SimAutopilotGuided, NoVelocityFlightBeforeTakeoff) {
  Rig r(ap::Personality::ArduCopter);
  mv::SetGpsGlobalOrigin o;
  o.target_system = 1;
  r.receive(o);
  r.vision_on = true;
  r.run(0.5);
  ASSERT_EQ(r.copter_mode(mv::copter::kGuided), mv::mav_result::kAccepted);
  ASSERT_EQ(r.arm(), mv::mav_result::kAccepted);
  for (int i = 0; i < 40; ++i) {
    r.setpoint({0, 0, -1}, mv::mav_frame::kLocalNed, 0x0DC7);
    r.run(0.05);
  }
  EXPECT_NEAR(r.mr.state().position.z(), 0, 1e-9);
  EXPECT_TRUE(r.ap.landed());
}

TEST(SimAutopilotPrecLand, PldMaxSrchZeroFallsBackAtOnce) {
  ap::Params params;
  params.PLD_MAX_SRCH = 0;
  Rig r(ap::Personality::Px4, params);
  r.airborne_px4(3.0f);
  ASSERT_EQ(r.command(mv::mav_cmd::kNavLand, {0, 2, 0, 0, 0, 0, 0}), mv::mav_result::kAccepted);
  EXPECT_EQ(r.ap.precland_state(), ap::PrecLandState::Fallback);
  EXPECT_TRUE(r.said("Maximum search attempts reached (PLD_MAX_SRCH)."));
  EXPECT_EQ(r.ap.precland_searches(), 0);
}

TEST(SimAutopilotTelemetry, ImuNoiseIsSeeded) {
  ap::Params noisy;
  noisy.imu_accel_noise_m_s2 = 0.2;
  noisy.imu_gyro_noise_rad_s = 0.01;
  noisy.noise_seed = 7;
  Rig a(ap::Personality::Px4, noisy), b(ap::Personality::Px4, noisy);
  noisy.noise_seed = 8;
  Rig c(ap::Personality::Px4, noisy);
  a.run(4.0);
  b.run(4.0);
  c.run(4.0);
  const auto ia = a.all<mv::HighresImu>(), ib = b.all<mv::HighresImu>(), ic = c.all<mv::HighresImu>();
  ASSERT_EQ(ia.size(), 200u);
  double sum = 0, sum2 = 0;
  bool differs = false;
  for (size_t i = 0; i < ia.size(); ++i) {
    EXPECT_EQ(ia[i].xacc, ib[i].xacc);  // same seed, same samples
    EXPECT_EQ(ia[i].zgyro, ib[i].zgyro);
    differs = differs || ia[i].xacc != ic[i].xacc;
    sum += ia[i].xacc;
    sum2 += ia[i].xacc * ia[i].xacc;
  }
  EXPECT_TRUE(differs);
  const double mean = sum / ia.size(), sd = std::sqrt(sum2 / ia.size() - mean * mean);
  EXPECT_NEAR(sd, 0.2, 0.04);
  EXPECT_NEAR(mean, 0.0, 0.05);
}
