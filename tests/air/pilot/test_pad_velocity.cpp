// The pilot's velocity feed-forward for a moving pad (issue 50 §2): the pad-velocity
// estimator against synthetic poses, and a still pad flown exactly as without it.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "air/pilot/pad_velocity.hpp"
#include "air/pilot/pilot.hpp"
#include "air/pilot/pilot_config.hpp"

using namespace aerie::pilot;

namespace {

constexpr double kDt = 0.05;  // 20 Hz frames

PilotConfig config(bool feedforward) {
  YAML::Node n = YAML::LoadFile(AERIE_SOURCE_DIR "/config/pilot.yaml");
  n["feedforward"]["enabled"] = feedforward;
  YAML::Emitter out;
  out << n;
  return load_pilot_config(aerie::util::Config::parse(out.c_str(), "config/pilot.yaml"));
}

// A vehicle flying its commands as the estimator models it (first order, tau), over a pad
// moving at a constant velocity; poses with 1 cm noise. The vehicle chases the pad.
struct Chase {
  Eigen::Vector2d pad{3.0, -1.0}, pad_v, veh = Eigen::Vector2d::Zero(), veh_v = Eigen::Vector2d::Zero();
  double tau = 0.7;
  std::mt19937_64 rng{5};
  std::normal_distribution<double> noise{0.0, 0.01};
  explicit Chase(Eigen::Vector2d v) : pad_v(v) {}
  Eigen::Vector2d pose() { return pad - veh + Eigen::Vector2d(noise(rng), noise(rng)); }
  void fly(const Eigen::Vector2d& cmd, double dt) {
    const double a = std::exp(-dt / tau);
    veh += cmd * dt + (veh_v - cmd) * tau * (1 - a);
    veh_v = cmd + (veh_v - cmd) * a;
    pad += pad_v * dt;
  }
};

}  // namespace

TEST(PadVelocity, ConvergesToTheTrueVelocityOnSyntheticPoses) {
  for (const Eigen::Vector2d v : {Eigen::Vector2d(2.0, 0.0), Eigen::Vector2d(-1.5, 0.8), Eigen::Vector2d(0.0, -3.0)}) {
    Chase c(v);
    PadVelocityEstimator e;
    double worst_after_5s = 0;
    for (int k = 0; k <= 400; ++k) {  // 20 s
      const double t = k * kDt;
      const Eigen::Vector2d rel = c.pose();
      e.observe(t, rel);
      const Eigen::Vector2d cmd = 0.8 * rel + e.velocity();  // chase with the feed-forward
      e.command(t, cmd);
      c.fly(cmd, kDt);
      if (t >= 5.0) worst_after_5s = std::max(worst_after_5s, (e.velocity() - v).norm());
    }
    EXPECT_TRUE(e.valid());
    EXPECT_LT(worst_after_5s, 0.1) << "pad at " << v.transpose() << " m/s";  // bound: 0.1 m/s from 5 s on
  }
}

TEST(PadVelocity, AGapRestartsItAndBadInputIsRefused) {
  PadVelocityEstimator e;
  for (int k = 0; k < 20; ++k) e.observe(k * kDt, {1.0 + 0.1 * k, 0.0});  // 2 m/s
  EXPECT_TRUE(e.valid());
  EXPECT_GT(e.velocity().x(), 1.0);
  e.observe(20 * kDt + 1.0, {0.0, 0.0});  // 1 s later: a new start
  EXPECT_EQ(e.updates(), 1);
  EXPECT_EQ(e.velocity(), Eigen::Vector2d::Zero());
  EXPECT_THROW(e.observe(5.0, {std::nan(""), 0.0}), std::invalid_argument);
  PadVelocityConfig bad;
  bad.alpha = 1.5;
  try {
    PadVelocityEstimator x(bad);
    FAIL() << "alpha 1.5 accepted";
  } catch (const std::invalid_argument& ex) {
    EXPECT_STREQ(ex.what(), "pilot config: feedforward.alpha must be in (0, 1)");
  }
}

