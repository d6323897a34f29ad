#pragma once
// The visible surface of an OctoMap's occupied voxels as few large quads, for software
// OpenGL: a voxel face is kept only where the neighbouring cell is not occupied, and the
// kept unit faces of each plane are merged greedily into maximal rectangles (the
// "greedy meshing" of voxel engines). A flat floor of 300x300 voxels becomes one quad
// instead of 180,000, a wall a handful.
#include <octomap/OcTree.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace aerie::viewer {

struct VoxelMesh {
  std::vector<std::array<float, 3>> points;    // shared corners
  std::vector<std::array<uint32_t, 4>> quads;  // corner indices, counter-clockwise seen from outside
  size_t voxels = 0;                           // occupied leaves at the display depth
  size_t unit_faces = 0;                       // visible faces before merging

  std::array<float, 3> corner(size_t quad, int i) const { return points[quads[quad][static_cast<size_t>(i)]]; }
};

// `coarsening` levels above the finest (0 = finest; n = cells 2^n voxels wide).
VoxelMesh mesh_occupied_surface(const octomap::OcTree& tree, int coarsening = 0);

}  // namespace aerie::viewer
