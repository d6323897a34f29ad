// The voxel surface mesher: exact face and quad counts on hand-built maps, and on a random
// map the merged quads cover exactly the visible unit faces, each facing out of the map.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <random>
#include <set>

#include "ground/viewer/voxel_mesh.hpp"

using aerie::viewer::mesh_occupied_surface;
using aerie::viewer::VoxelMesh;

namespace {

constexpr double kRes = 0.1;

octomap::point3d centre(int i, int j, int k) {
  return octomap::point3d(static_cast<float>((i + 0.5) * kRes), static_cast<float>((j + 0.5) * kRes),
                          static_cast<float>((k + 0.5) * kRes));
}

Eigen::Vector3d corner(const VoxelMesh& m, size_t q, int i) {
  const auto p = m.corner(q, i);
  return {p[0], p[1], p[2]};
}

double total_area(const VoxelMesh& m) {
  double a = 0;
  for (size_t q = 0; q < m.quads.size(); ++q)
    a += (corner(m, q, 1) - corner(m, q, 0)).cross(corner(m, q, 3) - corner(m, q, 0)).norm();
  return a;
}

}  // namespace

TEST(VoxelMesh, OneVoxelIsACubeOfSixFaces) {
  octomap::OcTree tree(kRes);
  tree.updateNode(centre(3, -2, 5), true);
  const VoxelMesh m = mesh_occupied_surface(tree);
  EXPECT_EQ(m.voxels, 1u);
  EXPECT_EQ(m.unit_faces, 6u);
  ASSERT_EQ(m.quads.size(), 6u);
  EXPECT_EQ(m.points.size(), 8u);  // shared corners
  for (const auto& p : m.points) {
    EXPECT_NEAR(p[0], p[0] < 0.35 ? 0.3 : 0.4, 1e-6);
    EXPECT_NEAR(p[1], p[1] < -0.15 ? -0.2 : -0.1, 1e-6);
    EXPECT_NEAR(p[2], p[2] < 0.55 ? 0.5 : 0.6, 1e-6);
  }
}

TEST(VoxelMesh, AFlatSlabMergesIntoSixQuads) {
  octomap::OcTree tree(kRes);
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 7; ++j) tree.updateNode(centre(i, j, 0), true);
  const VoxelMesh m = mesh_occupied_surface(tree);
  EXPECT_EQ(m.voxels, 70u);  // one layer: no 2x2x2 block to prune
  EXPECT_EQ(m.unit_faces, 70u + 70u + 2u * 10u + 2u * 7u);
  EXPECT_EQ(m.quads.size(), 6u);
  EXPECT_NEAR(total_area(m), static_cast<double>(m.unit_faces) * kRes * kRes, 1e-6);
}

TEST(VoxelMesh, PrunedBlockAndCoarserDisplay) {
  octomap::OcTree tree(kRes);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k) tree.updateNode(centre(i, j, k), true);
  tree.prune();
  const VoxelMesh fine = mesh_occupied_surface(tree);
  EXPECT_EQ(fine.voxels, 1u);  // one pruned leaf of 0.2 m
  EXPECT_EQ(fine.unit_faces, 24u);
  EXPECT_EQ(fine.quads.size(), 6u);
  const VoxelMesh coarse = mesh_occupied_surface(tree, 1);
  EXPECT_EQ(coarse.voxels, 1u);
  EXPECT_EQ(coarse.unit_faces, 6u);
  EXPECT_NEAR(total_area(coarse), 6 * 0.2 * 0.2, 1e-6);
}

TEST(VoxelMesh, RandomMapQuadsCoverTheVisibleFacesFacingOut) {
  octomap::OcTree tree(kRes);
  std::mt19937 rng(7);
  std::set<std::array<int, 3>> cells;
  std::uniform_int_distribution<int> coord(-6, 5);
  for (int n = 0; n < 600; ++n) {
    const std::array<int, 3> c{coord(rng), coord(rng), coord(rng)};
    cells.insert(c);
    tree.updateNode(centre(c[0], c[1], c[2]), true);
  }
  tree.updateNode(centre(20, 20, 20), false);  // free space is not drawn
  // Brute force: occupied cells times directions whose neighbour is not occupied.
  size_t visible = 0;
  const int dirs[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const auto& c : cells)
    for (const auto& d : dirs) visible += !cells.count({c[0] + d[0], c[1] + d[1], c[2] + d[2]});

  const VoxelMesh m = mesh_occupied_surface(tree);
  EXPECT_EQ(m.unit_faces, visible);
  EXPECT_LT(m.quads.size(), visible);
  EXPECT_NEAR(total_area(m), static_cast<double>(visible) * kRes * kRes, 1e-4);  // float corners
  auto occupied = [&](const Eigen::Vector3d& p) {
    const auto* node = tree.search(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
    return node && tree.isNodeOccupied(node);
  };
  for (size_t q = 0; q < m.quads.size(); ++q) {
    // Counter-clockwise corners: the normal points out, from an occupied cell into a free one.
    const Eigen::Vector3d c0 = corner(m, q, 0), c1 = corner(m, q, 1), c3 = corner(m, q, 3);
    const Eigen::Vector3d n = (c1 - c0).cross(c3 - c0).normalized();
    const Eigen::Vector3d mid = c0 + 0.5 * kRes * ((c1 - c0).normalized() + (c3 - c0).normalized());
    EXPECT_TRUE(occupied(mid - 0.5 * kRes * n)) << "quad " << q;
    EXPECT_FALSE(occupied(mid + 0.5 * kRes * n)) << "quad " << q;
  }
}
