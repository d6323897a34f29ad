// World geometry: occupancy, distances and ray casts against hand-placed points.
#include <gtest/gtest.h>

#include <cmath>

#include "common/sim/trajectory.hpp"
#include "common/sim/world.hpp"
#include "tests/common/sim/sim_fixtures.hpp"

namespace aerie::sim {
namespace {

World empty_room() {
  WorldConfig c;
  c.n_obstacles = 0;
  c.texels_per_metre = 20;
  return World::room(c);
}

TEST(SimWorld, EmptyRoomDistancesAndOccupancy) {
  const World w = empty_room();
  EXPECT_EQ(w.bounds().min, Eigen::Vector3d(-6, -5, 0));
  EXPECT_EQ(w.bounds().max, Eigen::Vector3d(6, 5, 4));
  // Room centre at 2 m: 2 m from floor and ceiling.
  EXPECT_DOUBLE_EQ(w.distance({0, 0, 2}), 2.0);
  EXPECT_DOUBLE_EQ(w.distance({5.5, 0, 2}), 0.5);   // east wall
  EXPECT_DOUBLE_EQ(w.distance({0, -4.75, 1}), 0.25);  // south wall
  EXPECT_DOUBLE_EQ(w.distance({1, 1, 0.1}), 0.1);   // floor
  EXPECT_FALSE(w.occupied({0, 0, 2}));
  // Beyond the walls is solid.
  EXPECT_TRUE(w.occupied({7, 0, 1}));
  EXPECT_DOUBLE_EQ(w.distance({7, 0, 1}), 1.0);
  EXPECT_DOUBLE_EQ(w.signed_distance({7, 0, 1}), -1.0);
  EXPECT_TRUE(w.occupied({0, 0, -0.5}));
  EXPECT_NEAR(w.distance({7, 6, 1}), std::sqrt(2.0), 1e-12);
}

TEST(SimWorld, RaycastHitsWallsExactly) {
  const World w = empty_room();
  const auto hit = w.raycast({0, 0, 1}, {1, 0, 0});
  ASSERT_TRUE(hit);
  EXPECT_DOUBLE_EQ(hit->t, 6.0);
  EXPECT_EQ(hit->normal, Eigen::Vector3d(-1, 0, 0));  // east wall faces west, into the room
  const auto down = w.raycast({1, 2, 3}, {0.5, 0, -1});
  ASSERT_TRUE(down);
  EXPECT_DOUBLE_EQ(down->t, 3.0);
  EXPECT_NEAR((down->point - Eigen::Vector3d(2.5, 2, 0)).norm(), 0, 1e-12);
  EXPECT_EQ(w.surfaces()[down->surface].axis, 2);
  EXPECT_FALSE(w.raycast({0, 0, 1}, {1, 0, 0}, 5.0));  // beyond max_t
  EXPECT_THROW(w.raycast({0, 0, 1}, {0, 0, 0}), std::invalid_argument);
}

TEST(SimWorld, ObstaclesAreSolidWithExactDistances) {
  const World& w = test::light_world();
  ASSERT_EQ(w.obstacles().size(), 6u);
  for (const auto& o : w.obstacles()) {
    const Aabb& b = o.box;
    EXPECT_TRUE(w.bounds().contains(b.min) && w.bounds().contains(b.max));
    EXPECT_EQ(b.min.z(), 0.0);  // standing on the floor
    EXPECT_TRUE(w.occupied(b.center()));
    const double half_min = 0.5 * b.size().minCoeff();
    EXPECT_NEAR(w.signed_distance(b.center()), -half_min, 1e-12);
    // 5 cm in front of the middle of a side face, at 0.3 m height: the face is nearest
    // unless a wall is closer.
    Eigen::Vector3d p(b.max.x() + 0.05, b.center().y(), std::min(0.3, 0.5 * b.max.z()));
    if (p.x() < w.bounds().max.x() - 0.1) {
      EXPECT_FALSE(w.occupied(p));
      EXPECT_NEAR(w.distance(p), 0.05, 1e-12);
      // Ray from 0.25 m in front of the face (obstacles keep 0.3 m apart) hits it at t = 0.25.
      const Eigen::Vector3d from(b.max.x() + 0.25, p.y(), p.z());
      if (w.bounds().contains(from) && !w.occupied(from)) {
        const auto hit = w.raycast(from, {-1, 0, 0});
        ASSERT_TRUE(hit);
        EXPECT_NEAR(hit->t, 0.25, 1e-12);
        EXPECT_EQ(hit->normal, Eigen::Vector3d(1, 0, 0));
      }
    }
  }
}

TEST(SimWorld, RouteIsClearOfObstacles) {
  const World& w = test::light_world();
  const Trajectory demo = Trajectory::demo_flight(w);
  for (double t = 0; t <= demo.duration(); t += 0.05) {
    const Eigen::Vector3d p = demo.pose(t).translation();
    ASSERT_FALSE(w.occupied(p)) << "t=" << t;
    // Horizontally clear of every obstacle by the configured clearance.
    for (const auto& o : w.obstacles()) {
      const double dx = std::max({o.box.min.x() - p.x(), 0.0, p.x() - o.box.max.x()});
      const double dy = std::max({o.box.min.y() - p.y(), 0.0, p.y() - o.box.max.y()});
      ASSERT_GE(std::hypot(dx, dy), w.config().route_clearance - 1e-9) << "t=" << t;
    }
  }
}

TEST(SimWorld, HelipadGeometry) {
  const World& w = test::light_world();
  const Helipad& pad = w.helipad();
  EXPECT_DOUBLE_EQ(pad.size, 1.0);
  const auto c = pad.corners();
  for (int i = 0; i < 4; ++i) {
    EXPECT_DOUBLE_EQ(c[i].z(), 0.0);
    EXPECT_NEAR((c[i] - c[(i + 1) % 4]).norm(), 1.0, 1e-12);
    EXPECT_NEAR((c[i] - pad.center).norm(), std::sqrt(0.5), 1e-12);
  }
  // Counter-clockwise seen from above.
  EXPECT_GT((c[1] - c[0]).cross(c[2] - c[1]).z(), 0.0);
}

TEST(SimWorld, LayoutDependsOnTheSeedOnly) {
  WorldConfig a;
  a.texels_per_metre = 20;
  WorldConfig b = a;
  b.seed = 2;
  const World w1 = World::room(a), w2 = World::room(a), w3 = World::room(b);
  ASSERT_EQ(w1.obstacles().size(), w2.obstacles().size());
  for (size_t i = 0; i < w1.obstacles().size(); ++i) {
    EXPECT_EQ(w1.obstacles()[i].box.min, w2.obstacles()[i].box.min);
    EXPECT_EQ(w1.obstacles()[i].box.max, w2.obstacles()[i].box.max);
  }
  EXPECT_NE(w1.obstacles()[0].box.min, w3.obstacles()[0].box.min);
}

TEST(SimWorld, RejectsBadConfigs) {
  WorldConfig c;
  c.room_x = 2;
  EXPECT_THROW(World::room(c), std::invalid_argument);
  c = {};
  c.n_obstacles = 500;  // cannot fit clear of the route
  c.texels_per_metre = 20;
  try {
    World::room(c);
    FAIL() << "expected an exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("n_obstacles"), std::string::npos) << e.what();
  }
  c = {};
  c.cruise_altitude = 3.9;
  EXPECT_THROW(World::room(c), std::invalid_argument);
}

}  // namespace
}  // namespace aerie::sim
