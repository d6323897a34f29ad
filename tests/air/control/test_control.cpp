// aerie-control: heading from pose, the control loop (limits, stale -> hover, run-time
// controller replacement) and the node in-process over memq://.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <aerie/process_status_t.hpp>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <optional>
#include <vector>

#include "air/control/anchor_file.hpp"
#include "air/control/control_config.hpp"
#include "air/control/control_loop.hpp"
#include "air/control/control_node.hpp"
#include "air/control/heading_from_pose.hpp"
#include "common/flc/flc_io.hpp"
#include "common/util/time.hpp"
#include "tests/common/bus/reliability_data.hpp"
#include "tests/support/test_support.hpp"

using namespace aerie;
using namespace aerie::control;

namespace {

void quaternion(const Eigen::Quaterniond& q, double out[4]) {
  out[0] = q.w();
  out[1] = q.x();
  out[2] = q.y();
  out[3] = q.z();
}

// Camera turned by `heading` degrees to the right (clockwise seen from above) in VO's
// frame (y down, zero heading along z).
aerie::pose_t vo_pose(int64_t utime, double heading) {
  aerie::pose_t p{};
  p.utime = utime;
  p.seq = utime / 1000;
  p.status = aerie::pose_t::OK;
  const Eigen::Quaterniond q(Eigen::AngleAxisd(-heading * M_PI / 180.0, Eigen::Vector3d(0, -1, 0)));
  quaternion(q, p.orientation);
  return p;
}

flc::FlcSpec tuned() {
  flc::FlcSpec s = flc::thesis_initial();
  s.id = "tuned";
  s.set_parameter("Kp", 3.0);
  s.set_parameter("Kd", 0.01);
  s.set_parameter("Ki", -0.01);
  return s;
}

// NAV_STATE input, one command per message, the avoidance manoeuvre: 0.4 m/s, turning after 1 m.
NodeOptions nav_avoidance_options() {
  NodeOptions opt;
  opt.input = NodeOptions::Input::kNavState;
  opt.frame = default_heading_frame(opt.input);
  opt.rate_hz = 0;
  opt.control.forward_speed_m_s = 0.4;
  opt.control.activation_distance_m = 1.0;
  return opt;
}

// Level, heading along x, at x metres along it.
aerie::nav_state_t nav_state(int64_t utime, int8_t status, double x) {
  aerie::nav_state_t m{};
  m.utime = utime;
  m.status = status;
  m.orientation[0] = 1;
  m.position[0] = x;
  return m;
}

void drain(bus::Bus& bus) {
  while (bus.handle(0) > 0) {
  }
}

}  // namespace

TEST(HeadingFromPose, VoAndZUpFrames) {
  double q[4];
  const HeadingFrame vo;
  for (double h : {0.0, 30.0, -75.0, 179.0}) {
    quaternion(Eigen::Quaterniond(Eigen::AngleAxisd(-h * M_PI / 180.0, Eigen::Vector3d(0, -1, 0))), q);
    EXPECT_NEAR(heading_from_quaternion(q, vo), h, 1e-9) << h;
  }
  // A pitched camera (looking 20 deg down) has the same heading.
  quaternion(Eigen::Quaterniond(Eigen::AngleAxisd(-40 * M_PI / 180.0, Eigen::Vector3d(0, -1, 0)) *
                                Eigen::AngleAxisd(-20 * M_PI / 180.0, Eigen::Vector3d(1, 0, 0))),
             q);
  EXPECT_NEAR(heading_from_quaternion(q, vo), 40.0, 1e-9);
  // z-up world, zero heading along +y, camera axes: x right, y down, z along the heading.
  HeadingFrame zup;
  zup.up = {0, 0, 1};
  zup.forward = {0, 1, 0};
  const double h = 25.0 * M_PI / 180.0;
  Eigen::Matrix3d r;
  r.col(0) = Eigen::Vector3d(std::cos(h), -std::sin(h), 0);
  r.col(1) = Eigen::Vector3d(0, 0, -1);
  r.col(2) = Eigen::Vector3d(std::sin(h), std::cos(h), 0);
  quaternion(Eigen::Quaterniond(r), q);
  EXPECT_NEAR(heading_from_quaternion(q, zup), 25.0, 1e-9);
  const double bad[4] = {2, 0, 0, 0};
  EXPECT_THROW(heading_from_quaternion(bad, vo), std::invalid_argument);
  quaternion(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d(1, 0, 0))), q);  // looking straight up/down
  EXPECT_THROW(heading_from_quaternion(q, vo), std::invalid_argument);
}

