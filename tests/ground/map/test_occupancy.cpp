// The robust occupancy update, queries, persistence and the distance map (ground/map).
#include <gtest/gtest.h>

#include <sstream>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include <random>

#include "ground/map/distance_map.hpp"
#include "ground/map/key_ray.hpp"
#include "ground/map/occupancy.hpp"
#include "tests/ground/map/room_fixture.hpp"
#include "tests/support/test_support.hpp"

namespace m = aerie::map;
using Eigen::Vector3d;
using Eigen::Vector3f;

namespace {

// Exact sensor model (no stereo error) so that the probabilities are the textbook ones.
m::OccupancyParams exact_params() {
  m::OccupancyParams p;
  p.resolution = 0.1;
  p.stereo.disparity_sigma_px = 0;
  return p;
}

double prob(const m::OccupancyMap& map, const Vector3d& p) { return map.occupancy(p).probability; }

// Centre of the voxel (i, j, k) of a 0.1 m map: voxels are [0.1 i, 0.1 (i + 1)).
Vector3d voxel(int i, int j, int k) { return {0.1 * i + 0.05, 0.1 * j + 0.05, 0.1 * k + 0.05}; }

const aerie::spherical::Intrinsics kCam{260.0, 260.0, 187.5, 119.5, 0.12};
const cv::Size kSize(376, 240);

}  // namespace

TEST(Occupancy, OccupiedWinsOverFreeAndEachVoxelOncePerFrame) {
  m::OccupancyMap map(exact_params());
  const Vector3f origin(0.05f, 0.05f, 0.05f);
  // Ray A ends in voxel (20,0,0); ray B passes through it to (40,0,0); five more points
  // land in voxel (20,0,0) and three rays pass through voxel (10,0,0).
  std::vector<Vector3f> pts{{2.05f, 0.05f, 0.05f}, {4.05f, 0.05f, 0.05f}};
  for (int i = 0; i < 5; ++i) pts.emplace_back(2.01f + 0.015f * i, 0.06f, 0.04f);
  const auto stats = map.insert_frame(pts, origin);
  EXPECT_EQ(stats.points, 7u);
  EXPECT_EQ(stats.rays, 2u);        // one per end voxel
  EXPECT_EQ(stats.hit_voxels, 2u);
  EXPECT_NEAR(prob(map, voxel(20, 0, 0)), 0.7, 1e-6);  // hit once, although also on ray B's free path
  EXPECT_NEAR(prob(map, voxel(40, 0, 0)), 0.7, 1e-6);
  EXPECT_NEAR(prob(map, voxel(10, 0, 0)), 0.4, 1e-6);  // free once, although on both rays
  EXPECT_NEAR(prob(map, voxel(30, 0, 0)), 0.4, 1e-6);
  EXPECT_EQ(map.occupancy(voxel(20, 0, 0)).state, m::Occupancy::Occupied);
  EXPECT_EQ(map.occupancy(voxel(30, 0, 0)).state, m::Occupancy::Free);
  EXPECT_EQ(map.occupancy(voxel(41, 0, 0)).state, m::Occupancy::Unknown);
  EXPECT_EQ(map.occupancy(voxel(20, 1, 0)).state, m::Occupancy::Unknown);
}

TEST(Occupancy, ClampingBounds) {
  auto params = exact_params();
  params.visibility_if_occluded = 1.0;  // plain misses
  m::OccupancyMap map(params);
  const Vector3f origin(0.05f, 0.05f, 0.05f);
  for (int i = 0; i < 30; ++i) map.insert_frame({{2.05f, 0.05f, 0.05f}}, origin);
  EXPECT_NEAR(prob(map, voxel(20, 0, 0)), 0.97, 1e-5);  // clamping max
  EXPECT_NEAR(prob(map, voxel(10, 0, 0)), 0.12, 1e-5);  // clamping min
  // The occupied voxel is now seen free 30 times: it goes down to the lower bound, not below.
  for (int i = 0; i < 30; ++i) map.insert_frame({{4.05f, 0.05f, 0.05f}}, origin);
  EXPECT_NEAR(prob(map, voxel(20, 0, 0)), 0.12, 1e-5);
  EXPECT_NEAR(prob(map, voxel(40, 0, 0)), 0.97, 1e-5);
}