TEST(PadVelocity, AStillPadGivesExactlyZeroFeedForwardAndTheSameCommands) {
  // The same frames (a still pad seen with 1 cm noise, through APPROACH, DESCEND and
  // TOUCHDOWN) to a pilot with and one without the feed-forward: every command identical.
  Pilot with(config(true)), without(config(false));
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.01);
  int64_t utime = 0;
  int frames_in_descent = 0;
  for (int k = 0; k < 1500 && with.state() != State::Landed; ++k) {
    utime += 50000;
    const double height = with.state() == State::Descend ? std::max(1.2, 2.0 - 0.02 * frames_in_descent++) : 2.0;
    const TargetObservation obs{utime, {noise(rng), noise(rng), height}, -std::numbers::pi / 2 + 0.01 * noise(rng), true};
    with.on_target(obs);
    without.on_target(obs);
    const Command a = with.on_track(utime, TrackStatus::Tracking), b = without.on_track(utime, TrackStatus::Tracking);
    ASSERT_EQ(a.mode, b.mode) << k;
    ASSERT_EQ(a.velocity, b.velocity) << k;  // bit for bit
    ASSERT_EQ(std::signbit(a.velocity.x()), std::signbit(b.velocity.x())) << k;
    ASSERT_EQ(a.yaw_rate_deg_s, b.yaw_rate_deg_s) << k;
    ASSERT_EQ(with.status().feedforward, Eigen::Vector2d::Zero()) << k;
    ASSERT_EQ(with.state(), without.state()) << k;
  }
  EXPECT_EQ(with.state(), State::Landed);  // the whole landing was compared
  EXPECT_LT(with.status().pad_velocity.norm(), with.config().feedforward.min_speed_m_s);
}

TEST(PadVelocity, APilotOverAMovingPadFeedsItsVelocityForwardAndDescendsWithIt) {
  // Level, heading east (AHRS yaw 0); the pad drives north at 1.5 m/s. Camera pitched down:
  // image x = -left, image y = -forward.
  Pilot p(config(true));
  Chase c({0.0, 1.5});
  c.pad = {0.3, 0.2};
  int64_t utime = 0;
  double worst = 0;
  Command cmd;
  bool blind_touchdown = false;
  int descent_frames = 0;
  double off_at_land = -1;  // when LAND follows the blind descent (the feet on the roof)
  for (int k = 0; k < 1200 && p.state() != State::Landed; ++k) {
    utime += 50000;
    const double height = p.state() == State::Descend ? std::max(1.2, 2.0 - 0.02 * descent_frames++) : 2.0;
    const Eigen::Vector2d rel = c.pose();  // (forward = east, left = north)
    p.on_target({utime, {-rel.y(), -rel.x(), height}, -std::numbers::pi / 2, true});
    cmd = p.on_track(utime, TrackStatus::Tracking);
    if (p.state() == State::Touchdown) blind_touchdown |= cmd.mode == Command::Mode::Velocity && cmd.velocity.z() < 0;
    if (p.state() == State::Touchdown && cmd.mode == Command::Mode::Land && off_at_land < 0) off_at_land = (c.pad - c.veh).norm();
    c.fly(cmd.mode == Command::Mode::Velocity ? Eigen::Vector2d(cmd.velocity.head<2>()) : Eigen::Vector2d::Zero(), kDt);
    if (k * kDt >= 6.0 && p.state() != State::Touchdown) worst = std::max(worst, (p.status().pad_velocity - c.pad_v).norm());
  }
  EXPECT_LT(worst, 0.15);
  EXPECT_TRUE(blind_touchdown);  // TOUCHDOWN descended with the pad, not with LAND's position hold
  EXPECT_EQ(p.state(), State::Landed);
  EXPECT_GE(off_at_land, 0.0);
  EXPECT_LT(off_at_land, 0.15);  // still over the pad after the blind descent
}
