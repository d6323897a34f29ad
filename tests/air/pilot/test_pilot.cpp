// The flight manager's state machine, transition by transition, and its geometry: the
// target from the camera frame into the levelled heading frame, the command signs.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <optional>

#include "air/pilot/pilot.hpp"
#include "air/pilot/pilot_config.hpp"

using namespace aerie::pilot;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr int64_t kFrame = 50000;  // 20 Hz

PilotConfig config(const std::string& controller = "fuzzy") {
  YAML::Node n = YAML::LoadFile(AERIE_SOURCE_DIR "/config/pilot.yaml");
  n["controller"] = controller;
  YAML::Emitter out;
  out << n;
  return load_pilot_config(aerie::util::Config::parse(out.c_str(), "config/pilot.yaml"));
}

// Drives a pilot frame by frame: a target at `height` below the camera, `offset` in the
// image plane (m, camera x right / y down), the pad's axis `yaw_error_deg` clockwise from
// body forward.
struct Flight {
  Pilot pilot;
  int64_t utime = 0;
  explicit Flight(PilotConfig c) : pilot(std::move(c)) {}
  std::optional<double> age_s;  // of every frame on the pilot's clock (nullopt: not comparable)
  Command frame(TrackStatus status = TrackStatus::Idle, double height = 0, Eigen::Vector2d offset = {0, 0},
                double yaw_error_deg = 0, bool fitted = true) {
    utime += kFrame;
    if (status == TrackStatus::Tracking || status == TrackStatus::Redetected)
      pilot.on_target({utime, {offset.x(), offset.y(), height}, (yaw_error_deg - 90) * kDeg, fitted});
    return pilot.on_track(utime, status, age_s);
  }
  // Frames until the state changes (at most n); returns the frames flown.
  int until_change(int n, TrackStatus status = TrackStatus::Idle, double height = 0) {
    const State s = pilot.state();
    for (int i = 1; i <= n; ++i) {
      frame(status, height);
      if (pilot.state() != s) return i;
    }
    return -1;
  }
};

}  // namespace

TEST(Pilot, FliesTheMissionTakeoffSurveyApproachDescendTouchdownLanded) {
  Flight f(config());
  const Command first = f.frame();
  EXPECT_EQ(f.pilot.state(), State::Takeoff);
  EXPECT_EQ(first.mode, Command::Mode::Takeoff);
  const int takeoff_frames = f.until_change(1000);
  EXPECT_NEAR(takeoff_frames * 0.05, f.pilot.config().takeoff_time_s, 0.051);
  EXPECT_EQ(f.pilot.state(), State::Survey);
  const Command leg = f.frame();  // the first leg: backwards
  EXPECT_LT(leg.velocity.x(), 0);
  f.frame(TrackStatus::Tracking, 2.0);
  EXPECT_EQ(f.pilot.state(), State::Approach);
  EXPECT_EQ(f.pilot.status().reason, "target acquired during the survey");
  // Centred, aligned, at the approach height: DESCEND after the settle frames.
  int n = 0;
  while (f.pilot.state() == State::Approach && n < 100) {
    f.frame(TrackStatus::Tracking, 2.0);
    ++n;
  }
  EXPECT_EQ(n, f.pilot.config().settle_frames);
  EXPECT_EQ(f.pilot.state(), State::Descend);
  const double h = f.pilot.config().touchdown_height_m;
  const Command down = f.frame(TrackStatus::Tracking, h + 0.5);
  EXPECT_NEAR(down.velocity.z(), -f.pilot.config().descent_speed_m_s, 1e-9);
  // Off-centre by the gate: the descent stops.
  const Command gated = f.frame(TrackStatus::Tracking, h + 0.5, {f.pilot.config().descent_gate_m, 0});
  EXPECT_NEAR(gated.velocity.z(), 0.0, 1e-9);
  // Near the handover height the descent slows down: it crosses it at 5 cm/s.
  EXPECT_NEAR(f.frame(TrackStatus::Tracking, h + 0.05).velocity.z(), -0.10, 1e-9);
  // Below it but off-centre: hold the height and keep centring, no LAND.
  const Command centring = f.frame(TrackStatus::Tracking, h - 0.01, {0, -0.2});  // ahead
  EXPECT_EQ(f.pilot.state(), State::Descend);
  EXPECT_EQ(centring.mode, Command::Mode::Velocity);
  EXPECT_NEAR(centring.velocity.z(), 0.0, 1e-9);
  EXPECT_GT(centring.velocity.x(), 0.0);
  // Centred: LAND after the handover frames.
  for (int i = 1; i < f.pilot.config().handover_frames; ++i) {
    f.frame(TrackStatus::Tracking, h - 0.01);
    EXPECT_EQ(f.pilot.state(), State::Descend);
  }
  const Command land = f.frame(TrackStatus::Tracking, h - 0.01);
  EXPECT_EQ(f.pilot.state(), State::Touchdown);
  EXPECT_EQ(land.mode, Command::Mode::Land);
  f.until_change(1000);
  EXPECT_EQ(f.pilot.state(), State::Landed);
  EXPECT_EQ(f.frame().mode, Command::Mode::Land);
}

