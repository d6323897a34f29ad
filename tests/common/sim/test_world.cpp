// World geometry: occupancy, distances and ray casts against hand-placed points; the room
// and the outdoor field (landing object with the helipad on top, sky, sun, rendering).
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <string>

#include "common/sim/sim_config.hpp"
#include "common/sim/simulation.hpp"
#include "common/sim/texture.hpp"
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


// ---- Room: helipad placement from the config ------------------------------------------

TEST(SimWorld, RoomHelipadPlacementOverride) {
  WorldConfig c;
  c.texels_per_metre = 20;
  c.helipad_x = -2.0;
  c.helipad_y = 1.5;
  const World w = World::make(c);
  EXPECT_EQ(w.helipad().center, Eigen::Vector3d(-2.0, 1.5, 0.0));
  EXPECT_EQ(w.landing_object(), nullptr);
  EXPECT_EQ(w.sun_direction(), Eigen::Vector3d::Zero());
  // Obstacles keep clear of the moved pad.
  for (const auto& o : w.obstacles())
    for (const auto& p : w.helipad().corners()) {
      const double dx = std::max({o.box.min.x() - p.x(), 0.0, p.x() - o.box.max.x()});
      const double dy = std::max({o.box.min.y() - p.y(), 0.0, p.y() - o.box.max.y()});
      EXPECT_GE(std::hypot(dx, dy), c.route_clearance - 1e-9);
    }
  // Only helipad_y set: x keeps today's placement.
  WorldConfig d;
  d.texels_per_metre = 20;
  d.helipad_y = -1.0;
  EXPECT_EQ(World::room(d).helipad().center,
            Eigen::Vector3d(test::light_world().helipad().center.x(), -1.0, 0.0));
  c.helipad_x = 5.8;  // the pad would cross the east wall
  try {
    World::room(c);
    FAIL() << "expected an exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("helipad_x"), std::string::npos) << e.what();
  }
}

// ---- Field --------------------------------------------------------------------------------

// A small field with everything placed by hand (fast to build).
WorldConfig small_field_config() {
  WorldConfig c;
  c.kind = "field";
  c.seed = 5;
  c.field_x = 20;
  c.field_y = 16;
  c.field_texels_per_metre = 40;
  c.vehicle_texels_per_metre = 300;
  c.cruise_altitude = 3.0;
  c.helipad_x = 1.0;
  c.helipad_y = -2.0;
  c.helipad_yaw_deg = 30.0;
  c.vehicle_yaw_deg = 90.0;  // length along y
  c.sun_azimuth_deg = 30.0;
  c.sun_elevation_deg = 50.0;
  c.road_width = 0.0;  // plain grass (SunCastsTheCarsShadow compares with the unlit texture)
  return c;
}

const World& small_field() {
  static const World w = World::make(small_field_config());
  return w;
}

// The documented example config (full-size defaults), built once.
const World& example_field() {
  static const World w =
      World::make(load_simulation_config(util::Config::load(AERIE_SOURCE_DIR "/config/sim/field.yaml")).world);
  return w;
}

// Left camera pose of `rig` with the body at p, yawed by yaw.
geometry::SE3 camera_at(const RigConfig& rig, const Eigen::Vector3d& p, double yaw) {
  return geometry::SE3(Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())), p) * body_to_left(rig);
}

// Pixel of a world point in the left image (nullopt behind the camera).
std::optional<cv::Point2d> project(const StereoRenderer& r, const geometry::SE3& T_world_left,
                                   const Eigen::Vector3d& p) {
  const Eigen::Vector3d q = T_world_left.inverse() * p;
  if (q.z() <= 0) return std::nullopt;
  const Intrinsics K = r.intrinsics();
  return cv::Point2d(K.fx * q.x() / q.z() + K.cx, K.fy * q.y() / q.z() + K.cy);
}

