// Issue 50 §2 in the flight simulator: Dryden turbulence (MIL-F-8785C low altitude) against
// its definition, the moving platform, and the historical defaults reproduced byte for byte.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "common/sim/flight/dryden.hpp"
#include "common/sim/flight/flight_config.hpp"
#include "common/sim/flight/flight_sim.hpp"
#include "common/sim/flight/platform.hpp"
#include "common/util/config.hpp"
#include "tests/common/sim/flight/flight_digest.hpp"

using namespace aerie;
using namespace aerie::sim;

namespace {

constexpr double kFt = 0.3048;

sim::FlightSimConfig landing_config(const char* file) {
  FlightSimConfig c = load_flight_config(util::Config::load(std::string(AERIE_SOURCE_DIR "/config/sim/") + file));
  c.wind.mean_m_s = 3.0;
  c.seed = 11;
  return c;
}

// Mean-free autocorrelation at lag k (samples) of a series.
double autocorrelation(const std::vector<double>& x, size_t k) {
  double s = 0;
  for (size_t i = 0; i + k < x.size(); ++i) s += x[i] * x[i + k];
  return s / static_cast<double>(x.size() - k);
}

}  // namespace

TEST(Dryden, LowAltitudeScalesFollowMilF8785c) {
  // h = 100 ft, W20 = 10 m/s: 0.177 + 0.0823 = 0.2593.
  const DrydenScales s = dryden_low_altitude(100 * kFt, 10.0);
  EXPECT_DOUBLE_EQ(s.sigma_w, 1.0);
  EXPECT_NEAR(s.sigma_u, 1.0 / std::pow(0.2593, 0.4), 1e-12);
  EXPECT_NEAR(s.sigma_u, 1.716, 1e-3);
  EXPECT_DOUBLE_EQ(s.sigma_v, s.sigma_u);
  EXPECT_NEAR(s.L_w, 100 * kFt, 1e-12);
  EXPECT_NEAR(s.L_u, 100 / std::pow(0.2593, 1.2) * kFt, 1e-9);
  EXPECT_DOUBLE_EQ(s.L_v, s.L_u);
  // Below 10 ft the spec's lowest height applies.
  const DrydenScales low = dryden_low_altitude(0.5, 10.0), ten = dryden_low_altitude(10 * kFt, 10.0);
  EXPECT_DOUBLE_EQ(low.L_u, ten.L_u);
  EXPECT_DOUBLE_EQ(low.sigma_u, ten.sigma_u);
}

TEST(Dryden, GustsMatchTheModelsDeviationAndAutocorrelationOverALongSeededRun) {
  // 10 ft, W20 = 5 m/s, airspeed 5 m/s: T_u = T_v = L_u / V (4.6 s), T_w = 0.61 s. 20000 s of
  // gusts are ~4000 correlation times: the sample deviation is within ~2 % of the model's.
  const DrydenScales s = dryden_low_altitude(3.0, 5.0);
  const double V = 5.0, dt = 0.02;
  DrydenGusts g(42);
  g.start(s, V);
  const size_t n = 1'000'000;
  std::vector<double> u(n), v(n), w(n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d x = g.step(dt, s, V);
    u[i] = x.x();
    v[i] = x.y();
    w[i] = x.z();
  }
  const double su = std::sqrt(autocorrelation(u, 0)), sv = std::sqrt(autocorrelation(v, 0)),
               sw = std::sqrt(autocorrelation(w, 0));
  EXPECT_NEAR(su / s.sigma_u, 1.0, 0.05);
  EXPECT_NEAR(sv / s.sigma_v, 1.0, 0.05);
  EXPECT_NEAR(sw / s.sigma_w, 1.0, 0.05);
  // Normalised autocorrelations at lags of 0.5, 1 and 2 time constants, within 0.05 of the
  // model's (R_u = e^{-x}; R_v = (1 - x/2) e^{-x}, which crosses zero at x = 2).
  for (double lag_T : {0.5, 1.0, 2.0}) {
    const double tu = lag_T * s.L_u / V;
    const size_t k = static_cast<size_t>(std::lround(tu / dt));
    EXPECT_NEAR(autocorrelation(u, k) / (su * su), dryden_autocorrelation_u(s, V, k * dt) / (s.sigma_u * s.sigma_u), 0.05)
        << "u at " << lag_T << " T";
    EXPECT_NEAR(autocorrelation(v, k) / (sv * sv), dryden_autocorrelation_v(s, V, k * dt) / (s.sigma_v * s.sigma_v), 0.05)
        << "v at " << lag_T << " T";
    const size_t kw = static_cast<size_t>(std::lround(lag_T * s.L_w / V / dt));
    DrydenScales sw_as_v = s;  // w has v's form with L_w
    sw_as_v.L_v = s.L_w;
    sw_as_v.sigma_v = s.sigma_w;
    EXPECT_NEAR(autocorrelation(w, kw) / (sw * sw), dryden_autocorrelation_v(sw_as_v, V, kw * dt) / (s.sigma_w * s.sigma_w),
                0.05)
        << "w at " << lag_T << " T";
  }
}