TEST(Occupancy, MissOnAnOccludedVoxelCountsLess) {
  // Voxel V = (20,0,0) believed occupied; the ray towards (40,0,0) crosses N = (19,0,0)
  // first. With N occupied, V is probably occluded (S&Z visibility): its miss is weak.
  auto run = [](bool neighbour_occupied) {
    m::OccupancyMap map(exact_params());
    auto& tree = map.tree();
    const float l_max = static_cast<float>(std::log(0.97 / 0.03)), l_min = static_cast<float>(std::log(0.12 / 0.88));
    tree.setNodeValue(voxel(20, 0, 0).x(), 0.05, 0.05, l_max);
    tree.setNodeValue(voxel(19, 0, 0).x(), 0.05, 0.05, neighbour_occupied ? l_max : l_min);
    tree.setNodeValue(voxel(18, 0, 0).x(), 0.05, 0.05, l_min);
    map.insert_frame({{4.05f, 0.05f, 0.05f}}, {0.05f, 0.05f, 0.05f});
    return prob(map, voxel(20, 0, 0));
  };
  const double p_visible = run(false);
  const double p_occluded = run(true);
  // Free neighbour: the plain miss, logit(0.97) + logit(0.4).
  EXPECT_NEAR(p_visible, 1.0 / (1.0 + std::exp(-(std::log(0.97 / 0.03) + std::log(0.4 / 0.6)))), 1e-4);
  EXPECT_GT(p_occluded, p_visible + 0.005);
  EXPECT_LT(p_occluded, 0.97);
}

TEST(Occupancy, StereoErrorModelWeightsFarHitsAndKeepsFreeSpaceOffTheSurface) {
  m::OccupancyParams params;
  params.stereo.focal_px = 260;
  params.stereo.baseline_m = 0.12;
  params.stereo.disparity_sigma_px = 0.5;
  params.stereo.free_margin_sigmas = 2.0;
  m::OccupancyMap map(params);
  const Vector3f origin(0.05f, 0.05f, 0.05f);
  map.insert_frame({{1.05f, 0.05f, 0.05f}, {0.05f, 4.05f, 0.05f}}, origin);
  const double near = prob(map, {1.05, 0.05, 0.05}), far = prob(map, {0.05, 4.05, 0.05});
  EXPECT_GT(near, 0.69);  // sigma_r(1 m) = 1.6 cm << 10 cm: nearly a full hit
  EXPECT_GT(far, 0.5);
  EXPECT_LT(far, 0.56);   // sigma_r(4 m) = 26 cm: a weak hit
  // Free space stops 2 sigma_r (~0.5 m) before the far hit: those voxels stay unknown.
  EXPECT_EQ(map.occupancy({0.05, 3.85, 0.05}).state, m::Occupancy::Unknown);
  EXPECT_EQ(map.occupancy({0.05, 3.25, 0.05}).state, m::Occupancy::Free);
  EXPECT_EQ(map.occupancy({0.95, 0.05, 0.05}).state, m::Occupancy::Free);
}

TEST(Occupancy, RangeAndHeightLimits) {
  auto params = exact_params();
  params.sensor_model.max_range = 3.0;
  params.pointcloud_min_z = -0.5;
  params.pointcloud_max_z = 1.0;
  m::OccupancyMap map(params);
  const auto stats = map.insert_frame({{5.05f, 0.05f, 0.05f}, {1.05f, 0.05f, 1.55f}, {1.05f, 0.05f, -0.95f}},
                                      {0.05f, 0.05f, 0.05f});
  EXPECT_EQ(stats.beyond_range, 1u);
  EXPECT_EQ(stats.outside_z, 2u);
  EXPECT_EQ(stats.hit_voxels, 0u);
  EXPECT_EQ(map.occupancy(voxel(50, 0, 0)).state, m::Occupancy::Unknown);  // beyond max_range: no hit
  EXPECT_EQ(map.occupancy(voxel(29, 0, 0)).state, m::Occupancy::Free);     // but free space up to it
  EXPECT_EQ(map.occupancy(voxel(31, 0, 0)).state, m::Occupancy::Unknown);
}

