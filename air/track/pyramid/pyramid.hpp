#pragma once
// The multi-resolution framework shared by hierarchical IPSL, AMCMR-CT and AM3
// (thesis 3.1.3 and 3.2.3): how many pyramid levels, how many samples each level
// rejects, and how the critical sample sets the next level's search range.
#include <cmath>
#include <vector>

namespace aerie::track::pyramid {

// N_PL = floor(log2(min(T_W, T_H) / minSize))  (eqs. 3.11, 3.23); at least 1.
inline int num_levels(double template_w, double template_h, double min_size) {
  const double r = std::min(template_w, template_h) / min_size;
  return r < 2 ? 1 : static_cast<int>(std::floor(std::log2(r)));
}

// Samples rejected at level p (p = 1 coarsest-side indexing as in the thesis):
// N_R^p = a^p * N^p  (eq. 3.14 with a = alpha, eq. 3.25 with a = xi).
inline int num_rejected(double a, int p, int n_at_level) {
  return static_cast<int>(std::floor(std::pow(a, p) * n_at_level));
}

// The next (finer) level's search range is twice the critical sample's distance
// (eqs. 3.15, 3.26): sigma^{p-1} = 2 H^p, alpha^{p-1} = 2 CD^p.
inline double next_search_range(double critical_distance) { return 2.0 * critical_distance; }

// Block size for appearance updates per level: N_B^{p-1} = floor(N_B^p / log2(1 + p))  (eq. 3.16).
inline int next_block_size(int block_size, int p) {
  return static_cast<int>(std::floor(block_size / std::log2(1.0 + p)));
}

// Integer offsets (dx, dy) strictly inside radius r: dx^2 + dy^2 < r^2 (Table 3.1:
// r = 5 -> 69, 6 -> 109, 8 -> 193, 10 -> 305, 20 -> 1245, 30 -> 2809 samples).
struct Offset {
  int dx, dy;
};
inline std::vector<Offset> offsets_within(double r) {
  std::vector<Offset> out;
  const int R = static_cast<int>(std::ceil(r));
  for (int dy = -R; dy <= R; ++dy)
    for (int dx = -R; dx <= R; ++dx)
      if (dx * dx + dy * dy < r * r) out.push_back({dx, dy});
  return out;
}

}  // namespace aerie::track::pyramid
