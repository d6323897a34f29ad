// The vehicle model's steady states and responses, the virtual camera, the zones and
// the avoidance run.
#include <gtest/gtest.h>

#include <cmath>

#include "common/sim/vehicle/avoidance.hpp"
#include "common/sim/vehicle/vehicle.hpp"

using namespace aerie::sim;

TEST(Vehicle, YawRateFirstOrderResponseAndSteadyState) {
  const VehicleParams p = VehicleParams::ar_drone();
  const double dt = 0.002;
  Vehicle v(p, dt);
  const int n_tau = static_cast<int>(std::lround(p.yaw_time_constant_s / dt));
  for (int k = 0; k < n_tau; ++k) v.step(30.0, 0.0);
  EXPECT_NEAR(v.state().yaw_rate_deg_s, 30.0 * (1.0 - std::exp(-1.0)), 1e-9);  // 63.2 % after one tau
  // Heading = the exact integral: 30 t - 30 tau (1 - exp(-t/tau)).
  EXPECT_NEAR(v.state().heading_deg, 30.0 * p.yaw_time_constant_s * std::exp(-1.0), 1e-9);
  for (int k = 0; k < 5000; ++k) v.step(30.0, 0.0);
  EXPECT_NEAR(v.state().yaw_rate_deg_s, 30.0, 1e-9);
  // Commands beyond the autopilot's limit saturate.
  for (int k = 0; k < 5000; ++k) v.step(500.0, 0.0);
  EXPECT_NEAR(v.state().yaw_rate_deg_s, p.max_yaw_rate_deg_s, 1e-9);
  for (int k = 0; k < 5000; ++k) v.step(-500.0, 0.0);
  EXPECT_NEAR(v.state().yaw_rate_deg_s, -p.max_yaw_rate_deg_s, 1e-9);
}

TEST(Vehicle, VelocityFollowsTheHeadingWithItsTimeConstant) {
  for (const VehicleParams& p : {VehicleParams::ar_drone(), VehicleParams::pelican()}) {
    VehicleState s;
    s.vy = 0.8;
    s.heading_deg = 90.0;  // already turned right, still flying toward +y
    const double dt = 0.001;
    Vehicle v(p, dt, s);
    const int n_tau = static_cast<int>(std::lround(p.velocity_time_constant_s / dt));
    for (int k = 0; k < n_tau; ++k) v.step(0.0, 0.8);
    EXPECT_NEAR(v.state().vy, 0.8 * std::exp(-1.0), 1e-9) << p.name;
    EXPECT_NEAR(v.state().vx, 0.8 * (1.0 - std::exp(-1.0)), 1e-9) << p.name;
    // y keeps growing by the integral of the decaying velocity: 0.8 tau (1 - e^-1).
    EXPECT_NEAR(v.state().y, 0.8 * p.velocity_time_constant_s * (1.0 - std::exp(-1.0)), 1e-6) << p.name;
    for (int k = 0; k < 40000; ++k) v.step(0.0, 0.8);
    EXPECT_NEAR(v.state().vx, 0.8, 1e-9);
    EXPECT_NEAR(v.state().vy, 0.0, 1e-9);
    EXPECT_NEAR(v.state().heading_deg, 90.0, 1e-12);
  }
  EXPECT_EQ(VehicleParams::by_name("pelican").name, "pelican");
  EXPECT_THROW(VehicleParams::by_name("blimp"), std::invalid_argument);
}

TEST(VirtualCamera, SeesTheWallAndGivesTheParallelReference) {
  const Scene scene;
  const CameraParams cam;
  CameraView v = look_at_wall(scene, cam, 0.0, 1.0, 0.0);
  ASSERT_TRUE(v.wall_visible);
  EXPECT_NEAR(v.distance_m, 4.0, 1e-12);
  EXPECT_EQ(v.reference_heading_deg, 90.0);
  v = look_at_wall(scene, cam, 0.0, 1.0, -20.0);
  ASSERT_TRUE(v.wall_visible);
  EXPECT_NEAR(v.distance_m, 4.0 / std::cos(20.0 * M_PI / 180.0), 1e-12);
  EXPECT_EQ(v.reference_heading_deg, -90.0);
  EXPECT_FALSE(look_at_wall(scene, cam, 0.0, 1.0, 60.0).wall_visible);    // outside the field of view
  EXPECT_FALSE(look_at_wall(scene, cam, 0.0, -6.0, 0.0).wall_visible);    // beyond range
  EXPECT_FALSE(look_at_wall(scene, cam, 0.0, 1.0, 180.0).wall_visible);   // facing away
}

