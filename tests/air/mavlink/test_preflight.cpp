// aerie-mavlink --check's logic (air/mavlink/preflight.hpp) in simulation time, through a
// memory pipe: against the simulator's autopilot (PX4 and ArduCopter personalities) with its
// default set-up, with a parameter changed, with the landing path and odometry switched, signed
// and mis-signed, against a silent autopilot and one that knows no parameter (a scripted one).
#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "air/mavlink/preflight.hpp"
#include "common/mavlink/transport.hpp"
#include "common/sim/autopilot/mavlink_face.hpp"

namespace aerie::bridge {
namespace {

namespace mav = aerie::mavlink;
namespace ap = aerie::sim::autopilot;
constexpr int64_t kStepUs = 10'000;  // 100 Hz, as a node's loop

// A scripted autopilot: PX4's HEARTBEAT at 1 Hz, and PARAM_VALUE (bytewise, as PX4) for the
// names it has; nothing else is answered.
struct ScriptedPx4 {
  std::map<std::string, float> reals;
  std::map<std::string, int32_t> ints;
  mav::Parser parser;
  uint8_t seq = 0;
  int64_t last_hb_us = -1'000'000'000;
  std::vector<mav::Frame> heard;
  std::vector<uint8_t> step(std::span<const uint8_t> in, int64_t now_us) {
    std::vector<uint8_t> out;
    auto put = [&](const auto& m) {
      const auto b = mav::encode(m, {1, 1, seq++});
      out.insert(out.end(), b.begin(), b.end());
    };
    parser.feed(in, [&](const mav::Frame& f) {
      heard.push_back(f);
      if (f.msgid != mav::ParamRequestRead::kId) return;
      const auto r = mav::decode<mav::ParamRequestRead>(f);
      const std::string name(r.param_id.data(), strnlen(r.param_id.data(), r.param_id.size()));
      mav::ParamValue v;
      std::memcpy(v.param_id.data(), name.data(), name.size());
      if (auto it = reals.find(name); it != reals.end()) {
        v.param_type = 9;
        v.param_value = it->second;
      } else if (auto jt = ints.find(name); jt != ints.end()) {
        v.param_type = 6;
        std::memcpy(&v.param_value, &jt->second, 4);
      } else {
        return;
      }
      put(v);
    });
    if (now_us - last_hb_us >= 1'000'000) {
      mav::Heartbeat hb;
      hb.type = mav::mav_type::kQuadrotor;
      hb.autopilot = mav::mav_autopilot::kPx4;
      hb.base_mode = mav::mav_mode_flag::kCustomModeEnabled;
      hb.custom_mode = mav::px4::custom_mode(mav::px4::kPosctl);
      hb.mavlink_version = 3;
      put(hb);
      last_hb_us = now_us;
    }
    return out;
  }
};

// The check on one end of a memory pipe, the autopilot on the other, stepped together.
struct Rig {
  enum class Far { Face, Scripted, Silent };
  Far far = Far::Face;
  std::unique_ptr<ap::MavlinkFace> face;
  ScriptedPx4 scripted;
  std::unique_ptr<mav::Endpoint> near_end, far_end;
  PreflightCheck check;
  int64_t now_us = 0;
  mav::Parser wire;                 // what the check wrote, as the autopilot's port sees it
  std::vector<mav::Frame> written;

