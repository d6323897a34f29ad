#include "ground/viewer/voxel_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>
#include <utility>

namespace aerie::viewer {

namespace {

uint64_t pack(int64_t hi, int64_t lo) {
  return (static_cast<uint64_t>(static_cast<uint32_t>(hi)) << 32) | static_cast<uint32_t>(lo);
}

using Cell = std::array<int64_t, 3>;  // cell index along x, y, z in display units

}  // namespace

VoxelMesh mesh_occupied_surface(const octomap::OcTree& tree, int coarsening) {
  VoxelMesh mesh;
  const unsigned depth = tree.getTreeDepth() - static_cast<unsigned>(std::clamp(coarsening, 0, 15));
  const double unit = tree.getNodeSize(depth);
  auto occupied = [&](const Cell& cell) {
    const octomap::point3d centre(static_cast<float>((static_cast<double>(cell[0]) + 0.5) * unit),
                                  static_cast<float>((static_cast<double>(cell[1]) + 0.5) * unit),
                                  static_cast<float>((static_cast<double>(cell[2]) + 0.5) * unit));
    const auto* node = tree.search(centre, depth);
    return node && tree.isNodeOccupied(node);
  };

  // 1. Visible unit faces, grouped by plane: (axis a, outward side, plane index) -> cells
  //    (index along b, index along d) with (a, b, d) a cyclic permutation of (x, y, z).
  std::unordered_map<uint64_t, std::vector<std::pair<int64_t, int64_t>>> planes;
  for (auto it = tree.begin_leafs(depth); it != tree.end_leafs(); ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    ++mesh.voxels;
    const int64_t n = std::max<int64_t>(1, std::llround(it.getSize() / unit));  // a pruned leaf spans n cells
    const octomap::point3d c = it.getCoordinate();
    Cell lo;
    for (int a = 0; a < 3; ++a) lo[a] = std::llround(c(a) / unit - static_cast<double>(n) / 2.0);
    for (int a = 0; a < 3; ++a) {
      const int b = (a + 1) % 3, d = (a + 2) % 3;
      for (int side = 0; side < 2; ++side) {
        const int64_t plane = side ? lo[a] + n : lo[a];
        auto& cells = planes[pack(a * 2 + side, plane)];
        Cell neighbour;
        neighbour[a] = side ? lo[a] + n : lo[a] - 1;
        for (int64_t j = 0; j < n; ++j)
          for (int64_t k = 0; k < n; ++k) {
            neighbour[b] = lo[b] + j;
            neighbour[d] = lo[d] + k;
            if (occupied(neighbour)) continue;  // hidden face
            cells.emplace_back(lo[b] + j, lo[d] + k);
            ++mesh.unit_faces;
          }
      }
    }
  }

  // Corners are lattice points shared by the quads that meet there (indexed drawing).
  std::unordered_map<uint64_t, uint32_t> corner_ids;
  auto corner_index = [&](const Cell& p) {
    constexpr int64_t kOffset = int64_t{1} << 20;  // 21 bits per axis hold any OcTree key
    const uint64_t key = (static_cast<uint64_t>(p[0] + kOffset) << 42) | (static_cast<uint64_t>(p[1] + kOffset) << 21) |
                         static_cast<uint64_t>(p[2] + kOffset);
    const auto [it, added] = corner_ids.try_emplace(key, static_cast<uint32_t>(mesh.points.size()));
    if (added)
      mesh.points.push_back({static_cast<float>(static_cast<double>(p[0]) * unit),
                             static_cast<float>(static_cast<double>(p[1]) * unit),
                             static_cast<float>(static_cast<double>(p[2]) * unit)});
    return it->second;
  };

  // 2. Greedy merge per plane: scan rows, grow each open face along b, then along d while
  //    the whole row of that width is open.
  for (auto& [key, cells] : planes) {
    if (cells.empty()) continue;
    const int a = static_cast<int>(key >> 33), side = static_cast<int>((key >> 32) & 1);
    const int64_t plane = static_cast<int32_t>(key & 0xffffffffu);
    const int b = (a + 1) % 3, d = (a + 2) % 3;
    std::sort(cells.begin(), cells.end(), [](const auto& p, const auto& q) {
      return p.second != q.second ? p.second < q.second : p.first < q.first;
    });
    std::unordered_set<uint64_t> open;
    open.reserve(cells.size());
    for (const auto& [j, k] : cells) open.insert(pack(j, k));
    for (const auto& [j, k] : cells) {
      if (!open.count(pack(j, k))) continue;
      int64_t w = 1, h = 1;
      while (open.count(pack(j + w, k))) ++w;
      auto row_open = [&](int64_t y) {
        for (int64_t x = 0; x < w; ++x)
          if (!open.count(pack(j + x, y))) return false;
        return true;
      };
      while (row_open(k + h)) ++h;
      for (int64_t y = 0; y < h; ++y)
        for (int64_t x = 0; x < w; ++x) open.erase(pack(j + x, k + y));
      // Corners counter-clockwise seen from +a (e_b x e_d = e_a); reversed on the -a side.
      const int64_t uv[4][2] = {{j, k}, {j + w, k}, {j + w, k + h}, {j, k + h}};
      std::array<uint32_t, 4> quad{};
      for (int i = 0; i < 4; ++i) {
        const auto& q = uv[side ? i : 3 - i];
        Cell p{};
        p[a] = plane;
        p[b] = q[0];
        p[d] = q[1];
        quad[static_cast<size_t>(i)] = corner_index(p);
      }
      mesh.quads.push_back(quad);
    }
  }
  return mesh;
}

}  // namespace aerie::viewer