namespace {
AvoidanceConfig quiet(double speed) {
  AvoidanceConfig c;
  c.speed_m_s = speed;
  c.sensor.noise_std_deg = 0.0;
  c.yaw_gust_std_per_speed = 0.0;
  c.record = true;
  return c;
}
HeadingControl proportional(double gain) {
  return [gain](double, double heading, double ref) { return gain * (ref - heading); };
}
}  // namespace

TEST(Avoidance, ProportionalTurnAvoidsTheWallAndSettles) {
  for (double speed : {0.4, 0.6, 0.8}) {
    const auto r = run_avoidance(quiet(speed), proportional(2.0), 1);
    EXPECT_TRUE(r.activated);
    EXPECT_TRUE(r.completed);
    EXPECT_FALSE(r.entered_dangerous);
    EXPECT_FALSE(r.collided);
    EXPECT_EQ(r.reference_deg, 90.0);
    // Activation at the first sample at or after 1 m (camera rate 30 Hz).
    EXPECT_NEAR(r.activation_time_s, 1.0 / speed, 1.0 / 30 + 1e-9) << speed;
    EXPECT_GT(r.min_wall_distance_m, 1.0);
    EXPECT_GE(r.settle_time_s, 0.0);
    EXPECT_LT(r.steady_rmse_deg, 5.0);
    EXPECT_NEAR(r.trajectory.back().heading_deg, 90.0, 0.5);
    EXPECT_GT(r.itse, 0.0);
  }
}

TEST(Avoidance, DoingNothingHitsTheWall) {
  const auto r = run_avoidance(quiet(0.8), [](double, double, double) { return 0.0; }, 1);
  EXPECT_TRUE(r.collided);
  EXPECT_TRUE(r.entered_dangerous);
  EXPECT_LE(r.min_wall_distance_m, 0.0);
  EXPECT_NEAR(r.duration_s, 5.0 / 0.8, 0.01);
}

TEST(Avoidance, SensorLatencyAndNoiseAreApplied) {
  AvoidanceConfig c = quiet(0.6);
  c.sensor.delay_s = 0.1;
  const auto r = run_avoidance(c, proportional(2.0), 1);
  // Noise-free: the measured heading is the true heading 3 samples (0.1 s) earlier.
  for (size_t k = 3; k < r.trajectory.size(); ++k)
    ASSERT_NEAR(r.trajectory[k].measured_heading_deg, r.trajectory[k - 3].heading_deg, 1e-9) << k;
  c.sensor.noise_std_deg = 1.0;
  c.sensor.delay_s = 0.0;
  const auto n = run_avoidance(c, proportional(2.0), 7);
  double sq = 0.0;
  for (const auto& s : n.trajectory) sq += std::pow(s.measured_heading_deg - s.heading_deg, 2);
  EXPECT_NEAR(std::sqrt(sq / n.trajectory.size()), 1.0, 0.1);
  // Reproducible from the seed, different with another one.
  const auto again = run_avoidance(c, proportional(2.0), 7);
  EXPECT_EQ(again.itse, n.itse);
  EXPECT_NE(run_avoidance(c, proportional(2.0), 8).itse, n.itse);
}

TEST(Avoidance, GustsGrowWithSpeed) {
  double rmse[2];
  const double speeds[2] = {0.4, 0.8};
  for (int k = 0; k < 2; ++k) {
    AvoidanceConfig c = quiet(speeds[k]);
    c.yaw_gust_std_per_speed = 3.0;
    double sum = 0.0;
    for (uint64_t seed = 0; seed < 10; ++seed) sum += run_avoidance(c, proportional(2.0), seed).steady_rmse_deg;
    rmse[k] = sum / 10;
  }
  EXPECT_GT(rmse[1], rmse[0]);
}
