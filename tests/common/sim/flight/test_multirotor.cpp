// The multirotor and IMU models: first-order responses with the configured time constants,
// the yaw sign convention, take-off and landing, wind rejection, the IMU at rest.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "common/sim/flight/imu.hpp"
#include "common/sim/flight/multirotor.hpp"

using namespace aerie::sim;

namespace {

constexpr double kDt = 0.005;

// command_timeout_s 0: one command is held for as long as a test runs.
Multirotor airborne(MultirotorParams p = MultirotorParams::by_name("ardrone"), double command_timeout_s = 0) {
  p.velocity_integral_per_s2 = 0;  // the pure first-order loops, to check their time constants
  p.hold_drift_m_per_sqrt_s = 0;
  p.command_timeout_s = command_timeout_s;
  MultirotorState s;
  s.position = {0, 0, 2};
  s.armed = true;
  s.on_ground = false;
  return Multirotor(p, s);
}

void run(Multirotor& m, double& t, double seconds, const Eigen::Vector3d& wind = Eigen::Vector3d::Zero()) {
  for (int i = 0; i < static_cast<int>(std::lround(seconds / kDt)); ++i, t += kDt) m.step(t, kDt, wind);
}

}  // namespace

TEST(Multirotor, ForwardVelocityIsFirstOrderAfterTheLatency) {
  Multirotor m = airborne();
  const auto& p = m.params();
  AutopilotCommand c;
  c.mode = AutopilotCommand::Mode::Velocity;
  c.velocity = {1.0, 0, 0};
  double t = 0;
  m.command(t, c);
  run(m, t, p.base.command_delay_s);
  EXPECT_NEAR(m.state().velocity.norm(), 0.0, 1e-9);  // nothing before the latency
  run(m, t, p.base.velocity_time_constant_s);
  // One time constant after the command acts: 1 - 1/e of the step (drag slows it a little).
  EXPECT_NEAR(m.state().velocity.x(), 1 - std::exp(-1.0), 0.08);
  run(m, t, 8 * p.base.velocity_time_constant_s);
  // Without the integrator, rotor drag leaves the steady-state speed at 1 / (1 + tau * drag).
  EXPECT_NEAR(m.state().velocity.x(), 1.0 / (1 + p.base.velocity_time_constant_s * p.drag_per_s), 0.01);
  EXPECT_GT(m.state().pitch, 0.0);  // accelerating forward pitches the nose down (positive about y)
}

TEST(Multirotor, PositiveYawRateTurnsClockwise) {
  Multirotor m = airborne();
  AutopilotCommand c;
  c.mode = AutopilotCommand::Mode::Velocity;
  c.yaw_rate_deg_s = 30;  // control_cmd_t: positive = clockwise from above
  double t = 0;
  m.command(t, c);
  run(m, t, 2.0);
  EXPECT_LT(m.state().yaw, 0.0);  // ENU yaw decreases when turning clockwise
  EXPECT_NEAR(m.state().yaw_rate, -30 * std::numbers::pi / 180, 0.01);
}

TEST(Multirotor, AVelocityCommandNotRenewedBecomesAHoverAfterTheTimeout) {
  Multirotor m = airborne(MultirotorParams::by_name("ardrone"), 1.0);
  const auto& p = m.params();
  AutopilotCommand c;
  c.mode = AutopilotCommand::Mode::Velocity;
  c.velocity = {1.0, 0, 0};
  double t = 0;
  for (int i = 0; i < 40; ++i) {  // renewed at 20 Hz for 2 s: it flies
    m.command(t, c);
    run(m, t, 0.05);
  }
  EXPECT_GT(m.state().velocity.x(), 0.7);  // 1 m/s less the rotor drag
  EXPECT_EQ(m.command_timeouts(), 0);
  const double x_last = m.state().position.x();
  run(m, t, 6.0);  // then silence (the flight manager died): a hover 1 s after the last command acted
  EXPECT_EQ(m.command_timeouts(), 1);
  EXPECT_EQ(m.active_command().mode, AutopilotCommand::Mode::Hover);
  EXPECT_NEAR(m.state().velocity.norm(), 0.0, 0.02);
  // It flew on for the timeout and the braking, not for the 6 s.
  EXPECT_LT(m.state().position.x() - x_last, 1.0 * (p.base.command_delay_s + p.command_timeout_s) + 1.0);
}