TEST(Pilot, DescendsOnlyOnPosesFittedToThePadAndClimbsOnABoxOnlyPose) {
  PilotConfig c = config();
  c.survey_legs.clear();
  Flight f(c);
  f.frame();
  f.until_change(1000);  // the take-off, then ACQUIRE
  f.frame(TrackStatus::Tracking, c.approach_height_m);
  while (f.pilot.state() == State::Approach) f.frame(TrackStatus::Tracking, c.approach_height_m);
  ASSERT_EQ(f.pilot.state(), State::Descend);
  // A box-only pose (the pad cut by the border), even centred and low: no descent, no
  // LAND, a slow climb and no chase of the box.
  for (int i = 0; i < 2 * c.handover_frames; ++i) {
    const Command up = f.frame(TrackStatus::Tracking, c.touchdown_height_m - 0.1, {0.3, 0}, 0, false);
    EXPECT_EQ(f.pilot.state(), State::Descend);
    EXPECT_EQ(up.mode, Command::Mode::Velocity);
    EXPECT_NEAR(up.velocity.z(), c.hold_climb_m_s, 1e-9);
    EXPECT_EQ(up.velocity.head<2>(), Eigen::Vector2d::Zero());
  }
  // Fitted again: it centres and hands over.
  for (int i = 0; i < c.handover_frames; ++i) f.frame(TrackStatus::Tracking, c.touchdown_height_m - 0.1);
  EXPECT_EQ(f.pilot.state(), State::Touchdown);
}

TEST(Pilot, ATargetSeenDuringTheTakeoffIsApproachedAfterTheMinimumTakeoffTime) {
  Flight f(config());
  f.frame();
  f.frame(TrackStatus::Tracking, 1.2);
  EXPECT_EQ(f.pilot.state(), State::Takeoff);  // too early: still climbing off the ground
  const int frames = [&] {
    for (int i = 1; i < 1000; ++i) {
      f.frame(TrackStatus::Tracking, 1.2);
      if (f.pilot.state() != State::Takeoff) return i + 1;
    }
    return -1;
  }();
  EXPECT_EQ(f.pilot.state(), State::Approach);
  EXPECT_NEAR(frames * 0.05, f.pilot.config().takeoff_min_s, 0.051);
  EXPECT_GT(f.frame(TrackStatus::Tracking, 1.2).velocity.z(), 0.0);  // up to the approach height
}

TEST(Pilot, ALossHoldsAndAReacquisitionResumesTheDescent) {
  Flight f(config());
  f.frame();
  f.until_change(1000);  // take-off
  f.frame(TrackStatus::Tracking, 2.0);
  while (f.pilot.state() != State::Descend) f.frame(TrackStatus::Tracking, 2.0);
  f.frame(TrackStatus::Tracking, 1.6);
  for (int i = 0; i < f.pilot.config().loss_frames - 1; ++i) f.frame(TrackStatus::Lost);
  EXPECT_EQ(f.pilot.state(), State::Descend);  // a short loss is ridden out
  const Command hold = f.frame(TrackStatus::Lost);
  EXPECT_EQ(f.pilot.state(), State::Hold);
  EXPECT_EQ(f.pilot.status().losses, 1);
  EXPECT_EQ(hold.velocity.head<2>().norm(), 0.0);
  EXPECT_GT(f.frame(TrackStatus::Lost).velocity.z(), 0.0);  // climbs slowly for a wider view
  f.frame(TrackStatus::Redetected, 1.7);
  EXPECT_EQ(f.pilot.state(), State::Descend);
  EXPECT_EQ(f.pilot.status().reacquisitions, 1);
  EXPECT_EQ(f.pilot.status().reason, "target re-acquired");
}