TEST(ControlLoop, HoverActiveLimitsAndStaleFallback) {
  ControlConfig cfg;
  cfg.forward_speed_m_s = 0.6;
  cfg.stale_timeout_s = 0.5;
  cfg.limits.max_yaw_rate_deg_s = 40.0;
  ControlLoop loop(tuned(), cfg);
  EXPECT_EQ(loop.command(0).mode, Mode::kHover);
  EXPECT_EQ(loop.command(0).yaw_rate_deg_s, 0.0);
  // First heading 10 deg: relative reference 100 deg, error 90 -> saturated to the limit.
  ASSERT_TRUE(loop.on_heading(1'000'000, 10.0, 5'000'000));
  Command c = loop.command(5'000'000);
  EXPECT_EQ(c.mode, Mode::kActive);
  EXPECT_DOUBLE_EQ(c.reference_deg, 100.0);
  EXPECT_DOUBLE_EQ(c.error_deg, 90.0);
  EXPECT_DOUBLE_EQ(c.yaw_rate_deg_s, 40.0);
  EXPECT_DOUBLE_EQ(c.forward_speed_m_s, 0.6);
  EXPECT_EQ(c.source_utime, 1'000'000);
  EXPECT_EQ(c.controller_id, "tuned");
  // Older or repeated message time is ignored.
  EXPECT_FALSE(loop.on_heading(1'000'000, 50.0, 5'010'000));
  EXPECT_FALSE(loop.on_heading(2'000'000, NAN, 5'010'000));
  // Held at the reference, the command settles to ~0 (the integral's small share).
  for (int k = 1; k <= 10; ++k) ASSERT_TRUE(loop.on_heading(1'000'000 + k * 33'333, 100.0, 5'000'000 + k * 33'333));
  EXPECT_LT(std::abs(loop.command(5'333'330).yaw_rate_deg_s), 2.0);
  // No heading for longer than the timeout: fallback hover, no speed, no turn.
  c = loop.command(5'333'330 + 600'000);
  EXPECT_EQ(c.mode, Mode::kFallbackHover);
  EXPECT_EQ(c.yaw_rate_deg_s, 0.0);
  EXPECT_EQ(c.forward_speed_m_s, 0.0);
  EXPECT_EQ(loop.command(5'333'330 + 400'000).mode, Mode::kActive);
  // Input resumes: active again.
  ASSERT_TRUE(loop.on_heading(3'000'000, 99.0, 7'000'000));
  EXPECT_EQ(loop.command(7'000'000).mode, Mode::kActive);
}

TEST(ControlLoop, RefusesAnInvalidControllerAndKeepsTheOld) {
  ControlLoop loop(tuned(), ControlConfig{});
  flc::FlcSpec bad = tuned();
  bad.id = "bad";
  bad.inputs[0].positions[1] = -100;  // outside the range and out of order
  const auto reason = loop.set_controller(bad);
  ASSERT_TRUE(reason.has_value());
  EXPECT_NE(reason->find("error"), std::string::npos) << *reason;
  EXPECT_EQ(loop.controller().id, "tuned");
  flc::FlcSpec good = tuned();
  good.id = "good";
  EXPECT_FALSE(loop.set_controller(good).has_value());
  EXPECT_EQ(loop.controller().id, "good");
  ControlConfig c;
  c.stale_timeout_s = 0;
  EXPECT_THROW(ControlLoop(tuned(), c), std::invalid_argument);
}

TEST(ControlConfig, ConfigFileAndErrors) {
  const auto setup = node_setup(util::Config::load((test::source_dir() / "config" / "control.yaml").string()));
  EXPECT_EQ(setup.controller.id, "thesis-initial");
  EXPECT_EQ(setup.options.input, NodeOptions::Input::kVoPose);
  EXPECT_DOUBLE_EQ(setup.options.control.reference_deg, 90.0);
  CliOverrides cli;
  cli.input = "gt";
  cli.reference_deg = -90.0;
  const auto gt = node_setup(util::Config::load((test::source_dir() / "config" / "control.yaml").string()), cli);
  EXPECT_EQ(gt.options.input, NodeOptions::Input::kGtPose);
  EXPECT_EQ(gt.options.frame.up, Eigen::Vector3d(0, 0, 1));  // the shipped config keeps the per-input defaults
  EXPECT_EQ(gt.options.frame.forward, Eigen::Vector3d(0, 1, 0));
  EXPECT_EQ(gt.options.pose_channel, "GT_POSE");
  EXPECT_DOUBLE_EQ(gt.options.control.reference_deg, -90.0);
  try {
    node_setup(util::Config::parse("stale_timeout_s: -1\n", "c.yaml"));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("c.yaml"), std::string::npos) << e.what();
  }
  EXPECT_THROW(node_setup(util::Config::parse("stale_timout_s: 1\n", "c.yaml")), std::runtime_error);  // misspelt key
}

TEST(ControlNode, RefusesMalformedParametersAndTimesOutToHover) {
  bus::Bus bus("memq://");
  bus::StatusReporter status(bus, "control");
  NodeOptions opt;
  opt.control.stale_timeout_s = 0.3;
  ControlNode node(bus, status, tuned(), opt);
  std::vector<aerie::control_cmd_t> cmds;
  bus.subscribe<aerie::control_cmd_t>("CTRL_CMD", [&](const aerie::control_cmd_t& m, const bus::ReceiveInfo&) { cmds.push_back(m); });
  aerie::process_status_t last_status{};
  bus.subscribe<aerie::process_status_t>("STATUS_CONTROL",
                                         [&](const aerie::process_status_t& m, const bus::ReceiveInfo&) { last_status = m; });
  auto counter = [&](const std::string& name) {
    for (int i = 0; i < last_status.ncounters; ++i)
      if (last_status.counter_names[i] == name) return last_status.counter_values[i];
    return int64_t{-1};
  };

  // A heading arrives; the command published right after uses it.
  bus.publish("VO_POSE", vo_pose(1'000'000, 0.0));
  drain(bus);
  int64_t now = util::wall_utime();
  node.publish_command(now);
  drain(bus);
  ASSERT_EQ(cmds.size(), 1u);
  EXPECT_EQ(cmds[0].mode, aerie::control_cmd_t::ACTIVE);
  EXPECT_EQ(cmds[0].utime, 1'000'000);
  EXPECT_GT(cmds[0].yaw_rate_deg_s, 10.0f);  // 90 deg to the right: turn right
  EXPECT_EQ(cmds[0].controller_id, "tuned");

  // Malformed controllers are refused with a reason; the old one stays.
  aerie::flc_params_t bad{};
  bad.controller_id = "broken-fll";
  bad.fll = "Engine: x\nInputVariable: e\n  term: A Gaussian 0 1\n";
  bus.publish("FLC_PARAMS", bad);
  aerie::flc_params_t bad2{};
  bad2.controller_id = "bad-position";
  bad2.names = {"error.Left"};
  bad2.values = {-120.0};  // beyond the range
  bad2.nparams = 1;
  bus.publish("FLC_PARAMS", bad2);
  aerie::flc_params_t bad3 = bad2;
  bad3.controller_id = "unknown-name";
  bad3.names = {"pitch.Left"};
  bad3.values = {1.0};
  bus.publish("FLC_PARAMS", bad3);
  const uint8_t junk[5] = {1, 2, 3, 4, 5};
  bus.publish_raw("FLC_PARAMS", junk, sizeof(junk));  // not even a flc_params_t
  drain(bus);
  status.publish_now();
  drain(bus);
  EXPECT_EQ(counter("params_refused"), 3);
  EXPECT_EQ(counter("FLC_PARAMS.malformed"), 1);
  EXPECT_EQ(last_status.health, aerie::process_status_t::WARN);
  EXPECT_NE(last_status.message.find("unknown-name"), std::string::npos) << last_status.message;
  EXPECT_NE(last_status.message.find("pitch"), std::string::npos) << last_status.message;
  EXPECT_EQ(node.loop().controller().id, "tuned");

  // A valid one (the FLL of another controller) is taken.
  flc::FlcSpec other = tuned();
  other.set_parameter("Kp", 2.0);
  aerie::flc_params_t good{};
  good.controller_id = "ce-sfmf";
  good.fll = flc::to_fll(other);
  bus.publish("FLC_PARAMS", good);
  drain(bus);
  EXPECT_EQ(node.loop().controller().id, "ce-sfmf");
  EXPECT_DOUBLE_EQ(node.loop().controller().parameter("Kp"), 2.0);

  // No heading for longer than the timeout: the fixed-rate commands fall back to hover.
  cmds.clear();
  now = util::wall_utime();
  node.tick(now + 100'000);
  node.tick(now + 110'000);  // within the period: nothing
  node.tick(now + 500'000);
  drain(bus);
  ASSERT_EQ(cmds.size(), 2u);
  EXPECT_EQ(cmds[0].mode, aerie::control_cmd_t::ACTIVE);
  EXPECT_EQ(cmds[1].mode, aerie::control_cmd_t::FALLBACK_HOVER);
  EXPECT_EQ(cmds[1].yaw_rate_deg_s, 0.0f);
  EXPECT_EQ(cmds[1].velocity_body[0], 0.0f);
  EXPECT_EQ(cmds[1].controller_id, "ce-sfmf");

  // A lost VO pose is not a heading.
  aerie::pose_t lost = vo_pose(2'000'000, 10.0);
  lost.status = aerie::pose_t::LOST;
  bus.publish("VO_POSE", lost);
  drain(bus);
  status.publish_now();
  drain(bus);
  EXPECT_EQ(counter("pose_not_ok"), 1);
  EXPECT_EQ(counter("poses"), 1);
  // A pose whose optical axis is vertical has no heading: counted and dropped.
  aerie::pose_t down = vo_pose(3'000'000, 0.0);
  quaternion(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d(1, 0, 0))), down.orientation);
  bus.publish("VO_POSE", down);
  drain(bus);
  status.publish_now();
  drain(bus);
  EXPECT_EQ(counter("bad_pose"), 1);
  EXPECT_EQ(counter("VO_POSE.handler_errors"), 0);
  EXPECT_NE(last_status.message.find("vertical"), std::string::npos) << last_status.message;
}

TEST(ControlNode, OversizedControllersAreRefusedBeforeAllocationAndCommandsGoOn) {
  // FLC_PARAMS of the reliability reproducers: FLL with 1000^3 and 2048 x 2048 x 1024 sets
  // (12 GB and an int overflow; 50 s without CTRL_CMD before). Refused by the set-count bounds
  // before anything is allocated; the control loop keeps its controller and its rate.
  bus::Bus bus("memq://");
  bus::StatusReporter status(bus, "control");
  ControlNode node(bus, status, tuned(), NodeOptions{});
  std::vector<aerie::control_cmd_t> cmds;
  bus.subscribe<aerie::control_cmd_t>("CTRL_CMD", [&](const aerie::control_cmd_t& m, const bus::ReceiveInfo&) { cmds.push_back(m); });
  bus.publish("VO_POSE", vo_pose(1'000'000, 0.0));
  drain(bus);
  for (const char* file : {"flc_params_fll_1000cubed_12GB_alloc.bin", "flc_params_fll_2048x2048x1024_overflow.bin"}) {
    const auto payload = test::read_bytes(test::reliability_data_dir() / file);
    bus.publish_raw("FLC_PARAMS", payload.data(), static_cast<unsigned>(payload.size()));
    drain(bus);
    // Refused by the parser at the 65th set, before any table is sized.
    EXPECT_NE(status.message().find("more than 64 terms"), std::string::npos) << file << ": " << status.message();
    node.publish_command(util::wall_utime());
    drain(bus);
  }
  EXPECT_EQ(status.counter("params_refused"), 2);
  ASSERT_EQ(cmds.size(), 2u);
  for (const auto& c : cmds) {
    EXPECT_EQ(c.mode, aerie::control_cmd_t::ACTIVE);
    EXPECT_EQ(c.controller_id, "tuned");
  }
}

TEST(ControlConfig, RefusesTimeoutsAndRatesOutsideTheirRanges) {
  const auto load = [](const std::string& text) { node_setup(util::Config::parse(text, "control.yaml")); };
  test::expect_refusals(load, {
      {"stale_timeout_s: 1e308\n", "control.yaml: control: stale_timeout_s must be in (0, 60] s"},
      {"limits:\n  max_yaw_rate_deg_s: 1e308\n", "max_yaw_rate_deg_s must be in (0, 720]"},
      {"limits:\n  max_yaw_accel_deg_s2: .nan\n", "max_yaw_accel_deg_s2 must be in [0, 10000]"},
      {"message_time:\n  max_jump_s: 1e308\n", "control.yaml:message_time: key 'max_jump_s' = 1e+308 is outside its valid range [1e-06, 3600] (line 2)"},
      {"message_time:\n  resync_messages: 0\n", "message_time: key 'resync_messages' = 0 is outside its valid range [1, 1000]"},
      {"message_time:\n  stale_timeout_s: 1\n", "staleness is the top-level 'stale_timeout_s'"},
      {"message_time:\n  max_jumps: 1\n", "message_time: unknown key 'max_jumps' (line 2"},
      {"max_input_age_s: -0.1\n", "control.yaml: control: max_input_age_s must be in [0, 60] s (0 = off)"},
      {"max_input_age_s: .nan\n", "max_input_age_s must be in [0, 60] s"},
  });
  EXPECT_EQ(test::refusal(load, "stale_timeout_s: 60\nlimits:\n  max_yaw_rate_deg_s: 720\n"), "");
  const auto setup = node_setup(util::Config::parse("message_time:\n  max_jump_s: 2.5\n  resync_messages: 5\n", "c.yaml"));
  EXPECT_EQ(setup.options.message_time.max_jump_us, 2'500'000);
  EXPECT_EQ(setup.options.message_time.resync_messages, 5);
  // The shipped config parses, with the documented defaults.
  const auto shipped = node_setup(util::Config::load((test::source_dir() / "config" / "control.yaml").string()));
  EXPECT_EQ(shipped.options.message_time.max_jump_us, 10'000'000);
  EXPECT_EQ(shipped.options.message_time.resync_messages, 3);
  EXPECT_EQ(shipped.options.control.max_input_age_s, 0.15);
  EXPECT_EQ(node_setup(util::Config::parse("max_input_age_s: 0\n", "c.yaml")).options.control.max_input_age_s, 0.0);
}

namespace {

// aerie-control in lock-step over memq://: the test owns the node clock; a pose at 30 Hz,
// each followed by the command of that step.
struct LockStep {
  bus::Bus bus{"memq://"};
  bus::StatusReporter status{bus, "control"};
  int64_t now;
  ControlNode node;
  std::vector<aerie::control_cmd_t> cmds;

  explicit LockStep(NodeOptions opt = {}, int64_t start_us = 1'000'000'000)
      : now(start_us), node(bus, status, tuned(), opt, [this] { return now; }) {
    bus.subscribe<aerie::control_cmd_t>("CTRL_CMD",
                                        [this](const aerie::control_cmd_t& m, const bus::ReceiveInfo&) { cmds.push_back(m); });
  }
  // One step of 1/30 s: an optional pose, then the command.
  aerie::control_cmd_t step(std::optional<int64_t> pose_utime, double heading = 0.0) {
    if (pose_utime) bus.publish("VO_POSE", vo_pose(*pose_utime, heading));
    drain(bus);
    now += 33'333;
    node.publish_command(now);
    drain(bus);
    return cmds.back();
  }
};

}  // namespace

TEST(ControlNode, AFutureStampedPoseIsHeldAndControlKeepsFlying) {
  // Issue 20: one VO_POSE with utime = INT64_MAX latched FALLBACK_HOVER for good, every real
  // pose after it counted as pose_out_of_order.
  LockStep s;
  int64_t t = 5'000'000;
  for (int k = 0; k < 5; ++k, t += 33'333) EXPECT_EQ(s.step(t).mode, aerie::control_cmd_t::ACTIVE);
  const auto payload = test::read_bytes(test::reliability_data_dir() / "vo_pose_utime_INT64_MAX.bin");
  s.bus.publish_raw("VO_POSE", payload.data(), static_cast<unsigned>(payload.size()));
  EXPECT_EQ(s.step(std::nullopt).mode, aerie::control_cmd_t::ACTIVE);
  EXPECT_EQ(s.status.counter("VO_POSE.time_jumps"), 1);
  EXPECT_NE(s.status.message().find("VO_POSE utime 9223372036854775807 jumps forwards"), std::string::npos)
      << s.status.message();
  for (int k = 0; k < 60; ++k, t += 33'333) {  // two more seconds of real poses: each one flown
    const auto c = s.step(t);
    ASSERT_EQ(c.mode, aerie::control_cmd_t::ACTIVE) << k;
    EXPECT_EQ(c.utime, t);
  }
  EXPECT_EQ(s.status.counter("poses"), 65);
  EXPECT_EQ(s.status.counter("pose_out_of_order"), 0);
  EXPECT_EQ(s.status.counter("VO_POSE.time_resyncs"), 0);
  EXPECT_EQ(s.status.counter("commands_fallback"), 0);
}

TEST(ControlNode, ABackwardsJumpResynchronisesAfterNPoses) {
  // VO restarts and its utime starts again from 0: the first 2 poses are held (the last
  // command stays, not stale yet), the 3rd re-synchronises the loop, and it flies on.
  LockStep s;
  int64_t t = 500'000'000;
  for (int k = 0; k < 10; ++k, t += 33'333) s.step(t, 10.0);
  const int64_t last = t - 33'333;
  t = 0;
  for (int k = 0; k < 2; ++k, t += 33'333) {
    const auto c = s.step(t, 10.0);
    EXPECT_EQ(c.mode, aerie::control_cmd_t::ACTIVE);
    EXPECT_EQ(c.utime, last);  // the held pose is not flown
  }
  EXPECT_EQ(s.status.counter("VO_POSE.time_jumps"), 2);
  EXPECT_NE(s.status.message().find("backwards"), std::string::npos) << s.status.message();
  for (int k = 0; k < 10; ++k, t += 33'333) {
    const auto c = s.step(t, 10.0);
    ASSERT_EQ(c.mode, aerie::control_cmd_t::ACTIVE) << k;
    EXPECT_EQ(c.utime, t) << k;
    EXPECT_TRUE(std::isfinite(c.yaw_rate_deg_s));
  }
  EXPECT_EQ(s.status.counter("VO_POSE.time_resyncs"), 1);
  EXPECT_EQ(s.status.counter("pose_out_of_order"), 0);
  EXPECT_NE(s.status.message().find("VO_POSE re-synchronised: time moved backwards"), std::string::npos)
      << s.status.message();
}

TEST(ControlNode, A25SecondCameraOutageHoversReportsStaleAndRecovers) {
  LockStep s;
  int64_t t = 5'000'000;
  for (int k = 0; k < 30; ++k, t += 33'333) EXPECT_EQ(s.step(t).mode, aerie::control_cmd_t::ACTIVE);
  // 25 s without a pose: FALLBACK_HOVER after stale_timeout_s (0.5 s), reported stale once.
  int hover = 0;
  for (int k = 0; k < 750; ++k) hover += s.step(std::nullopt).mode == aerie::control_cmd_t::FALLBACK_HOVER;
  EXPECT_GE(hover, 750 - 16);
  EXPECT_EQ(s.status.counter("VO_POSE.stale"), 1);
  EXPECT_EQ(s.status.counter("VO_POSE.outages"), 1);
  EXPECT_EQ(s.status.message().rfind("VO_POSE stale: no message for 0.5", 0), 0u) << s.status.message();
  // The camera comes back 25 s later: 2 poses held, then active again on every pose.
  t += 25'000'000;
  for (int k = 0; k < 2; ++k, t += 33'333) EXPECT_EQ(s.step(t).mode, aerie::control_cmd_t::FALLBACK_HOVER);
  for (int k = 0; k < 30; ++k, t += 33'333) {
    const auto c = s.step(t);
    ASSERT_EQ(c.mode, aerie::control_cmd_t::ACTIVE) << k;
    EXPECT_EQ(c.utime, t);
  }
  EXPECT_EQ(s.status.counter("VO_POSE.stale"), 0);
  EXPECT_EQ(s.status.counter("VO_POSE.time_resyncs"), 1);
  EXPECT_EQ(s.status.counter("pose_out_of_order"), 0);
}

TEST(ControlLoop, AnOldHeadingIsNotFlownOnAndHovers) {
  ControlConfig cfg;
  cfg.forward_speed_m_s = 0.6;
  cfg.activation_distance_m = 1.0;
  ASSERT_EQ(cfg.max_input_age_s, 0.15);
  ASSERT_EQ(cfg.stale_timeout_s, 0.5);
  const Eigen::Vector3d start(0, 0, 0), far(2, 0, 0);
  // Only aged headings so far: no flight yet, a fallback hover (not "no input").
  ControlLoop never(tuned(), cfg);
  ASSERT_TRUE(never.on_heading(1'000'000, 10.0, 1'300'000, start, 0.3));
  EXPECT_EQ(never.command(1'300'000).mode, Mode::kFallbackHover);

  ControlLoop loop(tuned(), cfg), reference(tuned(), cfg);
  // Fresh (0.05 s), then unknown age (another clock): flown.
  ASSERT_TRUE(loop.on_heading(1'000'000, 10.0, 1'050'000, start, 0.05));
  EXPECT_EQ(loop.command(1'050'000).mode, Mode::kActive);
  ASSERT_TRUE(loop.on_heading(1'033'333, 10.0, 1'083'333, start, std::nullopt));
  EXPECT_EQ(loop.command(1'083'333).mode, Mode::kActive);
  EXPECT_FALSE(loop.aged());
  // 0.3 s old: hover with no speed and no turn; the manoeuvre still moves past its
  // activation distance on it.
  ASSERT_TRUE(loop.on_heading(1'066'666, 30.0, 1'366'666, far, 0.3));
  const Command old = loop.command(1'366'666);
  EXPECT_TRUE(loop.aged());
  EXPECT_EQ(old.mode, Mode::kFallbackHover);
  EXPECT_EQ(old.yaw_rate_deg_s, 0.0);
  EXPECT_EQ(old.forward_speed_m_s, 0.0);
  EXPECT_TRUE(loop.turning());
  // Exactly the limit is flown: the FLC goes on as if the old heading had never come.
  ASSERT_TRUE(loop.on_heading(1'100'000, 40.0, 1'400'000, far, 0.15));
  EXPECT_FALSE(loop.aged());
  ASSERT_TRUE(reference.on_heading(1'000'000, 10.0, 1'050'000, start, 0.0));
  ASSERT_TRUE(reference.on_heading(1'033'333, 10.0, 1'083'333, start, 0.0));
  ASSERT_TRUE(reference.on_heading(1'100'000, 40.0, 1'400'000, far, 0.0));
  ASSERT_TRUE(loop.on_heading(1'133'333, 45.0, 1'433'333, far, 0.1));
  ASSERT_TRUE(reference.on_heading(1'133'333, 45.0, 1'433'333, far, 0.0));
  const Command fresh = loop.command(1'433'333), want = reference.command(1'433'333);
  EXPECT_EQ(fresh.mode, Mode::kActive);
  EXPECT_DOUBLE_EQ(fresh.yaw_rate_deg_s, want.yaw_rate_deg_s);
  EXPECT_DOUBLE_EQ(fresh.error_deg, want.error_deg);
  // Old headings for longer than stale_timeout_s: the next fresh one starts the FLC afresh,
  // the same command as a new loop turning on it.
  for (int k = 1; k <= 20; ++k)
    ASSERT_TRUE(loop.on_heading(1'133'333 + k * 33'333, 45.0, 1'733'333 + k * 33'333, far, 0.3));
  EXPECT_EQ(loop.command(2'400'000).mode, Mode::kFallbackHover);
  ASSERT_TRUE(loop.on_heading(1'900'000, 50.0, 2'450'000, far, 0.05));
  ControlLoop restarted(tuned(), cfg);
  ASSERT_TRUE(restarted.on_heading(1'000'000, 10.0, 1'050'000, start, 0.0));
  ASSERT_TRUE(restarted.on_heading(1'900'000, 50.0, 2'450'000, far, 0.0));
  EXPECT_EQ(loop.command(2'450'000).mode, Mode::kActive);
  EXPECT_DOUBLE_EQ(loop.command(2'450'000).yaw_rate_deg_s, restarted.command(2'450'000).yaw_rate_deg_s);
  // 0 turns the rule off.
  cfg.max_input_age_s = 0;
  ControlLoop off(tuned(), cfg);
  ASSERT_TRUE(off.on_heading(1'000'000, 10.0, 1'050'000, start, 30.0));
  EXPECT_EQ(off.command(1'050'000).mode, Mode::kActive);
}

TEST(ControlNode, PosesBehindADelayedLinkHoverAndAreCounted) {
  // Poses stamped on the node's clock and delivered 300 ms late (a steady delay: no gap, so
  // never stale), then 50 ms late.
  LockStep s({}, 5'000'000);
  int64_t t = 5'000'000;
  for (int k = 0; k < 30; ++k, t += 33'333) {
    s.now = t + 300'000;
    const auto c = s.step(t);
    EXPECT_EQ(c.mode, aerie::control_cmd_t::FALLBACK_HOVER) << k;
    EXPECT_EQ(c.velocity_body[0], 0.0f);
  }
  EXPECT_EQ(s.status.counter("aged_poses"), 30);
  EXPECT_EQ(s.status.counter("input_age_ms"), 300);
  EXPECT_EQ(s.status.counter("VO_POSE.stale"), 0);
  t += 250'000;  // the delay falls to 50 ms: the node's clock runs on, a pose is skipped
  for (int k = 0; k < 30; ++k, t += 33'333) {
    s.now = t + 50'000;
    ASSERT_EQ(s.step(t).mode, aerie::control_cmd_t::ACTIVE) << k;
  }
  EXPECT_EQ(s.status.counter("aged_poses"), 30);
  EXPECT_EQ(s.status.counter("input_age_ms"), 50);
}

TEST(ControlLoop, FliesStraightUntilTheActivationDistanceThenTurns) {
  // Thesis 5.1.2: the normal flight area (1 m) is flown straight at zero yaw rate; the turn to
  // the reference starts once the pose has moved that far from the first one.
  ControlConfig cfg;
  cfg.forward_speed_m_s = 0.5;
  cfg.activation_distance_m = 1.0;
  cfg.limits.max_yaw_rate_deg_s = 40.0;
  ControlLoop loop(tuned(), cfg);
  int64_t t = 1'000'000;
  for (int k = 0; k < 20; ++k, t += 50'000) {  // 0.95 m in 20 steps of 5 cm, heading 10 deg
    ASSERT_TRUE(loop.on_heading(t, 10.0, t, Eigen::Vector3d(0.3, 0.05 * k, 2.0)));
    const Command c = loop.command(t);
    EXPECT_EQ(c.mode, Mode::kActive);
    EXPECT_EQ(c.yaw_rate_deg_s, 0.0) << k;
    EXPECT_EQ(c.forward_speed_m_s, 0.5);
    EXPECT_DOUBLE_EQ(c.reference_deg, 100.0);  // known from the first heading on
    EXPECT_DOUBLE_EQ(c.error_deg, 90.0);
    EXPECT_FALSE(loop.turning());
  }
  ASSERT_TRUE(loop.on_heading(t, 10.0, t, Eigen::Vector3d(0.3, 1.0, 2.0)));  // 1 m from the first pose
  EXPECT_TRUE(loop.turning());
  EXPECT_DOUBLE_EQ(loop.command(t).yaw_rate_deg_s, 40.0);  // 90 deg of error, saturated
  // A non-finite position is refused like a non-finite heading.
  EXPECT_FALSE(loop.on_heading(t + 50'000, 10.0, t, Eigen::Vector3d(NAN, 0, 0)));
  ControlConfig bad = cfg;
  bad.activation_distance_m = -1;
  EXPECT_THROW(ControlLoop(tuned(), bad), std::invalid_argument);
}

TEST(HeadingFromPose, NavStateBodyAxisAndConfiguredAxis) {
  // NAV_STATE: a z-up world, the body's x forward, zero heading along world x; yaw is ENU
  // (counter-clockwise), the heading clockwise.
  const HeadingFrame nav = default_heading_frame(NodeOptions::Input::kNavState);
  double q[4];
  for (double yaw : {0.0, 30.0, -120.0}) {
    quaternion(Eigen::Quaterniond(Eigen::AngleAxisd(yaw * M_PI / 180, Eigen::Vector3d::UnitZ()) *
                                  Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY())),  // pitched: same heading
               q);
    EXPECT_NEAR(heading_from_quaternion(q, nav), -yaw, 1e-9) << yaw;
  }
  HeadingFrame zero = nav;
  zero.axis = Eigen::Vector3d::Zero();
  EXPECT_THROW(zero.validate(), std::invalid_argument);
  EXPECT_EQ(default_pose_channel(NodeOptions::Input::kNavState), "NAV_STATE");
  // The config: input nav, its defaults and an axis override; a misspelt input is refused.
  const auto setup = node_setup(util::Config::parse("input: nav\nheading_frame:\n  axis: [0, 1, 0]\n", "c.yaml"));
  EXPECT_EQ(setup.options.pose_channel, "NAV_STATE");
  EXPECT_EQ(setup.options.frame.up, Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(setup.options.frame.axis, Eigen::Vector3d(0, 1, 0));
  EXPECT_EQ(test::refusal([](const std::string& t) { node_setup(util::Config::parse(t, "c.yaml")); }, "input: navv\n"),
            "c.yaml: 'input' must be vo, nav or gt, not 'navv'");
}

TEST(ControlNode, NavStateInputOneCommandPerMessage) {
  // rate_hz 0: every NAV_STATE is answered by one command carrying its utime (lock-step,
  // replay); INITIALISING and LOST states are counted and answered by hover / fallback.
  LockStep s(nav_avoidance_options(), 0);
  auto& [bus, status, now, node, cmds] = s;
  bus.publish("NAV_STATE", nav_state(0, aerie::nav_state_t::INITIALISING, 0));
  for (int k = 1; k <= 30; ++k) {
    now = k * 5'000;
    bus.publish("NAV_STATE", nav_state(now, k == 15 ? aerie::nav_state_t::IMU_ONLY : aerie::nav_state_t::OK, 0.04 * k));
  }
  drain(bus);
  node.tick(10'000'000);  // no timer at rate 0
  drain(bus);
  ASSERT_EQ(cmds.size(), 31u);
  EXPECT_EQ(cmds[0].mode, aerie::control_cmd_t::HOVER);
  EXPECT_EQ(status.counter("nav_not_ok"), 1);
  EXPECT_EQ(status.counter("poses"), 30);  // IMU_ONLY is flown on
  for (int k = 1; k <= 30; ++k) {
    EXPECT_EQ(cmds[k].mode, aerie::control_cmd_t::ACTIVE);
    EXPECT_EQ(cmds[k].utime, k * 5'000);
    EXPECT_FLOAT_EQ(cmds[k].velocity_body[0], 0.4f);
    // Straight until 1 m from the first pose (x = 0.04 at k = 1; 1 m at k = 26), then turning.
    if (k < 26) EXPECT_EQ(cmds[k].yaw_rate_deg_s, 0.0f) << k;
    else EXPECT_GT(cmds[k].yaw_rate_deg_s, 10.0f) << k;
  }
  EXPECT_TRUE(node.loop().turning());
}

TEST(ControlNode, TheManoeuvreIsRefusedWhenItsFrameIsLost) {
  // The fault campaign (docs/faults.md): a respawned aerie-nav starts a new frame, a respawned
  // aerie-control would re-anchor the manoeuvre where the vehicle is; both flew into the wall.
  for (const bool restarted_nav : {true, false}) {
    LockStep s(nav_avoidance_options(), 0);
    auto& [bus, status, now, node, cmds] = s;
    // Nav restarted (OK, then INITIALISING, then OK in its new frame); or a control started
    // in flight, its first pose 2 m from the frame's origin.
    const double x0 = restarted_nav ? 0.0 : 2.0;
    for (int k = 1; k <= 10; ++k) bus.publish("NAV_STATE", nav_state(now = k * 5'000, aerie::nav_state_t::OK, x0 + 0.04 * k));
    if (restarted_nav) {
      bus.publish("NAV_STATE", nav_state(now = 50'500, aerie::nav_state_t::INITIALISING, 0));  // one alone: corrupt
      bus.publish("NAV_STATE", nav_state(now = 51'000, aerie::nav_state_t::OK, 0.41));
      for (int k = 0; k < 3; ++k) bus.publish("NAV_STATE", nav_state(now = 52'000 + 1'000 * k, aerie::nav_state_t::INITIALISING, 0));
    }
    for (int k = 12; k <= 20; ++k) bus.publish("NAV_STATE", nav_state(now = k * 5'000, aerie::nav_state_t::OK, 0.04 * k));
    drain(bus);
    ASSERT_EQ(cmds.size(), restarted_nav ? 24u : 19u) << restarted_nav;
    EXPECT_EQ(cmds.front().mode, restarted_nav ? aerie::control_cmd_t::ACTIVE : aerie::control_cmd_t::FALLBACK_HOVER);
    if (restarted_nav) {  // after the lone INITIALISING
      EXPECT_EQ(cmds[11].mode, aerie::control_cmd_t::ACTIVE);
    }
    EXPECT_EQ(cmds.back().mode, aerie::control_cmd_t::FALLBACK_HOVER) << restarted_nav;  // for good
    EXPECT_EQ(cmds.back().velocity_body[0], 0.0f);
    EXPECT_EQ(cmds.back().yaw_rate_deg_s, 0.0f);
    EXPECT_EQ(status.counter("mission_refused"), 1);
  }
}

TEST(ControlNode, ARestartedControlResumesTheManoeuvreFromItsAnchorFile) {
  NodeOptions opt = nav_avoidance_options();
  opt.anchor_file = (test::scratch_dir("control_anchor") / "control.anchor").string();
  LockStep first(opt, 0), continuing(opt, 0);
  // The mission starts at the frame's origin: the anchor is kept (the first OK pose).
  for (auto* s : {&first, &continuing})
    for (int k = 1; k <= 10; ++k) s->bus.publish("NAV_STATE", nav_state(s->now = k * 5'000, aerie::nav_state_t::OK, 0.04 * k));
  drain(first.bus);
  drain(continuing.bus);
  std::string why;
  const auto kept = read_anchor(opt.anchor_file, "NAV_STATE", why);
  ASSERT_TRUE(kept) << why;
  EXPECT_EQ(kept->utime, 5'000);
  EXPECT_DOUBLE_EQ(kept->start.x(), 0.04);
  EXPECT_DOUBLE_EQ(kept->reference_deg, 90.0);
  // aerie-control dies; its respawn's first pose is 2 m out, past the activation distance:
  // it resumes the manoeuvre and turns exactly as the one that lived on.
  LockStep respawned(opt, 0);
  for (auto* s : {&respawned, &continuing})
    for (int k = 40; k <= 60; ++k) s->bus.publish("NAV_STATE", nav_state(s->now = k * 5'000, aerie::nav_state_t::OK, 0.05 * k));
  drain(respawned.bus);
  drain(continuing.bus);
  EXPECT_EQ(respawned.status.counter("anchor_resumed"), 1);
  EXPECT_EQ(respawned.status.counter("mission_refused"), 0);
  ASSERT_EQ(respawned.cmds.size(), 21u);
  ASSERT_EQ(continuing.cmds.size(), 31u);
  for (size_t i = 0; i < respawned.cmds.size(); ++i) {
    const auto &a = respawned.cmds[i], &b = continuing.cmds[10 + i];
    ASSERT_EQ(a.mode, aerie::control_cmd_t::ACTIVE) << i;
    EXPECT_EQ(a.yaw_rate_deg_s, b.yaw_rate_deg_s) << i;
    EXPECT_EQ(a.heading_ref_deg, 90.0f);
  }
  EXPECT_GT(respawned.cmds.back().yaw_rate_deg_s, 1.0f);  // turning right, toward the reference

  // Refused, with the reason, when the file cannot be taken up: another channel's, older than
  // 10 minutes, or not an anchor file.
  const auto refused_with = [&](const std::string& text, const std::string& reason) {
    {
      std::ofstream(opt.anchor_file, std::ios::trunc) << text;
    }
    LockStep s(opt, 0);
    s.bus.publish("NAV_STATE", nav_state(s.now = 700'000'000, aerie::nav_state_t::OK, 2.0));
    drain(s.bus);
    EXPECT_EQ(s.status.counter("mission_refused"), 1) << text;
    EXPECT_NE(s.status.message().find(reason), std::string::npos) << s.status.message();
    EXPECT_EQ(s.cmds.back().mode, aerie::control_cmd_t::FALLBACK_HOVER);
  };
  refused_with("aerie-control anchor 1\nchannel VO_POSE\nutime 5000\nstart 0 0 0\nreference_deg 90\n",
               "the anchor is in VO_POSE's frame, not NAV_STATE's");
  refused_with("aerie-control anchor 1\nchannel NAV_STATE\nutime 5000\nstart 0 0 0\nreference_deg 90\n",
               "is not from the 10 minutes before this pose");
  refused_with("aerie-control anchor 1\nchannel NAV_STATE\nutime 600000000\nstart 0 nan 0\nreference_deg 90\n",
               "not an anchor file of aerie-control");
  refused_with("aerie-control anchor 1\nchannel NAV_STATE\nutime 600000000\nstart 0 0 0\n", "not an anchor file");
  // Without a file configured, the reason says so.
  opt.anchor_file = "";
  LockStep none(opt, 0);
  none.bus.publish("NAV_STATE", nav_state(none.now = 5'000, aerie::nav_state_t::OK, 2.0));
  drain(none.bus);
  EXPECT_NE(none.status.message().find("no anchor_file is configured"), std::string::npos) << none.status.message();
}

// Issue 46: an FLC_PARAMS controller with Ku = -50 was accepted and inverted the yaw command.
// Scaling factors, output range and the turn's sign are checked; a refused controller is
// counted, its reason names the field, and the old one keeps flying.
TEST(ControlNode, ControllersOutsideTheirRangesAreRefusedAndTheOldOneKeepsFlying) {
  bus::Bus bus("memq://");
  bus::StatusReporter status(bus, "control");
  ControlNode node(bus, status, tuned(), NodeOptions{});
  std::vector<aerie::control_cmd_t> cmds;
  bus.subscribe<aerie::control_cmd_t>("CTRL_CMD", [&](const aerie::control_cmd_t& m, const bus::ReceiveInfo&) { cmds.push_back(m); });
  bus.publish("VO_POSE", vo_pose(1'000'000, 0.0));
  drain(bus);
  auto params = [](const std::string& id, const std::string& name, double value) {
    aerie::flc_params_t m{};
    m.controller_id = id;
    m.nparams = 1;
    m.names = {name};
    m.values = {value};
    return m;
  };
  auto with_fll = [](const std::string& id, const flc::FlcSpec& spec) {
    aerie::flc_params_t m{};
    m.controller_id = id;
    m.fll = flc::to_fll(spec);
    return m;
  };
  flc::FlcSpec inverted = tuned();  // every rule's output mirrored: turns away from the reference
  for (auto& r : inverted.rules) r.out = inverted.output.size() - 1 - r.out;
  flc::FlcSpec wide = tuned();
  wide.output.min = -5000;
  wide.output.max = 5000;
  const std::vector<std::pair<aerie::flc_params_t, std::string>> cases{
      {params("ku-50", "Ku", -50),
       "Ku (scaling of output 'yaw_rate') = -50 is outside [0.01, 100]: a negative factor reverses the command"},
      {params("kp-neg", "Kp", -3), "Kp (scaling of input 'error') = -3 is outside [0.01, 100]"},
      {params("kp-huge", "error.scaling", 1e6), "Kp (scaling of input 'error') = 1e+06 is outside [0.01, 100]"},
      {params("kp-tiny", "Kp", 1e-9), "Kp (scaling of input 'error') = 1e-09 is outside [0.01, 100]"},
      {params("kd-neg", "Kd", -0.01), "Kd (scaling of input 'derivative') = -0.01 is outside (0, 100]"},
      {params("ki-huge", "Ki", -500), "Ki (scaling of input 'integral') = -500 is outside |Ki| in (0, 100]"},
      {params("ku-huge", "Ku", 1e9), "Ku (scaling of output 'yaw_rate') = 1e+09 is outside [0.01, 100]"},
      {params("unordered", "error.Left", 10), "set 'Zero' position 0 must be greater than 'Left' (10)"},
      {params("nan", "Kp", std::nan("")), "parameter 'Kp' is not finite"},
      {with_fll("wide", wide), "output 'yaw_rate' range [-5000, 5000] must hold 0 inside and lie within [-720, 720] deg/s"},
      {with_fll("inverted", inverted), "does not turn toward the reference"},
  };
  int64_t refused = 0;
  for (const auto& [m, why] : cases) {
    bus.publish("FLC_PARAMS", m);
    drain(bus);
    EXPECT_EQ(status.counter("params_refused"), ++refused) << m.controller_id;
    EXPECT_NE(status.message().find(why), std::string::npos) << m.controller_id << ": " << status.message();
    EXPECT_NE(status.message().find("refused controller '" + m.controller_id + "'"), std::string::npos) << status.message();
    EXPECT_NE(status.message().find("(keeping 'tuned')"), std::string::npos) << status.message();
    EXPECT_EQ(node.loop().controller().id, "tuned");
    EXPECT_DOUBLE_EQ(node.loop().controller().parameter("Ku"), 1.0);
  }
  EXPECT_EQ(status.counter("params_accepted"), 0);
  // The old controller still turns right toward the reference 90 deg to the right.
  node.publish_command(util::wall_utime());
  drain(bus);
  ASSERT_EQ(cmds.size(), 1u);
  EXPECT_EQ(cmds[0].mode, aerie::control_cmd_t::ACTIVE);
  EXPECT_GT(cmds[0].yaw_rate_deg_s, 10.0f);
  EXPECT_EQ(cmds[0].controller_id, "tuned");
  // Inside the ranges (Ki negative, as CE finds it) a controller is taken.
  bus.publish("FLC_PARAMS", params("ki-neg", "Ki", -0.5));
  drain(bus);
  EXPECT_EQ(status.counter("params_accepted"), 1);
  EXPECT_EQ(node.loop().controller().id, "ki-neg");
}

TEST(ControlNode, TheShippedControllersPassTheIncomingChecks) {
  for (const char* file : {"initial.yaml", "sf.yaml", "sfmf.yaml"}) {
    const flc::FlcSpec spec = flc::load_controller((test::source_dir() / "config" / "flc" / file).string());
    EXPECT_NO_THROW(check_incoming_controller(spec, file)) << file;
    // and as ceopt sends them: FLL
    aerie::flc_params_t m{};
    m.controller_id = file;
    m.fll = flc::to_fll(spec);
    EXPECT_NO_THROW(controller_from_message(m, tuned())) << file;
  }
  EXPECT_NO_THROW(check_incoming_controller(flc::thesis_initial(), "initial"));
}

namespace {

// 2 s of VO_POSE at 30 Hz turning from 0 to 20 deg, 1 s LOST, 1 s OK again at 20 deg: stamped from t0.
std::vector<aerie::pose_t> turn_lost_and_back(int64_t t0) {
  std::vector<aerie::pose_t> poses;
  for (int k = 0; k < 120; ++k) {
    aerie::pose_t p = vo_pose(t0 + k * 33'333, k < 60 ? k / 3.0 : 20.0);
    if (k >= 60 && k < 90) p.status = aerie::pose_t::LOST;
    poses.push_back(p);
  }
  return poses;
}

// The CTRL_CMD answering each pose (rate 0), on the node clock `clock`; `before` runs before each pose.
std::vector<aerie::control_cmd_t> answers(const std::vector<aerie::pose_t>& poses, bool message_clock,
                                          util::NodeClock clock, const std::function<void(const aerie::pose_t&)>& before = {}) {
  bus::Bus bus("memq://");
  bus::StatusReporter status(bus, "control");
  NodeOptions opt;
  opt.rate_hz = 0;
  opt.message_clock = message_clock;
  ControlNode node(bus, status, tuned(), opt, std::move(clock));
  std::vector<aerie::control_cmd_t> cmds;
  bus.subscribe<aerie::control_cmd_t>("CTRL_CMD", [&](const aerie::control_cmd_t& m, const bus::ReceiveInfo&) { cmds.push_back(m); });
  for (const auto& p : poses) {
    if (before) before(p);
    bus.publish("VO_POSE", p);
    drain(bus);
  }
  return cmds;
}

std::vector<uint8_t> encoded(const aerie::control_cmd_t& m) {
  std::vector<uint8_t> b(static_cast<size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

int count_mode(const std::vector<aerie::control_cmd_t>& cmds, int8_t mode) {
  return static_cast<int>(std::count_if(cmds.begin(), cmds.end(), [&](const auto& c) { return c.mode == mode; }));
}

}  // namespace

TEST(ControlNode, AReplayOnTheLogsTimeGivesTheLiveCommandsNotAHover) {
  // Issue 49: replayed 7.5 s after it was recorded, every pose was judged 7478 ms old on the wall
  // clock and every CTRL_CMD was a hover. A flight recorded 7.478 s and 3 days ago: live, each pose
  // arrived 20 ms after its frame; replayed as aerie-control --replay does (the wall clock is the
  // node's clock but the log's own time is used), the commands are the live ones byte for byte.
  for (const int64_t ago : {int64_t{7'478'000}, int64_t{3} * 86'400'000'000}) {
    const auto poses = turn_lost_and_back(util::wall_utime() - ago);
    int64_t now = 0;
    const auto live = answers(poses, false, [&] { return now; }, [&](const aerie::pose_t& p) { now = p.utime + 20'000; });
    ASSERT_EQ(live.size(), 120u);
    // Flown on every fresh pose; LOST for longer than stale_timeout_s (0.5 s): from the 16th LOST
    // pose on FALLBACK_HOVER, until the first OK one.
    EXPECT_EQ(count_mode(live, aerie::control_cmd_t::ACTIVE), 105);
    EXPECT_EQ(count_mode(live, aerie::control_cmd_t::FALLBACK_HOVER), 15);
    EXPECT_EQ(live[89].mode, aerie::control_cmd_t::FALLBACK_HOVER);
    EXPECT_EQ(live[90].mode, aerie::control_cmd_t::ACTIVE);
    EXPECT_GT(std::abs(live[30].yaw_rate_deg_s), 1.0f);
    const auto replayed = answers(poses, true, util::wall_utime);
    ASSERT_EQ(replayed.size(), live.size()) << ago;
    for (size_t i = 0; i < live.size(); ++i)
      ASSERT_EQ(encoded(replayed[i]), encoded(live[i])) << "command " << i << ", replayed " << ago << " us later";
  }
  // On the wall clock, what a replay used to do: 7.478 s old is past max_input_age_s, every pose hovers.
  const auto old_rule = answers(turn_lost_and_back(util::wall_utime() - 7'478'000), false, util::wall_utime);
  EXPECT_EQ(count_mode(old_rule, aerie::control_cmd_t::ACTIVE), 0);
  // 3 days old, the wall-clock age is not comparable, but a replay faster than real time never
  // saw the second of LOST poses go stale: no FALLBACK_HOVER where the live flight had 15.
  const auto burst = answers(turn_lost_and_back(util::wall_utime() - int64_t{3} * 86'400'000'000), false, util::wall_utime);
  EXPECT_EQ(count_mode(burst, aerie::control_cmd_t::FALLBACK_HOVER), 0);
}