TEST(Dryden, TheSameSeedGivesTheSameGustsAndTheSimulatorUsesThem) {
  const DrydenScales s = dryden_low_altitude(5.0, 4.0);
  DrydenGusts a(7), b(7), c(8);
  a.start(s, 4.0);
  b.start(s, 4.0);
  c.start(s, 4.0);
  bool differs = false;
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector3d x = a.step(0.005, s, 4.0), y = b.step(0.005, s, 4.0), z = c.step(0.005, s, 4.0);
    ASSERT_EQ(x, y) << "step " << i;
    differs |= x != z;
  }
  EXPECT_TRUE(differs);

  FlightSimConfig cfg = landing_config("landing_field.yaml");
  cfg.wind.model = "dryden";
  cfg.wind.mean_m_s = 5.0;
  FlightSim s1(cfg), s2(cfg);
  double vertical = 0;
  for (int k = 0; k < 40; ++k) {
    const FlightFrame f1 = s1.step(), f2 = s2.step();
    ASSERT_EQ(f1.wind, f2.wind);
    vertical = std::max(vertical, std::abs(f1.wind.z()));
    EXPECT_NEAR(f1.wind.head<2>().norm(), 5.0, 5.0);  // around the mean
  }
  EXPECT_GT(vertical, 0.0);  // Dryden has a vertical gust; the Gauss-Markov model has none
}

TEST(FlightSimDefaults, GaussMarkovWindAndAStillPlatformReproduceTheHistoricalFramesByteForByte) {
  // Digests of 120 frames with 3 m/s wind from the simulator before the Dryden model and the
  // moving platform existed (git HEAD of 2026-12-01, x86-64).
  EXPECT_EQ(test::flight_digest(landing_config("landing_field.yaml"), 120), 0x4e756f10d672dac8ull);
  EXPECT_EQ(test::flight_digest(landing_config("landing_room.yaml"), 120), 0x34f6817c80890997ull);
  FlightSimConfig explicit_defaults = landing_config("landing_field.yaml");
  explicit_defaults.wind.model = "gauss_markov";
  explicit_defaults.platform.motion = "still";
  explicit_defaults.platform.speed_m_s = 3.0;  // a still platform does not move whatever its speed
  EXPECT_EQ(test::flight_digest(explicit_defaults, 120), 0x4e756f10d672dac8ull);
}