  Rig(ap::Personality p, ap::Params params, PreflightConfig cfg = {})
      : face(std::make_unique<ap::MavlinkFace>(p, params)), check(cfg) { pipe(); }
  Rig(Far f, PreflightConfig cfg = {}) : far(f), check(cfg) { pipe(); }
  void pipe() {
    auto [a, b] = mav::memory_pipe("autopilot");
    near_end = std::move(a);
    far_end = std::move(b);
  }
  // Runs until the check is done (or max_s of simulation time).
  void run(double max_s = 120) {
    const sim::MultirotorState truth;
    std::vector<uint8_t> buf;
    while (!check.done() && now_us < static_cast<int64_t>(max_s * 1e6)) {
      for (const auto& f : check.poll(now_us)) {
        near_end->write(f);
        wire.feed(f, [&](const mav::Frame& fr) { written.push_back(fr); });
      }
      buf.clear();
      far_end->read(buf);
      const double t = static_cast<double>(now_us) * 1e-6;
      std::vector<uint8_t> out;
      if (far == Far::Face) {
        face->receive(buf, t);
        out = face->step(t, truth).bytes;
      } else if (far == Far::Scripted) {
        out = scripted.step(buf, now_us);
      }
      if (!out.empty()) far_end->write(out);
      buf.clear();
      near_end->read(buf);
      check.receive(buf, now_us);
      now_us += kStepUs;
    }
  }
  const CheckItem& item(const std::string& name) const {
    for (const auto& i : check.items())
      if (i.name == name) return i;
    throw std::runtime_error("no item " + name);
  }
  std::map<std::string, Verdict> verdicts() const {
    std::map<std::string, Verdict> m;
    for (const auto& i : check.items()) m[i.name] = i.verdict;
    return m;
  }
  std::vector<std::string> names() const {
    std::vector<std::string> n;
    for (const auto& i : check.items()) n.push_back(i.name);
    return n;
  }
  template <class Msg>
  std::vector<Msg> sent() const {
    std::vector<Msg> out;
    for (const auto& f : written)
      if (f.msgid == Msg::kId) out.push_back(mav::decode<Msg>(f));
    return out;
  }
};

using V = Verdict;

TEST(Preflight, LineFormat) {
  EXPECT_EQ(to_line({"COM_OF_LOSS_T", V::Fail, "0 (offboard loss never detected)", "set COM_OF_LOSS_T 1.0"}),
            "FAIL COM_OF_LOSS_T = 0 (offboard loss never detected) — set COM_OF_LOSS_T 1.0");
  EXPECT_EQ(to_line({"GUID_TIMEOUT", V::Pass, "3 s", ""}), "PASS GUID_TIMEOUT = 3 s");
  EXPECT_EQ(to_line({"PLD_BTOUT", V::Fail, "not found on this autopilot", "build it in", false}),
            "FAIL PLD_BTOUT: not found on this autopilot — build it in");
}

TEST(Preflight, ConfigRefusedNamingTheField) {
  PreflightConfig c;
  c.attempts = 0;
  try {
    PreflightCheck check(c);
    FAIL() << "attempts = 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("attempts"), std::string::npos) << e.what();
  }
}

TEST(Preflight, Px4DefaultSetUp) {
  Rig rig(ap::Personality::Px4, {});
  rig.run();
  ASSERT_TRUE(rig.check.done());
  EXPECT_EQ(rig.check.autopilot(), mav::Autopilot::Px4);
  // Not found: 3 attempts 1 s apart after the heartbeat at t = 0, then judged.
  EXPECT_LE(rig.now_us, 5'000'000);
  EXPECT_EQ(rig.names(), (std::vector<std::string>{"heartbeat", "version", "signing", "MAV_1_CONFIG", "MAV_1_MODE",
                                                    "SER_TEL2_BAUD", "COM_OF_LOSS_T", "COM_OBL_RC_ACT", "EKF2_EV_CTRL",
                                                    "EKF2_HGT_REF", "EKF2_EV_DELAY"}));
  EXPECT_EQ(rig.verdicts(), (std::map<std::string, V>{{"heartbeat", V::Pass},     {"version", V::Pass},
                                                       {"signing", V::Warn},       {"MAV_1_CONFIG", V::Warn},
                                                       {"MAV_1_MODE", V::Warn},    {"SER_TEL2_BAUD", V::Warn},
                                                       {"COM_OF_LOSS_T", V::Pass}, {"COM_OBL_RC_ACT", V::Pass},
                                                       {"EKF2_EV_CTRL", V::Pass},  {"EKF2_HGT_REF", V::Pass},
                                                       {"EKF2_EV_DELAY", V::Warn}}));
  EXPECT_TRUE(rig.check.passed());
  EXPECT_EQ(to_line(rig.item("heartbeat")), "PASS heartbeat = PX4 quadrotor, system 1 component 1, POSCTL");
  EXPECT_EQ(to_line(rig.item("version")), "PASS version = 1.14.0 (official)");
  EXPECT_EQ(to_line(rig.item("COM_OF_LOSS_T")), "PASS COM_OF_LOSS_T = 1 s");
  EXPECT_EQ(to_line(rig.item("COM_OBL_RC_ACT")), "PASS COM_OBL_RC_ACT = 0 (Position), position from vision");
  // An integer sent bytewise (PX4) reads as itself.
  EXPECT_EQ(rig.item("EKF2_EV_CTRL").found, "15 (horizontal position, vertical position, velocity, yaw)");
  EXPECT_EQ(rig.item("EKF2_HGT_REF").found, "3 (vision)");
  EXPECT_EQ(rig.item("MAV_1_CONFIG").found, "not found on this autopilot");
  EXPECT_FALSE(rig.item("MAV_1_CONFIG").has_value);
  EXPECT_NE(rig.item("EKF2_EV_DELAY").fix.find("set EKF2_EV_DELAY"), std::string::npos);
  EXPECT_EQ(rig.item("signing").found, "unsigned: anyone on the link can command the autopilot");
  // What went out: heartbeats as an onboard controller, one version request (answered), each
  // parameter by name (param_index -1, to system 1 component 1): found ones once, missing ones 3 times.
  const auto hbs = rig.sent<mav::Heartbeat>();
  ASSERT_FALSE(hbs.empty());
  EXPECT_EQ(hbs[0].type, mav::mav_type::kOnboardController);
  const auto cmds = rig.sent<mav::CommandLong>();
  ASSERT_EQ(cmds.size(), 1u);
  EXPECT_EQ(cmds[0].command, mav::mav_cmd::kRequestMessage);
  EXPECT_EQ(cmds[0].param1, 148.0f);
  std::map<std::string, int> asked;
  for (const auto& r : rig.sent<mav::ParamRequestRead>()) {
    EXPECT_EQ(r.param_index, -1);
    EXPECT_EQ(r.target_system, 1);
    EXPECT_EQ(r.target_component, 1);
    ++asked[std::string(r.param_id.data(), strnlen(r.param_id.data(), 16))];
  }
  EXPECT_EQ(asked, (std::map<std::string, int>{{"MAV_1_CONFIG", 3}, {"MAV_1_MODE", 3}, {"SER_TEL2_BAUD", 3},
                                               {"COM_OF_LOSS_T", 1}, {"COM_OBL_RC_ACT", 1}, {"EKF2_OF_CTRL", 1},
                                               {"EKF2_EV_CTRL", 1}, {"EKF2_HGT_REF", 1}, {"EKF2_EV_DELAY", 1}}));
  EXPECT_EQ(rig.face->parser_counters().refused(), 0u);
}

TEST(Preflight, ArduCopterDefaultSetUp) {
  Rig rig(ap::Personality::ArduCopter, {});
  rig.run();
  ASSERT_TRUE(rig.check.done());
  EXPECT_EQ(rig.names(), (std::vector<std::string>{"heartbeat", "version", "signing", "SERIAL2_PROTOCOL",
                                                    "SERIAL2_BAUD", "VISO_TYPE", "EK3_SRC1_POSXY", "EK3_SRC1_VELXY",
                                                    "GUID_TIMEOUT"}));
  EXPECT_EQ(rig.verdicts(), (std::map<std::string, V>{{"heartbeat", V::Pass},        {"version", V::Pass},
                                                       {"signing", V::Warn},          {"SERIAL2_PROTOCOL", V::Warn},
                                                       {"SERIAL2_BAUD", V::Warn},     {"VISO_TYPE", V::Pass},
                                                       {"EK3_SRC1_POSXY", V::Pass},   {"EK3_SRC1_VELXY", V::Pass},
                                                       {"GUID_TIMEOUT", V::Pass}}));
  EXPECT_TRUE(rig.check.passed());
  EXPECT_EQ(to_line(rig.item("heartbeat")), "PASS heartbeat = ArduPilot quadrotor, system 1 component 1, STABILIZE");
  EXPECT_EQ(to_line(rig.item("version")), "PASS version = 4.5.0 (official)");
  // An integer sent as a C cast (ArduPilot) reads as itself.
  EXPECT_EQ(to_line(rig.item("VISO_TYPE")), "PASS VISO_TYPE = 1 (MAVLink)");
  EXPECT_EQ(to_line(rig.item("EK3_SRC1_POSXY")), "PASS EK3_SRC1_POSXY = 6 (ExternalNav)");
  EXPECT_EQ(to_line(rig.item("GUID_TIMEOUT")), "PASS GUID_TIMEOUT = 3 s");
}

TEST(Preflight, ChangedParameterFlipsItsVerdictWithTheFix) {
  {
    ap::Params p;
    p.COM_OF_LOSS_T = 5;
    Rig rig(ap::Personality::Px4, p);
    rig.run();
    EXPECT_EQ(to_line(rig.item("COM_OF_LOSS_T")),
              "FAIL COM_OF_LOSS_T = 5 (Aerie's last setpoint flown 5 s after it stops) — set COM_OF_LOSS_T 1.0");
    EXPECT_FALSE(rig.check.passed());
    // Nothing else changed.
    auto v = rig.verdicts();
    v.erase("COM_OF_LOSS_T");
    for (const auto& [name, verdict] : v) EXPECT_NE(verdict, V::Fail) << name;
  }
  {
    ap::Params p;
    p.COM_OBL_RC_ACT = 4;
    p.EKF2_EV_DELAY = 35;
    Rig rig(ap::Personality::Px4, p);
    rig.run();
    EXPECT_EQ(to_line(rig.item("COM_OBL_RC_ACT")), "PASS COM_OBL_RC_ACT = 4 (Land)");
    EXPECT_EQ(to_line(rig.item("EKF2_EV_DELAY")), "PASS EKF2_EV_DELAY = 35 ms");
  }
  {
    // Vision velocity only: no vision position, so a Position failsafe has no position source.
    ap::Params p;
    p.EKF2_EV_CTRL = 4;
    Rig rig(ap::Personality::Px4, p);
    rig.run();
    EXPECT_EQ(to_line(rig.item("EKF2_EV_CTRL")),
              "FAIL EKF2_EV_CTRL = 4 (velocity): Aerie's vision position not fused — set EKF2_EV_CTRL 15 (or 11 "
              "without vision yaw)");
    EXPECT_EQ(to_line(rig.item("COM_OBL_RC_ACT")),
              "WARN COM_OBL_RC_ACT = 0 (Position) without a position source (no vision, no optical flow) — set "
              "COM_OBL_RC_ACT 4 (Land), unless GPS is fitted");
  }
  {
    // ... but optical flow is one.
    ap::Params p;
    p.EKF2_EV_CTRL = 4;
    p.EKF2_OF_CTRL = 1;
    Rig rig(ap::Personality::Px4, p);
    rig.run();
    EXPECT_EQ(to_line(rig.item("COM_OBL_RC_ACT")), "PASS COM_OBL_RC_ACT = 0 (Position), position from optical flow");
  }
  {
    ap::Params p;
    p.GUID_TIMEOUT = 8;
    p.EK3_SRC1_POSXY = 3;
    Rig rig(ap::Personality::ArduCopter, p);
    rig.run();
    EXPECT_EQ(to_line(rig.item("GUID_TIMEOUT")),
              "FAIL GUID_TIMEOUT = 8 (Aerie's last setpoint flown 8 s after it stops) — set GUID_TIMEOUT 3");
    EXPECT_EQ(to_line(rig.item("EK3_SRC1_POSXY")),
              "FAIL EK3_SRC1_POSXY = 3 (GPS): Aerie's vision not used — set EK3_SRC1_POSXY 6 (ExternalNav)");
    EXPECT_EQ(rig.item("EK3_SRC1_VELXY").verdict, V::Pass);
  }
}

TEST(Preflight, ZeroOffboardLossTimeFails) {
  // The simulator refuses COM_OF_LOSS_T = 0 (its Params range), so a scripted PX4 answers it.
  Rig rig(Rig::Far::Scripted);
  rig.scripted.reals = {{"COM_OF_LOSS_T", 0.0f}, {"EKF2_EV_DELAY", 20.0f}};
  rig.scripted.ints = {{"COM_OBL_RC_ACT", 4}, {"EKF2_EV_CTRL", 11}, {"EKF2_HGT_REF", 2}, {"MAV_1_CONFIG", 102},
                       {"MAV_1_MODE", 0}, {"SER_TEL2_BAUD", 57600}};
  rig.run();
  ASSERT_TRUE(rig.check.done());
  EXPECT_EQ(to_line(rig.item("COM_OF_LOSS_T")),
            "FAIL COM_OF_LOSS_T = 0 (offboard loss never detected) — set COM_OF_LOSS_T 1.0");
  // MAV_1 is on TELEM2: its mode and TELEM2's speed are the companion's.
  EXPECT_EQ(to_line(rig.item("MAV_1_CONFIG")), "PASS MAV_1_CONFIG = 102 (TELEM2)");
  EXPECT_EQ(to_line(rig.item("MAV_1_MODE")),
            "FAIL MAV_1_MODE = 0 (Normal), the companion's TELEM2 link — set MAV_1_MODE 2 (Onboard)");
  EXPECT_EQ(rig.item("SER_TEL2_BAUD").verdict, V::Fail);
  EXPECT_EQ(rig.item("EKF2_EV_CTRL").found, "11 (horizontal position, vertical position, yaw)");
  EXPECT_EQ(rig.item("EKF2_HGT_REF").verdict, V::Pass);
  // No AUTOPILOT_VERSION from it: asked 3 times (confirmation 0, 1, 2), then a WARN.
  const auto cmds = rig.sent<mav::CommandLong>();
  ASSERT_EQ(cmds.size(), 3u);
  for (size_t i = 0; i < cmds.size(); ++i) EXPECT_EQ(cmds[i].confirmation, i);
  EXPECT_EQ(to_line(rig.item("version")),
            "WARN version: no AUTOPILOT_VERSION after 3 requests — not needed to fly; the parameter names checked are "
            "those of PX4 1.14 / ArduCopter 4");
}

TEST(Preflight, UnknownParametersAreNotFoundAfterThreeAttemptsAtMostFiveAtOnce) {
  Rig rig(Rig::Far::Scripted);  // knows no parameter
  rig.run();
  ASSERT_TRUE(rig.check.done());
  EXPECT_FALSE(rig.check.passed());
  for (const char* n : {"COM_OF_LOSS_T", "COM_OBL_RC_ACT", "EKF2_EV_CTRL", "EKF2_HGT_REF", "EKF2_EV_DELAY"}) {
    EXPECT_EQ(rig.item(n).verdict, V::Fail) << n;
    EXPECT_EQ(rig.item(n).found, "not found on this autopilot") << n;
  }
  EXPECT_EQ(to_line(rig.item("EKF2_EV_CTRL")),
            "FAIL EKF2_EV_CTRL: not found on this autopilot — PX4 before 1.14 has EKF2_AID_MASK instead: use PX4 1.14 "
            "or newer (docs/mavlink.md)");
  EXPECT_EQ(rig.item("MAV_1_CONFIG").verdict, V::Warn);
  std::map<std::string, int> asked;
  for (const auto& r : rig.sent<mav::ParamRequestRead>()) ++asked[std::string(r.param_id.data(), strnlen(r.param_id.data(), 16))];
  EXPECT_EQ(asked.size(), 9u);
  for (const auto& [name, n] : asked) EXPECT_EQ(n, 3) << name;
  // The first round: the window's five names, in the plan's order.
  std::vector<std::string> first;
  for (const auto& f : rig.scripted.heard)
    if (f.msgid == mav::ParamRequestRead::kId && first.size() < 5) {
      const auto r = mav::decode<mav::ParamRequestRead>(f);
      first.emplace_back(r.param_id.data(), strnlen(r.param_id.data(), 16));
    }
  EXPECT_EQ(first, (std::vector<std::string>{"MAV_1_CONFIG", "MAV_1_MODE", "SER_TEL2_BAUD", "COM_OF_LOSS_T",
                                             "COM_OBL_RC_ACT"}));
  EXPECT_EQ(rig.check.parameters_asked().size(), 9u);
}

TEST(Preflight, TheWholeCheckTimesOut) {
  PreflightConfig c;
  c.timeout_s = 2;
  Rig rig(Rig::Far::Scripted, c);  // knows no parameter: 3 s each
  rig.run();
  ASSERT_TRUE(rig.check.done());
  EXPECT_EQ(rig.now_us, 2'000'000 + kStepUs);
  // Those asked 3 times are not found; the rest was cut short.
  EXPECT_EQ(rig.item("COM_OF_LOSS_T").found, "no answer within the check's 2 s");
  EXPECT_EQ(rig.item("COM_OF_LOSS_T").verdict, V::Fail);
  EXPECT_EQ(rig.item("EKF2_EV_DELAY").found, "no answer within the check's 2 s");
  EXPECT_EQ(rig.item("heartbeat").verdict, V::Pass);
  EXPECT_FALSE(rig.check.passed());
}

TEST(Preflight, LandingPathAndOdometryChooseTheParameters) {
  {
    PreflightConfig c;
    c.landing_path = LandingPath::Autopilot;
    Rig rig(ap::Personality::Px4, {}, c);
    rig.run();
    for (const char* n : {"PLD_HACC_RAD", "PLD_BTOUT", "PLD_FAPPR_ALT", "PLD_SRCH_ALT", "PLD_SRCH_TOUT", "PLD_MAX_SRCH"})
      EXPECT_EQ(rig.item(n).verdict, V::Pass) << n;
    EXPECT_EQ(to_line(rig.item("PLD_HACC_RAD")), "PASS PLD_HACC_RAD = 0.2");
    EXPECT_EQ(to_line(rig.item("PLD_MAX_SRCH")), "PASS PLD_MAX_SRCH = 3");
    EXPECT_TRUE(rig.check.passed());
  }
  {
    PreflightConfig c;
    c.landing_path = LandingPath::Autopilot;
    Rig rig(ap::Personality::ArduCopter, {}, c);
    rig.run();
    EXPECT_EQ(to_line(rig.item("PLND_ENABLED")), "PASS PLND_ENABLED = 1 (on)");
    EXPECT_EQ(to_line(rig.item("PLND_TYPE")), "PASS PLND_TYPE = 1 (companion computer)");
    EXPECT_TRUE(rig.check.passed());
  }
  {
    PreflightConfig c;
    c.landing_path = LandingPath::Autopilot;
    ap::Params p;
    p.PLND_ENABLED = 0;
    Rig rig(ap::Personality::ArduCopter, p, c);
    rig.run();
    EXPECT_EQ(to_line(rig.item("PLND_ENABLED")),
              "FAIL PLND_ENABLED = 0 (precision landing off) — set PLND_ENABLED 1 and reboot");
    EXPECT_FALSE(rig.check.passed());
  }
  {
    // Without odometry the vision items are not asked, and a vision height reference FAILs.
    PreflightConfig c;
    c.send_odometry = false;
    Rig rig(ap::Personality::Px4, {}, c);
    rig.run();
    EXPECT_EQ(rig.names(), (std::vector<std::string>{"heartbeat", "version", "signing", "MAV_1_CONFIG", "MAV_1_MODE",
                                                      "SER_TEL2_BAUD", "COM_OF_LOSS_T", "COM_OBL_RC_ACT",
                                                      "EKF2_HGT_REF"}));
    EXPECT_EQ(to_line(rig.item("EKF2_HGT_REF")),
              "FAIL EKF2_HGT_REF = 3 (vision), but Aerie sends no odometry — set EKF2_HGT_REF 2 (range finder) or 0 "
              "(baro), or turn send_odometry on");
    EXPECT_EQ(rig.item("COM_OBL_RC_ACT").verdict, V::Warn);  // vision is no position source without odometry
  }
}

TEST(Preflight, SilentAutopilotTimesOut) {
  Rig rig(Rig::Far::Silent);
  rig.run();
  ASSERT_TRUE(rig.check.done());
  EXPECT_EQ(rig.now_us, 5'000'000 + kStepUs);  // done at the poll of t = 5 s
  ASSERT_EQ(rig.check.items().size(), 1u);
  EXPECT_EQ(to_line(rig.check.items()[0]),
            "FAIL heartbeat: no autopilot HEARTBEAT in 5.0 s — check the endpoint, the wiring (TX to RX, RX to TX, "
            "GND), the baud rate, and that the autopilot's port speaks MAVLink 2");
  EXPECT_FALSE(rig.check.passed());
  // Only heartbeats went out, one a second.
  EXPECT_EQ(rig.sent<mav::Heartbeat>().size(), 5u);
  EXPECT_EQ(rig.written.size(), 5u);
}

TEST(Preflight, SignedCheckAgainstSignedAutopilot) {
  mav::Key key{};
  for (size_t i = 0; i < key.size(); ++i) key[i] = static_cast<uint8_t>(3 * i + 1);
  Rig rig(ap::Personality::Px4, {});
  const int64_t* now = &rig.now_us;
  rig.face->enable_signing(key, [now] { return signing_ticks(*now); });
  rig.check.enable_signing(key, 0, 0);
  rig.wire.set_signing(key, true, [now] { return signing_ticks(*now); });
  rig.run();
  ASSERT_TRUE(rig.check.done());
  EXPECT_EQ(to_line(rig.item("signing")), "PASS signing: signed both ways (key " + mav::fingerprint(key) + ")");
  // The same verdicts as unsigned, but signing.
  EXPECT_EQ(rig.item("COM_OF_LOSS_T").verdict, V::Pass);
  EXPECT_EQ(rig.item("EKF2_EV_CTRL").verdict, V::Pass);
  EXPECT_EQ(rig.item("version").found, "1.14.0 (official)");
  EXPECT_TRUE(rig.check.passed());
  // Every frame out was signed and verified; nothing refused either way.
  ASSERT_FALSE(rig.written.empty());
  for (const auto& f : rig.written) EXPECT_TRUE(f.signature.has_value());
  EXPECT_EQ(rig.wire.counters().refused(), 0u);
  EXPECT_EQ(rig.face->parser_counters().refused(), 0u);
  EXPECT_EQ(rig.check.parser_counters().refused(), 0u);
  ASSERT_TRUE(rig.check.last_signing_timestamp().has_value());
  EXPECT_GT(*rig.check.last_signing_timestamp(), 0u);
}

TEST(Preflight, SignedCheckAgainstUnsignedAutopilotFailsSigning) {
  mav::Key key{};
  key.fill(7);
  Rig rig(ap::Personality::Px4, {});
  rig.check.enable_signing(key, 0, 0);
  rig.run();
  ASSERT_TRUE(rig.check.done());
  // Its heartbeat passes unsigned (as PX4 lets it), its answers do not.
  EXPECT_EQ(rig.item("heartbeat").verdict, V::Pass);
  const CheckItem& s = rig.item("signing");
  EXPECT_EQ(s.verdict, V::Fail);
  EXPECT_NE(s.found.find("the autopilot does not sign"), std::string::npos) << s.found;
  EXPECT_EQ(rig.item("COM_OF_LOSS_T").found, "no answer accepted");
  EXPECT_NE(rig.item("COM_OF_LOSS_T").fix.find("fix signing first"), std::string::npos);
  EXPECT_GT(rig.check.parser_counters().unsigned_refused, 0u);
  EXPECT_FALSE(rig.check.passed());
}

TEST(Preflight, UnsignedCheckAgainstSigningAutopilotSaysWhyNothingAnswers) {
  mav::Key key{};
  key.fill(9);
  Rig rig(ap::Personality::Px4, {});
  const int64_t* now = &rig.now_us;
  rig.face->enable_signing(key, [now] { return signing_ticks(*now); });
  rig.run();
  ASSERT_TRUE(rig.check.done());
  EXPECT_EQ(to_line(rig.item("signing")),
            "WARN signing: the autopilot signs, but without --key nothing is verified — aerie-keys generate --out KEY, "
            "then aerie-mavlink --key KEY --setup-signing over USB; check with --key KEY");
  EXPECT_EQ(to_line(rig.item("COM_OF_LOSS_T")),
            "FAIL COM_OF_LOSS_T: no answer — the autopilot signs and ignores unsigned requests: check with --key KEY");
  EXPECT_GT(rig.face->parser_counters().unsigned_refused, 0u);
  EXPECT_FALSE(rig.check.passed());
}

TEST(Preflight, AutopilotWithAnotherKeyIsNeverHeard) {
  mav::Key ours{}, theirs{};
  ours.fill(1);
  theirs.fill(2);
  Rig rig(ap::Personality::ArduCopter, {});
  const int64_t* now = &rig.now_us;
  rig.face->enable_signing(theirs, [now] { return signing_ticks(*now); });
  rig.check.enable_signing(ours, 0, 0);
  rig.run();
  ASSERT_TRUE(rig.check.done());
  ASSERT_EQ(rig.check.items().size(), 1u);
  const CheckItem& hb = rig.check.items()[0];
  EXPECT_EQ(hb.verdict, V::Fail);
  EXPECT_NE(hb.found.find("frames with a bad signature refused"), std::string::npos) << hb.found;
  EXPECT_NE(hb.fix.find("--setup-signing"), std::string::npos) << hb.fix;
  EXPECT_GT(rig.face->parser_counters().bad_signature, 0u);  // and it refused ours
}

}  // namespace
}  // namespace aerie::bridge