TEST(Occupancy, BadInputsAreCountedOrRejected) {
  m::OccupancyMap map(exact_params());
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const auto stats = map.insert_frame({{nan, 0.f, 0.f}, {1.f, std::numeric_limits<float>::infinity(), 0.f},
                                       {1.05f, 0.05f, 0.05f}},
                                      {0.05f, 0.05f, 0.05f});
  EXPECT_EQ(stats.nonfinite, 2u);
  EXPECT_EQ(stats.hit_voxels, 1u);
  try {
    map.insert_frame({{1.f, 0.f, 0.f}}, {nan, 0.f, 0.f});
    FAIL() << "NaN origin accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sensor origin"), std::string::npos) << e.what();
  }
  EXPECT_THROW(map.insert_frame({{1.f, 0.f, 0.f}}, {1e5f, 0.f, 0.f}), std::invalid_argument);  // outside the key range
  auto bad = exact_params();
  bad.sensor_model.hit = 0.4;
  try {
    m::OccupancyMap bad_map(bad);
    FAIL() << "hit 0.4 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sensor_model/hit"), std::string::npos) << e.what();
  }
}

TEST(Occupancy, MultiResolutionQueriesAndRays) {
  m::OccupancyMap map(exact_params());
  map.insert_frame({{2.05f, 0.05f, 0.05f}}, {0.05f, 0.05f, 0.05f});
  // Depth 15 = 0.2 m cells, depth 13 = 0.8 m: an inner node holds the max of its children.
  const auto coarse = map.occupancy({2.15, 0.15, 0.15}, 15);
  EXPECT_NEAR(coarse.voxel_size, 0.2, 1e-9);
  EXPECT_EQ(coarse.state, m::Occupancy::Occupied);
  EXPECT_NEAR(coarse.probability, 0.7, 1e-6);
  EXPECT_EQ(map.occupancy({1.0, 0.5, 0.5}, 13).state, m::Occupancy::Free);  // cell [0.8, 1.6) x [0, 0.8)^2
  EXPECT_EQ(map.occupancy({2.15, 0.15, 0.15}).state, m::Occupancy::Unknown);
  const auto ray = map.cast_ray({0.05, 0.05, 0.05}, {1.0, 0.0, 0.0}, 5.0);
  ASSERT_TRUE(ray.hit);
  EXPECT_NEAR(ray.distance, 1.95, 1e-9);  // enters the voxel [2.0, 2.1)
  EXPECT_NEAR(ray.hit_center.x(), 2.05, 1e-6);  // OctoMap's keyToCoord is float: 2.0499999523 at -O1
  EXPECT_FALSE(ray.crossed_unknown);
  const auto miss = map.cast_ray({0.05, 0.05, 0.05}, {0.0, 1.0, 0.0}, 1.0);
  EXPECT_FALSE(miss.hit);
  EXPECT_TRUE(miss.crossed_unknown);
  const auto coarse_ray = map.cast_ray({0.05, 0.05, 0.05}, {1.0, 0.0, 0.0}, 5.0, 14);  // 0.4 m cells
  ASSERT_TRUE(coarse_ray.hit);
  EXPECT_NEAR(coarse_ray.distance, 1.95, 1e-9);  // the 0.4 m cell [2.0, 2.4) holds the hit
  EXPECT_THROW(map.occupancy({0, 0, 0}, 17), std::invalid_argument);
}

TEST(Occupancy, ChangedRegionCoversTheFrame) {
  m::OccupancyMap map(exact_params());
  EXPECT_FALSE(map.take_changed_region().has_value());
  map.insert_frame({{2.05f, 0.05f, 0.05f}}, {0.05f, 0.05f, 0.05f});
  const auto r = map.take_changed_region();
  ASSERT_TRUE(r.has_value());
  EXPECT_NEAR(r->min.x(), 0.0, 1e-9);
  EXPECT_NEAR(r->max.x(), 2.1, 1e-9);
  EXPECT_FALSE(map.take_changed_region().has_value());
  map.insert_frame({{2.05f, 0.05f, 0.05f}}, {0.05f, 0.05f, 0.05f});  // no state change
  EXPECT_FALSE(map.take_changed_region().has_value());
}