TEST(Pilot, ASilentTrackerIsStaleAndHoldsThenTheHoldTimesOutIntoAnAbort) {
  Flight f(config());
  f.frame();
  f.until_change(1000);
  f.frame(TrackStatus::Tracking, 2.0);
  ASSERT_EQ(f.pilot.state(), State::Approach);
  // The IMU clock goes on, no TRACK comes.
  EXPECT_FALSE(f.pilot.on_clock(f.utime + 100000).has_value());
  const auto stale = f.pilot.on_clock(f.utime + 600000);
  ASSERT_TRUE(stale.has_value());
  EXPECT_EQ(f.pilot.state(), State::Hold);
  EXPECT_NE(f.pilot.status().reason.find("stale"), std::string::npos);
  EXPECT_EQ(stale->velocity.head<2>().norm(), 0.0);
  EXPECT_FALSE(f.pilot.on_clock(f.utime + 610000).has_value());  // one tick per control period
  int64_t t = f.utime + 600000;
  while (f.pilot.state() == State::Hold && t < f.utime + 60000000) f.pilot.on_clock(t += kFrame);
  EXPECT_EQ(f.pilot.state(), State::Abort);
  EXPECT_NEAR((t - f.utime - 600000) * 1e-6, f.pilot.config().hold_timeout_s, 0.06);
  const auto climb = f.pilot.on_clock(t += kFrame);
  EXPECT_GT(climb->velocity.z(), 0.0);
  while (f.pilot.state() == State::Abort) f.pilot.on_clock(t += kFrame);
  EXPECT_EQ(f.pilot.state(), State::Aborted);
}

TEST(Pilot, ResultsOlderThanTheAgeLimitHoldAndOnlyFreshOnesResume) {
  // Behind a steady link delay the tracker is never silent, its results are only old: the
  // gap rule above cannot see it (docs/results/linkstudy.md section 4).
  Flight f(config());
  const double limit = f.pilot.config().max_input_age_s;
  ASSERT_GT(limit, 0.0);
  f.frame();
  f.until_change(1000);
  f.frame(TrackStatus::Tracking, 2.0);
  while (f.pilot.state() != State::Descend) f.frame(TrackStatus::Tracking, 2.0);
  f.age_s = limit - 0.01;  // within the limit: flown on
  f.frame(TrackStatus::Tracking, 1.9);
  EXPECT_EQ(f.pilot.state(), State::Descend);
  f.age_s = limit + 0.1;
  const Command hold = f.frame(TrackStatus::Tracking, 1.9);
  EXPECT_EQ(f.pilot.state(), State::Hold);
  EXPECT_EQ(hold.velocity.head<2>().norm(), 0.0);
  EXPECT_NE(f.pilot.status().reason.find("s old (limit"), std::string::npos) << f.pilot.status().reason;
  EXPECT_EQ(f.pilot.status().age_holds, 1);
  EXPECT_EQ(f.pilot.status().losses, 0);  // not a loss: the target is tracked, too late
  for (int i = 0; i < 5; ++i) f.frame(TrackStatus::Tracking, 1.9);  // old results never re-acquire
  EXPECT_EQ(f.pilot.state(), State::Hold);
  EXPECT_EQ(f.pilot.status().aged_results, 6);
  f.age_s.reset();  // clocks not comparable: no age rule
  f.frame(TrackStatus::Tracking, 1.9);
  EXPECT_EQ(f.pilot.state(), State::Descend);
  EXPECT_EQ(f.pilot.status().reacquisitions, 1);
  // A link that stays slow: HOLD, then the hold times out into an abort.
  f.age_s = limit + 0.1;
  const int frames = f.until_change(1000, TrackStatus::Tracking, 1.9);
  EXPECT_EQ(frames, 1);
  EXPECT_EQ(f.pilot.state(), State::Hold);
  const int held = f.until_change(10000, TrackStatus::Tracking, 1.9);
  EXPECT_EQ(f.pilot.state(), State::Abort);
  EXPECT_NEAR(held * 0.05, f.pilot.config().hold_timeout_s, 0.051);
  EXPECT_EQ(f.pilot.status().age_holds, 2);
}