TEST(Multirotor, AClimbSlowsToAStopAtTheHeightFence) {
  MultirotorParams p = MultirotorParams::by_name("ardrone");
  p.command_timeout_s = 0;
  MultirotorState s;
  s.position = {0, 0, 2};
  s.armed = true;
  s.on_ground = false;
  Multirotor m(p, s);
  m.set_ceiling(3.0);
  AutopilotCommand up;
  up.mode = AutopilotCommand::Mode::Velocity;
  up.velocity = {0.5, 0, 1.0};  // forward and up: only the climb is fenced
  m.command(0, up);
  double t = 0, top = 0;
  for (int i = 0; i < 2000; ++i, t += kDt) {
    m.step(t, kDt, Eigen::Vector3d::Zero());
    top = std::max(top, m.state().position.z());
  }
  EXPECT_LT(top, 3.0 + 0.06);  // the vertical loop's lag and integrator overshoot it by a few cm
  EXPECT_NEAR(m.state().position.z(), 3.0, 0.01);
  EXPECT_GT(m.state().velocity.x(), 0.3);
  up.velocity = {0, 0, -0.5};  // descending is never fenced
  m.command(t, up);
  run(m, t, 3.0);
  EXPECT_LT(m.state().position.z(), 2.0);
}

TEST(Multirotor, TakeoffClimbsToItsHeightAndLandDisarmsOnContact) {
  MultirotorParams p = MultirotorParams::by_name("pelican");
  Multirotor m(p, {});
  EXPECT_FALSE(m.state().armed);
  double t = 0;
  AutopilotCommand up;
  up.mode = AutopilotCommand::Mode::Takeoff;
  m.command(t, up);
  run(m, t, 10.0);
  EXPECT_TRUE(m.state().armed);
  EXPECT_NEAR(m.state().position.z(), p.takeoff_height_m, 0.02);
  AutopilotCommand land;
  land.mode = AutopilotCommand::Mode::Land;
  m.command(t, land);
  run(m, t, 5.0);  // the vertical loop settles (its integrator unwinds from the climb)
  EXPECT_NEAR(m.state().velocity.z(), -p.land_speed_m_s, 0.02);
  m.set_contact(0.0);
  EXPECT_FALSE(m.state().armed);
  EXPECT_TRUE(m.state().on_ground);
}

TEST(Multirotor, TheVelocityIntegratorRejectsASteadyWind) {
  MultirotorState s;
  s.position = {0, 0, 2};
  s.armed = true;
  Multirotor m(MultirotorParams::by_name("ardrone"), s);
  AutopilotCommand hover;
  hover.mode = AutopilotCommand::Mode::Hover;
  double t = 0;
  m.command(t, hover);
  run(m, t, 20.0, {2.0, 0, 0});
  EXPECT_NEAR(m.state().velocity.x(), 0.0, 0.01);  // held against a 2 m/s wind
  EXPECT_LT(m.state().pitch, 0.0);                 // leaning into it (nose up to push west)
}

TEST(Multirotor, BadParametersAreNamed) {
  MultirotorParams p = MultirotorParams::by_name("ardrone");
  p.max_tilt_deg = 80;
  EXPECT_THROW(
      {
        try {
          p.validate();
        } catch (const std::invalid_argument& e) {
          EXPECT_NE(std::string(e.what()).find("max_tilt_deg"), std::string::npos);
          throw;
        }
      },
      std::invalid_argument);
  EXPECT_THROW(MultirotorParams::by_name("zeppelin"), std::invalid_argument);
}

TEST(Imu, AtRestItMeasuresGravityAndItsBiasWithTheConfiguredNoise) {
  ImuParams p;
  Imu imu(p, 7);
  const int n = 20000;
  Eigen::Vector3d sum_a = Eigen::Vector3d::Zero(), sum_g = Eigen::Vector3d::Zero();
  double sq = 0;
  for (int i = 0; i < n; ++i) {
    const auto s = imu.sample(i / p.rate_hz, Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
    sum_a += s.accel;
    sum_g += s.gyro - imu.gyro_bias();
    sq += (s.gyro.x() - imu.gyro_bias().x()) * (s.gyro.x() - imu.gyro_bias().x());
  }
  EXPECT_NEAR(sum_a.z() / n, 9.81, 0.3);  // plus a bias of about 0.05
  EXPECT_NEAR(sum_g.norm() / n, 0.0, 1e-4);
  // Discrete gyro noise = density * sqrt(rate).
  EXPECT_NEAR(std::sqrt(sq / n), p.gyro_noise_density * std::sqrt(p.rate_hz), 0.05 * p.gyro_noise_density * std::sqrt(p.rate_hz));
}
