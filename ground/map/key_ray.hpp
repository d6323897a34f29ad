#pragma once
// Voxel traversal in OctoMap key space (Amanatides & Woo 1987, "A fast voxel traversal
// algorithm for ray tracing"), at the finest level or on the coarser cells of a tree
// depth. Key units: u = x / resolution + 32768, so that cell c of edge 2^shift keys spans
// [c 2^shift, (c + 1) 2^shift) and its keys are those of OctoMap's coordToKey.
#include <octomap/OcTreeKey.h>

#include <Eigen/Core>
#include <cmath>
#include <limits>

namespace aerie::map {

inline constexpr int kKeyCentre = 32768;  // OcTree tree_max_val for the 16-level tree

// Calls visit(key, t_enter, t_exit) for every cell of edge resolution * 2^shift that the
// segment origin + t * direction (|direction| = 1, t in metres) crosses for t in [0, length],
// in order, until visit returns false. The key passed is the cell's lowest key. Returns
// false when the segment leaves the key range.
template <typename Visit>
bool traverse_keys(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double length, double resolution,
                   unsigned shift, Visit&& visit) {
  const double cell = static_cast<double>(1u << shift);
  const long n_cells = 65536L >> shift;
  long c[3];
  int step[3];
  double t_max[3], t_delta[3];
  for (int i = 0; i < 3; ++i) {
    const double u = origin[i] / resolution + kKeyCentre;
    const double ci = std::floor(u / cell);
    if (!(ci >= 0 && ci < static_cast<double>(n_cells))) return false;  // also NaN; checked before the cast (1e159 overflowed it)
    c[i] = static_cast<long>(ci);
    const double du = direction[i] / resolution;  // key units per metre
    if (du > 0) {
      step[i] = 1;
      t_max[i] = ((static_cast<double>(c[i]) + 1) * cell - u) / du;
      t_delta[i] = cell / du;
    } else if (du < 0) {
      step[i] = -1;
      t_max[i] = (static_cast<double>(c[i]) * cell - u) / du;
      t_delta[i] = -cell / du;
    } else {
      step[i] = 0;
      t_max[i] = t_delta[i] = std::numeric_limits<double>::infinity();
    }
  }
  double t_enter = 0.0;
  while (true) {
    const int dim = t_max[0] < t_max[1] ? (t_max[0] < t_max[2] ? 0 : 2) : (t_max[1] < t_max[2] ? 1 : 2);
    const double t_exit = t_max[dim];
    const octomap::OcTreeKey key(static_cast<octomap::key_type>(c[0] << shift),
                                 static_cast<octomap::key_type>(c[1] << shift),
                                 static_cast<octomap::key_type>(c[2] << shift));
    if (!visit(key, t_enter, t_exit) || t_exit >= length) return true;
    c[dim] += step[dim];
    if (c[dim] < 0 || c[dim] >= n_cells) return false;
    t_max[dim] += t_delta[dim];
    t_enter = t_exit;
  }
}

}  // namespace aerie::map
