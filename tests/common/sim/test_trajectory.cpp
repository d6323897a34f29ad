// Trajectories: continuity, speed, exact return of the loops, phases, frame stepping.
#include <gtest/gtest.h>

#include <cmath>

#include "common/sim/simulation.hpp"
#include "common/sim/trajectory.hpp"
#include "tests/common/sim/sim_fixtures.hpp"

namespace aerie::sim {
namespace {

// Largest position step and rotation step between samples dt apart.
void expect_continuous(const Trajectory& tr, double max_speed, double max_yaw_rate) {
  const double dt = 1e-3;
  geometry::SE3 prev = tr.pose(0);
  for (double t = dt; t <= tr.duration(); t += dt) {
    const geometry::SE3 cur = tr.pose(t);
    const double dp = (cur.translation() - prev.translation()).norm();
    const double dr = geometry::rotation_angle((prev.inverse() * cur).rotation_matrix());
    ASSERT_LE(dp, max_speed * dt * 1.02 + 1e-9) << "position jump at t=" << t;
    ASSERT_LE(dr, max_yaw_rate * dt * 1.02 + 1e-9) << "rotation jump at t=" << t;
    // Upright: the body z axis stays vertical (yaw only).
    ASSERT_NEAR(cur.rotation_matrix()(2, 2), 1.0, 1e-12);
    prev = cur;
  }
}

TEST(SimTrajectory, DemoFlightIsSmoothAndLandsOnTheHelipad) {
  const World& w = test::light_world();
  const double speed = 0.8;
  const Trajectory tr = Trajectory::demo_flight(w, speed);
  // Turns on arcs of radius r at speed v: yaw rate v / r; turn on the spot is slower than 1.
  expect_continuous(tr, speed, std::max(speed / w.route().corner_radius, 1.0));
  const Eigen::Vector3d start = tr.pose(0).translation(), end = tr.pose(tr.duration()).translation();
  EXPECT_NEAR(start.x(), w.route().home.x(), 1e-12);
  EXPECT_NEAR(start.y(), w.route().home.y(), 1e-12);
  EXPECT_LT(start.z(), 0.2);
  EXPECT_NEAR(end.x(), w.helipad().center.x(), 1e-12);
  EXPECT_NEAR(end.y(), w.helipad().center.y(), 1e-12);
  EXPECT_LT(end.z(), 0.2);
  const char* names[] = {"takeoff", "survey", "turn", "approach", "descent"};
  ASSERT_EQ(tr.phases().size(), 5u);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(tr.phases()[i].name, names[i]);
    if (i) {
      EXPECT_DOUBLE_EQ(tr.phases()[i].t_begin, tr.phases()[i - 1].t_end);
    }
  }
  EXPECT_DOUBLE_EQ(tr.phases().back().t_end, tr.duration());
  // The survey reaches the cruise altitude and the route's corners.
  const auto& sv = tr.phases()[1];
  EXPECT_NEAR(tr.pose(0.5 * (sv.t_begin + sv.t_end)).translation().z(), w.route().altitude, 1e-12);
}

TEST(SimTrajectory, SurveyLoopsReturnExactlyToTheStart) {
  const World& w = test::light_world();
  const Trajectory tr = Trajectory::survey_loops(w, 10, 1.2);
  const geometry::SE3 a = tr.pose(0), b = tr.pose(tr.duration());
  EXPECT_EQ(a.translation(), b.translation());
  EXPECT_EQ(a.rotation().coeffs(), b.rotation().coeffs());
  EXPECT_GT(tr.length(), 250.0);  // hundreds of metres for drift tests
  // Speed profile: cruise at the requested speed, starting and ending at rest.
  const double dt = 0.01;
  EXPECT_LT((tr.pose(dt).translation() - a.translation()).norm(), 1e-3);
  const double mid = 0.5 * tr.duration();
  EXPECT_NEAR((tr.pose(mid + dt).translation() - tr.pose(mid).translation()).head<2>().norm() / dt, 1.2, 0.01);
  expect_continuous(tr, 1.3, 1.2 / w.route().corner_radius);
  // Altitude wave stays clear of floor and ceiling; the loop's length is its perimeter plus
  // the small extra of the wave.
  for (double t = 0; t < tr.duration(); t += 0.5) {
    const double z = tr.pose(t).translation().z();
    EXPECT_GT(z, 1.0);
    EXPECT_LT(z, 2.0);
  }
  EXPECT_THROW(Trajectory::survey_loops(w, 0, 1.0), std::invalid_argument);
  EXPECT_THROW(Trajectory::survey_loops(w, 1, 0.0), std::invalid_argument);
}

TEST(SimTrajectory, LandingIsTheEndOfTheDemo) {
  const World& w = test::light_world();
  const Trajectory demo = Trajectory::demo_flight(w);
  const Trajectory land = Trajectory::landing(w);
  const double offset = demo.phases()[3].t_begin;
  EXPECT_NEAR(land.duration(), demo.duration() - offset, 1e-9);
  for (double t = 0; t < land.duration(); t += 0.7) {
    EXPECT_EQ(land.pose(t).translation(), demo.pose(offset + t).translation());
  }
  ASSERT_EQ(land.phases().size(), 2u);
  EXPECT_EQ(land.phases()[0].name, "approach");
  EXPECT_EQ(land.phases()[1].name, "descent");
  EXPECT_THROW(demo.slice(5, 1), std::invalid_argument);
}

TEST(SimTrajectory, SimulationStepsFramesAtTheRate) {
  const World& w = test::light_world();
  RigConfig rig;
  rig.width = 64;
  rig.height = 40;
  StereoSimulation sim(w, rig, Trajectory::landing(w), 20.0, 1'000'000);
  const double T = Trajectory::landing(w).duration();
  EXPECT_EQ(sim.frame_count(), static_cast<int>(std::floor(T * 20)) + 1);
  StereoFrame f;
  int n = 0;
  while (sim.next(f)) {
    EXPECT_EQ(f.seq, n);
    EXPECT_EQ(f.utime, 1'000'000 + n * 50'000);
    const geometry::SE3 expect = sim.trajectory().pose(n / 20.0) * body_to_left(rig);
    EXPECT_NEAR((f.T_world_left.translation() - expect.translation()).norm(), 0, 1e-12);
    ++n;
    if (n == 5) sim.seek(sim.frame_count() - 2), n = sim.frame_count() - 2;
  }
  EXPECT_EQ(n, sim.frame_count());
  EXPECT_THROW(sim.frame(sim.frame_count()), std::out_of_range);
}

TEST(SimTrajectory, RigMounting) {
  RigConfig rig;
  rig.pitch_deg = 0;
  geometry::SE3 T = body_to_left(rig);
  // Optical axis along body x, image right along body -y, left camera at +b/2 along body y.
  EXPECT_NEAR((T.rotation_matrix().col(2) - Eigen::Vector3d(1, 0, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR((T.rotation_matrix().col(0) - Eigen::Vector3d(0, -1, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR((T.translation() - Eigen::Vector3d(0, 0.06, 0)).norm(), 0, 1e-12);
  rig.pitch_deg = 90;
  T = body_to_left(rig);
  EXPECT_NEAR((T.rotation_matrix().col(2) - Eigen::Vector3d(0, 0, -1)).norm(), 0, 1e-12);
}

}  // namespace
}  // namespace aerie::sim