TEST(SimField, LandingObjectCarriesTheHelipad) {
  const World& w = small_field();
  ASSERT_NE(w.landing_object(), nullptr);
  const Obstacle& car = *w.landing_object();
  EXPECT_EQ(car.kind, Obstacle::Kind::Vehicle);
  // Length along y (yaw 90), centred under the pad, standing on the ground.
  EXPECT_NEAR((car.box.min - Eigen::Vector3d(0.1, -4.1, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((car.box.max - Eigen::Vector3d(1.9, 0.1, 1.4)).norm(), 0.0, 1e-12);
  EXPECT_EQ(car.box.min.z(), 0.0);
  const Helipad& pad = w.helipad();
  EXPECT_EQ(pad.center, Eigen::Vector3d(1.0, -2.0, 1.4));  // on the top face
  EXPECT_NEAR(pad.yaw, 30.0 * M_PI / 180.0, 1e-12);
  for (const auto& c : pad.corners()) {
    EXPECT_DOUBLE_EQ(c.z(), 1.4);
    EXPECT_TRUE(car.box.contains(c));
  }
  EXPECT_EQ(w.bounds().min, Eigen::Vector3d(-10, -8, 0));
  EXPECT_EQ(w.bounds().max, Eigen::Vector3d(10, 8, 30));
  // The top face has its own, finer texture.
  const int top = 6 + 5;  // the vehicle is obstacle 0; its +z face
  EXPECT_EQ(w.surfaces()[top].axis, 2);
  EXPECT_EQ(w.surfaces()[top].offset, 1.4);
  EXPECT_FLOAT_EQ(w.textures().surfaces[top].texels_per_metre(), 300.f);
  EXPECT_FLOAT_EQ(w.textures().surfaces[4].texels_per_metre(), 40.f);
  // Other obstacles keep 1.5 m from the landing object.
  for (size_t i = 1; i < w.obstacles().size(); ++i) {
    const Aabb& b = w.obstacles()[i].box;
    const double gap = std::max({b.min.x() - car.box.max.x(), car.box.min.x() - b.max.x(),
                                 b.min.y() - car.box.max.y(), car.box.min.y() - b.max.y()});
    EXPECT_GT(gap, 1.5);
  }
}

TEST(SimField, ExactDistancesAndRaycasts) {
  const World& w = small_field();
  // Inside the car: depth to the nearest face (the half height, 0.7 < half width 0.9).
  EXPECT_TRUE(w.occupied({1.0, -2.0, 0.7}));
  EXPECT_NEAR(w.signed_distance({1.0, -2.0, 0.7}), -0.7, 1e-12);
  // Standing on the ground: 5 cm above its bottom face is 5 cm deep.
  EXPECT_NEAR(w.signed_distance({1.0, -2.0, 0.05}), -0.05, 1e-12);
  // 1 m above the pad centre (the sky is 28.6 m higher, other obstacles >= 1.5 m away).
  EXPECT_NEAR(w.signed_distance({1.0, -2.0, 2.4}), 1.0, 1e-12);
  // Beside the car's +x face at 1 m height: 0.25 m from it.
  EXPECT_NEAR(w.signed_distance({2.15, -2.0, 1.0}), 0.25, 1e-12);
  // Above its top edge, diagonally: Euclidean distance to the edge.
  EXPECT_NEAR(w.signed_distance({2.2, -2.0, 1.8}), 0.5, 1e-12);
  // Beside the car near the ground: the ground is nearest.
  EXPECT_NEAR(w.signed_distance({2.4, -2.0, 0.2}), 0.2, 1e-12);
  // The sky is solid too (it is a rendered surface): 1 m above it is 1 m deep.
  EXPECT_NEAR(w.signed_distance({0.0, 0.0, 31.0}), -1.0, 1e-12);

  // Straight down from 2 m above the pad: the top face at z = 1.4.
  const auto down = w.raycast({1.1, -1.9, 3.4}, {0, 0, -1});
  ASSERT_TRUE(down);
  EXPECT_NEAR(down->t, 2.0, 1e-12);
  EXPECT_EQ(down->point, Eigen::Vector3d(1.1, -1.9, 1.4));
  EXPECT_EQ(down->normal, Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(down->surface, 11);
  // From the side at 0.7 m: the +x face.
  const auto side = w.raycast({4.0, -2.5, 0.7}, {-1, 0, 0});
  ASSERT_TRUE(side);
  EXPECT_NEAR(side->t, 2.1, 1e-12);
  EXPECT_EQ(side->normal, Eigen::Vector3d(1, 0, 0));
  // Straight up where nothing stands: the sky's top face; straight down: the ground.
  const auto up = w.raycast({-4.0, 5.0, 2.0}, {0, 0, 1});
  const auto ground = w.raycast({-4.0, 5.0, 2.0}, {0, 0, -1});
  ASSERT_TRUE(up && ground);
  EXPECT_EQ(up->surface, 5);
  EXPECT_NEAR(up->t, 28.0, 1e-12);
  EXPECT_EQ(ground->surface, 4);
  EXPECT_NEAR(ground->t, 2.0, 1e-12);
}

TEST(SimField, SunAndSeededLayout) {
  const World& w = small_field();
  const double el = 50.0 * M_PI / 180.0, az = 30.0 * M_PI / 180.0;
  EXPECT_NEAR((w.sun_direction() - Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az),
                                                   std::sin(el)))
                  .norm(),
              0.0, 1e-12);
  // Unset keys come from the seed: the same seed gives the same field, another seed another.
  WorldConfig a = small_field_config();
  a.helipad_x = a.helipad_y = a.vehicle_yaw_deg = a.sun_azimuth_deg = a.sun_elevation_deg = WorldConfig::kAuto;
  a.field_texels_per_metre = 10;
  a.vehicle_texels_per_metre = 50;
  WorldConfig b = a;
  b.seed = 6;
  const World w1 = World::make(a), w2 = World::make(a), w3 = World::make(b);
  EXPECT_EQ(w1.helipad().center, w2.helipad().center);
  EXPECT_EQ(w1.sun_direction(), w2.sun_direction());
  ASSERT_EQ(w1.obstacles().size(), w2.obstacles().size());
  for (size_t i = 0; i < w1.obstacles().size(); ++i) EXPECT_EQ(w1.obstacles()[i].box.min, w2.obstacles()[i].box.min);
  EXPECT_NE(w1.helipad().center, w3.helipad().center);
  EXPECT_NE(w1.sun_direction(), w3.sun_direction());
  // Seeded defaults: pad in the central half, sun 35-65 deg high, on the car's top.
  for (const World* x : {&w1, &w3}) {
    EXPECT_LE(std::abs(x->helipad().center.x()), 0.25 * a.field_x);
    EXPECT_LE(std::abs(x->helipad().center.y()), 0.25 * a.field_y);
    EXPECT_DOUBLE_EQ(x->helipad().center.z(), a.vehicle_height);
    const double sun_el = std::asin(x->sun_direction().z()) * 180.0 / M_PI;
    EXPECT_GE(sun_el, 35.0 - 1e-9);
    EXPECT_LE(sun_el, 65.0 + 1e-9);
  }
  // Placing the pad by hand leaves the other seeded choices as they were.
  WorldConfig c = a;
  c.helipad_x = -1.0;
  c.helipad_y = 0.5;
  const World w4 = World::make(c);
  EXPECT_EQ(w4.helipad().center, Eigen::Vector3d(-1.0, 0.5, a.vehicle_height));
  EXPECT_EQ(w4.sun_direction(), w1.sun_direction());
  EXPECT_NEAR((w4.landing_object()->box.size() - w1.landing_object()->box.size()).norm(), 0.0, 1e-12);
}

TEST(SimField, SunCastsTheCarsShadow) {
  // Ground texels in the car's shadow are darker than the same ground out of it: compare the
  // baked ground with the unlit texture at a point in the shadow and one in the sun.
  const World& w = small_field();
  const Eigen::Vector3d s = w.sun_direction();
  // The sun (azimuth 30, elevation 50 deg) throws the top's outline 1.17 m towards -x -y:
  // this point, 0.5 m west of the car, is inside that shadow, 0.5 m from its edges.
  const Eigen::Vector3d shadowed(-0.4, -2.0, 0.0);
  ASSERT_GE(w.raycast(shadowed + 1e-6 * Eigen::Vector3d::UnitZ(), s).value().surface, 6);
  ASSERT_FALSE(w.occupied(shadowed + Eigen::Vector3d(0, 0, 0.01)));
  const Surface& g = w.surfaces()[4];
  const cv::Mat baked = w.textures().surfaces[4].level(0);
  const cv::Mat raw = make_texture(Material::Grass, g.u_len, g.v_len, 40, mix_seed(5, 104));
  auto ratio = [&](const Eigen::Vector3d& p) {
    const int u = static_cast<int>((p.x() - g.u0) * 40), v = static_cast<int>((g.v0 - p.y()) * 40);
    double lit = 0, unlit = 0;
    for (int dv = -3; dv <= 3; ++dv)
      for (int du = -3; du <= 3; ++du) {
        lit += baked.at<uint8_t>(v + dv, u + du);
        unlit += raw.at<uint8_t>(v + dv, u + du);
      }
    return lit / unlit;
  };
  // In the sun: ambient 0.4 + 0.7 sin(el) (clamped at 1.05); in the shadow: the ambient only.
  const double sunny_expected = std::min(1.05, 0.4 + 0.7 * s.z());
  const Eigen::Vector3d sunny(-6.0, 6.0, 0.0);
  ASSERT_LT(w.raycast(sunny + 1e-6 * Eigen::Vector3d::UnitZ(), s).value().surface, 6);  // the sky
  ASSERT_FALSE(w.occupied(sunny + Eigen::Vector3d(0, 0, 0.01)));
  EXPECT_NEAR(ratio(shadowed), 0.4, 0.05);
  EXPECT_NEAR(ratio(sunny), sunny_expected, 0.05);
}

TEST(SimField, DownCameraSeesThePadWhereProjectHelipadSays) {
  const World& w = example_field();
  ASSERT_EQ(w.config().kind, "field");
  RigConfig rig = landing_rig();
  rig.color = true;
  const StereoRenderer r(w, rig);
  const Helipad& pad = w.helipad();
  const geometry::SE3 T = camera_at(rig, pad.center + Eigen::Vector3d(0.1, -0.05, 2.0), 0.4);
  const StereoFrame f = r.render(T, 0, 0);
  ASSERT_TRUE(f.target_visible);
  // Corners as the pinhole projection of Helipad::corners() (z = top face).
  const auto corners = pad.corners();
  for (int i = 0; i < 4; ++i) {
    const auto p = project(r, T, corners[i]);
    ASSERT_TRUE(p);
    EXPECT_NEAR(f.target_corners[i].x, p->x, 1e-9);
    EXPECT_NEAR(f.target_corners[i].y, p->y, 1e-9);
  }
  // The marking in the image: dark interior, white H bar and ring, at the predicted pixels.
  cv::Mat gray;
  cv::transform(f.left, gray, cv::Matx13f(0.114f, 0.587f, 0.299f));
  gray.convertTo(gray, CV_8U);
  const double c = std::cos(pad.yaw), s = std::sin(pad.yaw);
  auto pixel = [&](double lx, double ly) {
    const Eigen::Vector3d p = pad.center + pad.size * Eigen::Vector3d(c * lx - s * ly, s * lx + c * ly, 0.0);
    const cv::Point2d q = project(r, T, p).value();
    return static_cast<int>(gray.at<uint8_t>(cvRound(q.y), cvRound(q.x)));
  };
  for (const auto& [lx, ly] : {std::pair{0.0, 0.32}, {0.0, -0.32}, {0.32, 0.0}, {-0.32, 0.0}, {0.3, 0.1}})
    EXPECT_LT(pixel(lx, ly), 90) << "dark interior at " << lx << ", " << ly;
  for (const auto& [lx, ly] : {std::pair{0.0, 0.0}, {0.05, 0.0}, {0.43, 0.0}, {0.0, -0.43}, {0.15, 0.2}})
    EXPECT_GT(pixel(lx, ly), 130) << "white paint at " << lx << ", " << ly;
  // Every pixel whose depth lands on the ground is grass or road (green-tinted: G >= R, B),
  // every pixel inside the projected quad is the pad (on the red car: R > G).
  std::vector<cv::Point2f> quad;
  for (const auto& q : f.target_corners) quad.emplace_back(static_cast<float>(q.x), static_cast<float>(q.y));
  const Intrinsics K = r.intrinsics();
  int ground = 0, inside = 0;
  for (int v = 0; v < f.left.rows; ++v)
    for (int u = 0; u < f.left.cols; ++u) {
      const cv::Vec3b px = f.left.at<cv::Vec3b>(v, u);
      const Eigen::Vector3d d = T.rotation_matrix() * Eigen::Vector3d((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
      const RayHit hit = w.raycast(T.translation(), d).value();
      if (hit.surface == 4) {
        ++ground;
        ASSERT_TRUE(px[1] >= px[0] && px[1] >= px[2]) << u << "," << v;
      }
      if (cv::pointPolygonTest(quad, cv::Point2f(static_cast<float>(u), static_cast<float>(v)), true) > 1.0) {
        ++inside;
        ASSERT_EQ(hit.surface, 11) << u << "," << v;  // the car's top face
        ASSERT_GT(px[2], px[1]) << u << "," << v;
      }
    }
  EXPECT_GT(ground, 1000);
  EXPECT_GT(inside, 2000);  // the 1 m pad from 2 m: ~80 px wide
}

TEST(SimField, ForwardCameraSeesSkyAboveTheHorizon) {
  const World& w = example_field();
  RigConfig rig;  // 20 deg pitch would hide the sky: look level
  rig.pitch_deg = 0.0;
  const StereoRenderer r(w, rig);
  const Eigen::Vector3d eye(w.route().home.x(), w.route().home.y(), 2.0);
  const geometry::SE3 T = camera_at(rig, eye, 0.0);  // facing east, across the field
  const StereoFrame f = r.render(T, 0, 0);
  const Intrinsics K = r.intrinsics();
  // Classify each pixel by the surface its ray hits.
  int sky = 0, top_rows = 0, ground_bottom = 0, bottom_rows = 0, depth_errors = 0;
  for (int v = 0; v < K.height; ++v)
    for (int u = 0; u < K.width; ++u) {
      const Eigen::Vector3d d = T.rotation_matrix() * Eigen::Vector3d((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
      const auto hit = w.raycast(T.translation(), d).value();
      depth_errors += std::abs(f.depth.at<float>(v, u) - hit.t) > 1e-3 * hit.t;
      const int value = f.left.at<uint8_t>(v, u);
      if (v < K.height / 4) {
        ++top_rows;
        // Sky: a side face above the treeline (<= 5 m) or the top face; bright, nearly uniform.
        if ((hit.surface < 4 && hit.point.z() > 5.0) || hit.surface == 5) {
          ++sky;
          EXPECT_GE(value, 205);
          EXPECT_LE(value, 230);
        }
      }
      if (v >= 3 * K.height / 4) {
        ++bottom_rows;
        if (hit.surface == 4) {
          ++ground_bottom;
          EXPECT_LT(value, 160);  // grass and road are darker than the sky
        }
      }
    }
  EXPECT_EQ(depth_errors, 0);
  EXPECT_GT(sky, 0.8 * top_rows);
  EXPECT_GT(ground_bottom, 0.8 * bottom_rows);
}

TEST(SimField, HelipadOnTheCarIsHiddenFromBelowItsTop) {
  const World& w = small_field();
  RigConfig rig;
  rig.pitch_deg = 0.0;
  const StereoRenderer r(w, rig);
  const Eigen::Vector3d pc = w.helipad().center;
  // 4 m west of the car at 1 m height (below the top face at 1.4 m), looking east at it: the
  // corners are in front and inside the image but the car's side hides them.
  ASSERT_FALSE(w.occupied(Eigen::Vector3d(pc.x() - 4.0, pc.y(), 1.0)));
  StereoFrame low;
  r.project_helipad(camera_at(rig, Eigen::Vector3d(pc.x() - 4.0, pc.y(), 1.0), 0.0), low);
  for (const auto& q : low.target_corners) {
    EXPECT_GT(q.x, 0);
    EXPECT_LT(q.x, rig.width - 1);
    EXPECT_GT(q.y, 0);
    EXPECT_LT(q.y, rig.height - 1);
  }
  EXPECT_FALSE(low.target_visible);
  // From 3.5 m height, pitched down 35 deg: visible.
  rig.pitch_deg = 35.0;
  const StereoRenderer r2(w, rig);
  StereoFrame high;
  r2.project_helipad(camera_at(rig, Eigen::Vector3d(pc.x() - 4.0, pc.y(), 3.5), 0.0), high);
  EXPECT_TRUE(high.target_visible);
}

TEST(SimField, SameSeedSameBytes) {
  WorldConfig c = small_field_config();
  c.field_texels_per_metre = 20;
  const World w1 = World::make(c), w2 = World::make(c);
  c.seed = 9;
  const World w3 = World::make(c);
  RigConfig rig = landing_rig();
  rig.pitch_deg = 60.0;
  rig.noise_sigma = 1.0;
  const geometry::SE3 T = camera_at(rig, w1.helipad().center + Eigen::Vector3d(-2.5, 0.3, 2.0), 0.1);
  const StereoFrame a = StereoRenderer(w1, rig).render(T, 5, 3), b = StereoRenderer(w2, rig).render(T, 5, 3);
  const StereoFrame d = StereoRenderer(w3, rig).render(T, 5, 3);
  EXPECT_EQ(cv::norm(a.left, b.left, cv::NORM_L1), 0.0);
  EXPECT_EQ(cv::norm(a.right, b.right, cv::NORM_L1), 0.0);
  EXPECT_GT(cv::norm(a.left, d.left, cv::NORM_L1), 0.0);
}

TEST(SimField, ExampleConfigKeepsTextureMemorySane) {
  const World& w = example_field();
  EXPECT_DOUBLE_EQ(w.config().field_x, 30.0);
  size_t bytes = 0;
  for (const auto& t : w.textures().surfaces)
    for (int k = 0; k < t.levels(); ++k) bytes += t.level(k).total();
  EXPECT_LT(bytes, 100u << 20);
  // The pad's texels are <= 2.5 mm: finer than a 376 px, 98 deg camera's pixel at 0.7 m.
  const auto& top = w.textures().surfaces[6 + 6 * 0 + 5];
  EXPECT_LT(1.0 / top.texels_per_metre(), 0.7 * 2 * std::tan(49.0 * M_PI / 180.0) / 376);
}

TEST(SimField, RejectsBadConfigsNamingTheKey) {
  auto expect_error = [](WorldConfig c, const std::string& key) {
    try {
      World::make(c);
      FAIL() << "no error for " << key;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  const WorldConfig ok = small_field_config();
  WorldConfig c = ok;
  c.vehicle_yaw_deg = 45;
  expect_error(c, "vehicle_yaw_deg");
  c = ok;
  c.field_x = c.field_y = 100;
  c.field_texels_per_metre = 200;  // 400 Mtexels of ground
  expect_error(c, "field_texels_per_metre");
  c = ok;
  c.helipad_size = 1.7;  // rotated by 30 deg it overhangs the 1.8 m wide top
  expect_error(c, "helipad_size");
  c = ok;
  c.cruise_altitude = 1.5;  // skims the 1.4 m car
  expect_error(c, "cruise_altitude");
  c = ok;
  c.helipad_x = 9.0;  // the car would stick out of the field
  expect_error(c, "helipad_x");
  c = ok;
  c.sun_elevation_deg = 5;
  expect_error(c, "sun_elevation_deg");
  c = ok;
  c.road_width = -1;
  expect_error(c, "road_width");
  c = ok;
  c.vehicle_height = 0;
  expect_error(c, "vehicle_height");
  c = ok;
  c.kind = "forest";
  expect_error(c, "kind");
  c = ok;
  EXPECT_THROW(World::room(c), std::invalid_argument);  // a field config is not a room
  // From YAML: the new keys are read, unknown ones and bad kinds rejected with the key named.
  const WorldConfig y = load_world_config(util::Config::parse(
      "{kind: field, field_x: 18, vehicle_length: 3.5, vehicle_yaw_deg: 180, helipad_x: 1.5, sun_azimuth_deg: 10}"));
  EXPECT_EQ(y.kind, "field");
  EXPECT_DOUBLE_EQ(y.field_x, 18.0);
  EXPECT_DOUBLE_EQ(y.vehicle_length, 3.5);
  EXPECT_DOUBLE_EQ(y.vehicle_yaw_deg, 180.0);
  EXPECT_DOUBLE_EQ(y.helipad_x, 1.5);
  EXPECT_TRUE(std::isnan(y.helipad_y));
  EXPECT_DOUBLE_EQ(y.sun_azimuth_deg, 10.0);
  for (const auto& [yaml, key] : {std::pair<std::string, std::string>{"{vehicle_colour: red}", "vehicle_colour"},
                                  {"{kind: forest}", "kind"}}) {
    try {
      load_world_config(util::Config::parse(yaml, "w.yaml"));
      FAIL() << "no error for " << yaml;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("w.yaml"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace aerie::sim