TEST(Pilot, ALostAutopilotLinkHoldsAsStaleInputsAndOnlyItsReturnResumes) {
  Flight f(config());
  f.frame();
  f.until_change(1000);
  f.frame(TrackStatus::Tracking, 2.0);
  while (f.pilot.state() != State::Descend) f.frame(TrackStatus::Tracking, 2.0);
  f.pilot.on_autopilot_link(false, f.utime);
  EXPECT_EQ(f.pilot.state(), State::Hold);
  EXPECT_EQ(f.pilot.status().reason, "autopilot link lost (no heartbeat)");
  EXPECT_EQ(f.pilot.status().link_holds, 1);
  for (int i = 0; i < 5; ++i) f.frame(TrackStatus::Tracking, 1.9);  // tracked, but nothing can fly on it
  EXPECT_EQ(f.pilot.state(), State::Hold);
  f.pilot.on_autopilot_link(true, f.utime);
  f.frame(TrackStatus::Tracking, 1.9);
  EXPECT_EQ(f.pilot.state(), State::Descend);
  EXPECT_EQ(f.pilot.status().reacquisitions, 1);
  f.pilot.on_autopilot_link(false, f.utime);  // lost for good: the hold times out into an abort
  const int held = f.until_change(10000, TrackStatus::Tracking, 1.9);
  EXPECT_EQ(f.pilot.state(), State::Abort);
  EXPECT_NEAR(held * 0.05, f.pilot.config().hold_timeout_s, 0.051);
}

TEST(Pilot, AnAgeLimitOfZeroIsOffAndANegativeOneIsRefused) {
  PilotConfig c = config();
  c.max_input_age_s = 0;
  Flight f(c);
  f.age_s = 30.0;
  f.frame();
  f.until_change(1000);
  f.frame(TrackStatus::Tracking, 2.0);
  EXPECT_EQ(f.pilot.state(), State::Approach);
  EXPECT_EQ(f.pilot.status().aged_results, 0);
  c.max_input_age_s = -0.1;
  try {
    Pilot p(c);
    FAIL() << "a negative age limit was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_input_age_s"), std::string::npos) << e.what();
  }
}

TEST(Pilot, NoTargetAfterTheSurveyAbortsAfterTheAcquireTimeout) {
  PilotConfig c = config();
  c.survey_legs.clear();
  Flight f(c);
  f.frame();
  f.until_change(1000);
  EXPECT_EQ(f.pilot.state(), State::Acquire);
  const int frames = f.until_change(10000);
  EXPECT_EQ(f.pilot.state(), State::Abort);
  EXPECT_NEAR(frames * 0.05, c.acquire_timeout_s, 0.051);
}

TEST(Pilot, OperatorCommandsApplyOnlyWhereTheyMakeSense) {
  PilotConfig c = config();
  c.wait_for_start = true;
  Flight f(c);
  f.frame();
  EXPECT_EQ(f.pilot.state(), State::Idle);  // waits for START
  std::string why;
  EXPECT_FALSE(f.pilot.on_operator(Pilot::Operator::Resume, f.utime, &why));
  EXPECT_EQ(why, "RESUME in state IDLE");
  EXPECT_TRUE(f.pilot.on_operator(Pilot::Operator::Start, f.utime));
  f.frame();
  EXPECT_EQ(f.pilot.state(), State::Takeoff);
  EXPECT_TRUE(f.pilot.on_operator(Pilot::Operator::Abort, f.utime));
  EXPECT_EQ(f.pilot.state(), State::Abort);
  while (f.pilot.state() == State::Abort) f.frame();
  EXPECT_EQ(f.pilot.state(), State::Aborted);
  EXPECT_TRUE(f.pilot.on_operator(Pilot::Operator::Resume, f.utime));
  EXPECT_EQ(f.pilot.state(), State::Acquire);
  EXPECT_TRUE(f.pilot.on_operator(Pilot::Operator::Land, f.utime));
  EXPECT_EQ(f.pilot.state(), State::Touchdown);
  EXPECT_EQ(f.frame().mode, Command::Mode::Land);
  EXPECT_FALSE(f.pilot.on_operator(Pilot::Operator::Abort, f.utime, &why));
  EXPECT_EQ(why, "ABORT in state TOUCHDOWN");
}