// Skipping free space in bricks already clamped free is exact: over a flight that revisits
// the same space (so that bricks saturate), the map is identical, leaf for leaf, and the
// shortcut did skip updates.
TEST(Occupancy, SkippingClampedFreeBricksLeavesTheMapUnchanged) {
  const m::test::Room room;
  m::OccupancyParams exact, fast;
  exact.skip_clamped_free = false;
  m::OccupancyMap reference(exact), map(fast);
  const aerie::spherical::SphericalEncoder encoder(kCam, kSize);
  size_t reference_updates = 0, updates = 0;
  for (int i = 0; i < 48; ++i) {  // six headings, eight times each
    const auto T = m::test::camera_pose({-1.0, 0.0, 1.2}, (i % 6) * M_PI / 6);
    const auto depth = encoder.encode_depth(m::test::render_depth(room, T, kCam, kSize));
    const auto a = reference.insert_depth(depth, T);
    const auto b = map.insert_depth(depth, T);
    reference_updates += a.free_voxels;
    updates += b.free_voxels;
    EXPECT_EQ(a.hit_voxels, b.hit_voxels);
    EXPECT_EQ(a.state_changes, b.state_changes);
  }
  EXPECT_LT(updates, reference_updates * 3 / 4) << "clamped free bricks were not skipped";
  std::ostringstream a, b;
  reference.tree().writeBinaryConst(a);
  map.tree().writeBinaryConst(b);
  EXPECT_EQ(reference.tree().size(), map.tree().size());
  EXPECT_TRUE(a.str() == b.str()) << "the maps differ";
  // writeBinary stores occupied/free only: the log-odds must agree too.
  auto it = map.tree().begin_leafs();
  for (auto ref = reference.tree().begin_leafs(); ref != reference.tree().end_leafs(); ++ref, ++it) {
    ASSERT_EQ(ref.getKey(), it.getKey());
    ASSERT_EQ(ref->getLogOdds(), it->getLogOdds());
  }
}

TEST(Occupancy, SimulatedRoomIsReconstructedWithinOneVoxel) {
  const m::test::Room room;
  m::OccupancyParams params;  // defaults: 0.1 m, 5 m, stereo model of the demo camera
  m::OccupancyMap map(params);
  const aerie::spherical::SphericalEncoder encoder(kCam, kSize);
  // A turn on the spot at two heights and a pass along the room.
  std::vector<aerie::geometry::SE3> poses;
  for (int i = 0; i < 12; ++i) poses.push_back(m::test::camera_pose({-1.0, 0.0, 1.2}, i * M_PI / 6));
  for (int i = 0; i < 12; ++i) poses.push_back(m::test::camera_pose({-0.5, 1.2, 1.8}, i * M_PI / 6 + 0.2, 0.3));
  for (const auto& T : poses) {
    const auto depth = encoder.encode_depth(m::test::render_depth(room, T, kCam, kSize));
    map.insert_depth(depth, T);
  }
  // Every occupied voxel lies within one voxel of a surface of the room.
  size_t occupied = 0, far_from_surface = 0;
  const auto& tree = map.tree();
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    const double half = 0.5 * it.getSize();
    const Vector3d c(it.getX(), it.getY(), it.getZ());
    ++occupied;
    if (room.surface_distance(c) > params.resolution + half) ++far_from_surface;
  }
  EXPECT_GT(occupied, 2000u);
  EXPECT_EQ(far_from_surface, 0u);
  // The surfaces in view are there: points of the walls and the box faces within 4 m are
  // occupied within one voxel; the room's inside is free.
  const Vector3d wall_points[] = {{-3.0, 0.3, 1.0}, {-1.0, 2.5, 1.5}, {-1.0, -2.5, 0.7}, {0.8, 0.0, 0.8}, {-2.5, -1.0, 0.0}};
  for (const auto& p : wall_points) {
    bool found = false;
    for (double dx = -0.1; dx <= 0.1 && !found; dx += 0.1)
      for (double dy = -0.1; dy <= 0.1 && !found; dy += 0.1)
        for (double dz = -0.1; dz <= 0.1 && !found; dz += 0.1)
          found = map.occupancy(p + Vector3d(dx, dy, dz)).state == m::Occupancy::Occupied;
    EXPECT_TRUE(found) << "surface point " << p.transpose() << " not mapped";
  }
  EXPECT_EQ(map.occupancy({-1.0, 0.0, 1.0}).state, m::Occupancy::Free);
  EXPECT_EQ(map.occupancy({-2.0, -1.0, 1.5}).state, m::Occupancy::Free);

  // Distance map: from the camera position the nearest surface is the floor/wall geometry.
  m::DistanceMap distances(2.0);
  distances.update(map);
  for (const Vector3d& p : {Vector3d(-2.4, 0.0, 1.2), Vector3d(-1.0, 1.9, 1.5), Vector3d(0.3, -0.1, 0.6)}) {
    const auto n = distances.nearest(p);
    const double truth = room.surface_distance(p);
    if (truth < 1.8) {
      ASSERT_GE(n.distance, 0) << p.transpose();
      EXPECT_NEAR(n.distance, truth, 2.5 * params.resolution) << p.transpose();
      EXPECT_LT(room.surface_distance(n.obstacle), 1.5 * params.resolution);
    }
  }
}