TEST(Platform, MotionsFollowTheirClosedForms) {
  PlatformParams p;
  p.motion = "straight";
  p.speed_m_s = 2.0;
  p.start_time_s = 1.0;
  const PlatformMotion straight(p, std::numbers::pi / 2);
  EXPECT_EQ(straight.offset(0.5), Eigen::Vector2d::Zero());
  EXPECT_NEAR((straight.offset(4.0) - Eigen::Vector2d(0.0, 6.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((straight.velocity(4.0) - Eigen::Vector2d(0.0, 2.0)).norm(), 0.0, 1e-12);

  p.motion = "turning";
  p.start_time_s = 0.0;
  p.turn_rate_deg_s = 20.0;
  const PlatformMotion turning(p, 0.3);
  const double R = 2.0 / (20.0 * std::numbers::pi / 180.0);
  const Eigen::Vector2d centre = R * Eigen::Vector2d(-std::sin(0.3), std::cos(0.3));  // left of the start heading
  for (double t : {0.0, 2.0, 7.0, 15.0}) {
    EXPECT_NEAR((turning.offset(t) - centre).norm(), R, 1e-9) << t;
    if (t == 0.0) continue;  // the drive starts here: no two-sided derivative
    const Eigen::Vector2d numeric = (turning.offset(t + 1e-5) - turning.offset(t - 1e-5)) / 2e-5;
    EXPECT_NEAR((numeric - turning.velocity(t)).norm(), 0.0, 1e-6) << t;
    EXPECT_NEAR(turning.velocity(t).norm(), 2.0, 1e-12);
  }

  p.motion = "braking";
  p.brake_time_s = 3.0;
  p.deceleration_m_s2 = 1.0;
  const PlatformMotion braking(p, 0.0);
  EXPECT_NEAR(braking.offset(3.0).x(), 6.0, 1e-12);
  EXPECT_NEAR(braking.velocity(4.0).x(), 1.0, 1e-12);
  EXPECT_NEAR(braking.offset(20.0).x(), 6.0 + 2.0 * 2.0 / 2.0, 1e-12);  // + v^2 / (2 a), then stands
  EXPECT_EQ(braking.velocity(20.0), Eigen::Vector2d::Zero());
}

TEST(Platform, TheCarDrivesInTheRenderedFieldAndTheTruthFollowsIt) {
  FlightSimConfig cfg = landing_config("landing_field.yaml");
  cfg.wind.mean_m_s = 0;
  cfg.platform.motion = "straight";
  cfg.platform.speed_m_s = 0.3;
  {  // towards the take-off point: the car drives under the climbing vehicle's camera
    const FlightSim probe(cfg);
    const Eigen::Vector3d to = probe.vehicle().state().position - probe.world().helipad().center;
    cfg.platform.heading_deg = std::atan2(to.y(), to.x()) * 180 / std::numbers::pi;
  }
  FlightSim sim(cfg);
  const FlightFrame f0 = sim.step();
  const Eigen::Vector3d pad0 = sim.world().helipad().center;
  const Eigen::Vector3d car0 = sim.world().landing_object()->box.min;
  sim.command({3, {}, 0});
  FlightFrame f = f0;
  for (int k = 0; k < 200; ++k) f = sim.step();  // 10 s: 6 m up, the car 3 m on
  const double psi = cfg.platform.heading_deg * std::numbers::pi / 180;
  const Eigen::Vector3d drive = 3.0 * Eigen::Vector3d(std::cos(psi), std::sin(psi), 0);
  EXPECT_NEAR((sim.world().helipad().center - pad0 - drive).norm(), 0.0, 1e-9);
  EXPECT_NEAR((sim.world().landing_object()->box.min - car0 - drive).norm(), 0.0, 1e-9);
  EXPECT_NEAR((f.platform_velocity - 0.1 * drive.head<2>()).norm(), 0.0, 1e-12);
  // The truth is the moved pad's, and the still simulator's differs by exactly the drive.
  FlightSimConfig still = cfg;
  still.platform.motion = "still";
  FlightSim ref(still);
  ref.step();
  ref.command({3, {}, 0});
  FlightFrame g = ref.step();
  for (int k = 1; k < 200; ++k) g = ref.step();
  ASSERT_EQ(f.vehicle.position, g.vehicle.position);  // the vehicle flies the same
  const Eigen::Vector3d moved = f.T_world_down.inverse() * (pad0 + drive);
  EXPECT_NEAR((f.target.position - moved).norm(), 0.0, 1e-9);
  EXPECT_NEAR((f.target.position - g.target.position).norm(), 3.0, 1e-9);
  // The images show it: the moved pad in view (its box around the projection of its centre).
  ASSERT_TRUE(f.down.target_visible);
  const Intrinsics K = sim.down_intrinsics();
  const cv::Point2d c(K.fx * moved.x() / moved.z() + K.cx, K.fy * moved.y() / moved.z() + K.cy);
  EXPECT_TRUE(f.down.target_box.contains(c));
  EXPECT_GT(cv::norm(f.down.left, g.down.left, cv::NORM_L1), 1e5);
}

TEST(Platform, BadValuesAreRefusedNamingTheKey) {
  auto refused = [](const FlightSimConfig& c, const std::string& what) {
    try {
      c.validate();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what()).find(what) != std::string::npos;
    }
    return false;
  };
  FlightSimConfig c = landing_config("landing_field.yaml");
  c.platform.motion = "drifting";
  EXPECT_TRUE(refused(c, "platform.motion must be still, straight, turning or braking (got 'drifting')"));
  c.platform.motion = "straight";
  c.platform.speed_m_s = 6.0;
  EXPECT_TRUE(refused(c, "platform.speed_m_s must be in [0, 5]"));
  c.platform.speed_m_s = 2.0;
  c.world.kind = "room";
  EXPECT_TRUE(refused(c, "a moving platform needs world.kind field"));
  FlightSimConfig w = landing_config("landing_field.yaml");
  w.wind.model = "von_karman";
  EXPECT_TRUE(refused(w, "wind.model must be gauss_markov or dryden (got 'von_karman')"));
  w.wind.model = "dryden";
  w.wind.mean_m_s = 5.0;  // issue 50: up to 5 m/s
  EXPECT_NO_THROW(w.validate());
}