TEST(Pilot, CommandsPointAtTheTargetForBothControllers) {
  for (const std::string kind : {"fuzzy", "pid"}) {
    Flight f(config(kind));
    f.frame();
    f.until_change(1000);
    // Ahead (image up = -y), to the right (+x), the pad's axis 20 deg clockwise of forward.
    f.frame(TrackStatus::Tracking, 2.0, {0.3, -0.5}, 20);
    EXPECT_EQ(f.pilot.state(), State::Approach) << kind;
    const Command c = f.frame(TrackStatus::Tracking, 2.0, {0.3, -0.5}, 20);
    EXPECT_GT(c.velocity.x(), 0.1) << kind;       // forward
    EXPECT_LT(c.velocity.y(), -0.05) << kind;     // right = -left
    EXPECT_GT(c.yaw_rate_deg_s, 5.0) << kind;     // clockwise
    EXPECT_NEAR(f.pilot.status().target_level.x(), 0.5, 1e-9) << kind;
    EXPECT_NEAR(f.pilot.status().target_level.y(), -0.3, 1e-9) << kind;
    EXPECT_NEAR(f.pilot.status().height_m, 2.0, 1e-9) << kind;
    EXPECT_NEAR(f.pilot.status().yaw_error_deg, 20.0, 1e-9) << kind;
    // Too low: climb back to the approach height.
    EXPECT_GT(f.frame(TrackStatus::Tracking, 1.2).velocity.z(), 0.1) << kind;
  }
}

TEST(Pilot, TheTargetIsLevelledWithTheAutopilotsAttitude) {
  Flight f(config());
  f.frame();
  f.until_change(1000);
  // Nose down by 10 deg and rolled by 5 deg: a pad 2 m straight below appears off-centre ...
  const Eigen::Quaterniond q = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(10 * kDeg, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(5 * kDeg, Eigen::Vector3d::UnitX());
  f.pilot.on_attitude(f.utime, q);
  const Eigen::Matrix3d R_body_cam = (Eigen::Matrix3d() << 0, -1, 0, -1, 0, 0, 0, 0, -1).finished();  // pitch 90
  const Eigen::Matrix3d tilt = (Eigen::AngleAxisd(-0.7, Eigen::Vector3d::UnitZ()) * q).toRotationMatrix();
  const Eigen::Vector3d cam = R_body_cam.transpose() * (tilt.transpose() * Eigen::Vector3d(0, 0, -2.0));
  f.utime += kFrame;
  f.pilot.on_target({f.utime, cam, -90 * kDeg});
  f.pilot.on_track(f.utime, TrackStatus::Tracking);
  // ... and is straight below once levelled.
  EXPECT_LT(f.pilot.status().target_level.head<2>().norm(), 1e-9);
  EXPECT_NEAR(f.pilot.status().height_m, 2.0, 1e-9);
}

TEST(Pilot, BadInputsAreRefusedWithAReason) {
  Pilot p(config());
  EXPECT_THROW(p.on_target({1, {std::nan(""), 0, 1}, 0}), std::invalid_argument);
  EXPECT_THROW(p.on_target({1, {0, 0, -1}, 0}), std::invalid_argument);  // behind the camera
  EXPECT_THROW(p.on_attitude(1, Eigen::Quaterniond(2, 0, 0, 0)), std::invalid_argument);
  PilotConfig c = config();
  c.touchdown_height_m = 3.0;
  try {
    Pilot bad(c);
    FAIL() << "accepted a touchdown height above the approach height";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("touchdown_height_m"), std::string::npos);
  }
  EXPECT_THROW(load_pilot_config(aerie::util::Config::parse("approach: {hieght_m: 2}\ngains: {fuzzy: {}}\n")),
               std::runtime_error);
  // A gain that would make no controller is refused with the config, naming its axis.
  try {
    load_pilot_config(aerie::util::Config::parse("gains: {fuzzy: {left: {ku: -0.5}}}\n"));
    FAIL() << "accepted a negative output factor";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("gains.fuzzy.left"), std::string::npos) << e.what();
  }
}