TEST(DistanceMap, IncrementalUpdateSeesNewObstacles) {
  m::OccupancyMap map(exact_params());
  const Vector3f origin(0.05f, 0.05f, 0.05f);
  map.insert_frame({{3.05f, 0.05f, 0.05f}}, origin);
  m::DistanceMap distances(2.0);
  distances.update(map);
  EXPECT_LT(distances.nearest({0.55, 0.05, 0.05}).distance, 0);  // 2.5 m > max_distance: none
  EXPECT_NEAR(distances.nearest({1.05, 0.05, 0.05}).distance, 2.0, 1e-6);
  EXPECT_NEAR(distances.nearest({2.55, 0.05, 0.05}).distance, 0.5, 1e-6);
  // Far outside the grid: none, without OctoMap's key arithmetic (overflowed an int at 2e8 m).
  EXPECT_LT(distances.nearest({-2.1e9, 0.05, 0.05}).distance, 0);
  EXPECT_LT(distances.nearest({0.05, 0.05, 1e30}).distance, 0);
  EXPECT_LT(distances.nearest({6.2, 0.05, 0.05}).distance, 0);  // just outside the grid (3.05 + 3 m)
  map.insert_frame({{1.55f, 0.05f, 0.05f}}, origin);
  distances.update(map);
  EXPECT_EQ(distances.rebuilds(), 1u);  // incremental
  const auto n = distances.nearest({1.05, 0.05, 0.05});
  EXPECT_NEAR(n.distance, 0.5, 1e-6);
  EXPECT_NEAR(n.obstacle.x(), 1.55, 1e-6);
  map.clear();
  distances.update(map);
  EXPECT_LT(distances.nearest({1.05, 0.05, 0.05}).distance, 0);
}

TEST(Occupancy, SaveLoadRoundTrip) {
  m::OccupancyMap map(exact_params());
  const Vector3f origin(0.05f, 0.05f, 0.05f);
  for (int i = 0; i < 3; ++i) map.insert_frame({{2.05f, 0.05f, 0.05f}, {1.05f, 1.55f, 0.35f}}, origin);
  const auto dir = aerie::test::scratch_dir("maps");
  for (const std::string ext : {".bt", ".ot"}) {
    const std::string path = (dir / ("map" + ext)).string();
    map.save(path);
    ASSERT_TRUE(std::filesystem::exists(path));
    EXPECT_FALSE(std::filesystem::exists(path + ".part"));
    auto other_params = exact_params();
    other_params.resolution = 0.25;  // replaced by the file's
    m::OccupancyMap loaded(other_params);
    loaded.load(path);
    EXPECT_DOUBLE_EQ(loaded.params().resolution, 0.1);
    size_t leaves = 0;
    for (auto it = map.tree().begin_leafs(), end = map.tree().end_leafs(); it != end; ++it, ++leaves) {
      const Vector3d c(it.getX(), it.getY(), it.getZ());
      const auto q = loaded.occupancy(c);
      ASSERT_EQ(q.state == m::Occupancy::Occupied, map.tree().isNodeOccupied(*it)) << ext << " " << c.transpose();
      if (ext == ".ot") {
        ASSERT_NEAR(q.probability, it->getOccupancy(), 1e-6);  // .bt keeps only the state
      }
    }
    EXPECT_GT(leaves, 10u);
    // The loaded map goes on mapping.
    loaded.insert_frame({{0.05f, 2.05f, 0.05f}}, origin);
    EXPECT_EQ(loaded.occupancy({0.05, 2.05, 0.05}).state, m::Occupancy::Occupied);
  }
  EXPECT_THROW(map.save((dir / "map.txt").string()), std::runtime_error);
  try {
    map.load((dir / "missing.bt").string());
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.bt"), std::string::npos);
  }
  std::ofstream(dir / "junk.bt") << "not a map";
  EXPECT_THROW(map.load((dir / "junk.bt").string()), std::runtime_error);
}

TEST(KeyRay, SameVoxelsAsOctoMapComputeRayKeys) {
  octomap::OcTree tree(0.1);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-6.0, 6.0);
  size_t rays = 0, differing = 0;
  for (int i = 0; i < 500; ++i) {
    const Vector3d o(u(rng) * 0.3, u(rng) * 0.3, u(rng) * 0.3), e(u(rng), u(rng), u(rng));
    octomap::KeyRay reference;
    ASSERT_TRUE(tree.computeRayKeys(octomap::point3d(o.x(), o.y(), o.z()), octomap::point3d(e.x(), e.y(), e.z()), reference));
    octomap::OcTreeKey end_key = tree.coordToKey(e.x(), e.y(), e.z());
    std::vector<octomap::OcTreeKey> ours;
    const double length = (e - o).norm();
    m::traverse_keys(o, (e - o) / length, length, 0.1, 0, [&](const octomap::OcTreeKey& k, double, double) {
      if (k == end_key) return false;
      ours.push_back(k);
      return true;
    });
    ++rays;
    const std::vector<octomap::OcTreeKey> ref(reference.begin(), reference.end());
    if (ref != ours) ++differing;
  }
  // Both are Amanatides & Woo; ties at voxel corners may be broken differently.
  EXPECT_LE(differing, rays / 50) << differing << " of " << rays;
}

TEST(KeyRay, AnOriginOutsideTheKeyRangeIsRefusedBeforeAnyCast) {
  // A MAP_QUERY ray from x = 4.4e159 (the map fuzzer's input): the key was cast to long
  // first, which is undefined for such a double. Now it is out of the key range: false.
  int visited = 0;
  auto visit = [&](const octomap::OcTreeKey&, double, double) {
    ++visited;
    return true;
  };
  EXPECT_FALSE(m::traverse_keys(Vector3d(4.4e159, 0, 0), Vector3d(1, 0, 0), 1.0, 0.1, 0, visit));
  EXPECT_FALSE(m::traverse_keys(Vector3d(0, -1e300, 0), Vector3d(0, 1, 0), 1.0, 0.1, 3, visit));
  EXPECT_FALSE(m::traverse_keys(Vector3d(0, 0, std::nan("")), Vector3d(0, 0, 1), 1.0, 0.1, 0, visit));
  EXPECT_EQ(visited, 0);
  EXPECT_TRUE(m::traverse_keys(Vector3d(0.05, 0.05, 0.05), Vector3d(1, 0, 0), 0.25, 0.1, 0, visit));
  EXPECT_EQ(visited, 3);  // [0, 0.1), [0.1, 0.2), [0.2, 0.3)
}

TEST(Occupancy, APointFarOutsideTheTreeIsUnknownWithoutReachingOctoMapsCast) {
  // OctoMap's coordToKeyChecked casts before it checks: a MAP_QUERY at x = 4.4e159 was
  // undefined behaviour there (the map fuzzer, after the ray fix above).
  m::OccupancyMap map(exact_params());
  map.insert_frame({{2.05f, 0.05f, 0.05f}}, {0.05f, 0.05f, 0.05f});
  for (const Vector3d& p : {Vector3d(4.4e159, 0, 0), Vector3d(0, -1e300, 0), Vector3d(0, 0, 1e10)})
    EXPECT_EQ(map.occupancy(p).state, m::Occupancy::Unknown);
  EXPECT_EQ(map.occupancy({2.05, 0.05, 0.05}).state, m::Occupancy::Occupied);
  EXPECT_THROW(map.insert_frame({{0.f, 0.f, 0.f}}, {3e38f, 0.f, 0.f}), std::invalid_argument);
}
