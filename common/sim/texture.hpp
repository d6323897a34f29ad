#pragma once
// Procedural textures of the simulated world, stored as mip-mapped 8-bit images and
// sampled with trilinear filtering (anti-aliasing keeps the stereo pair consistent).
#include <opencv2/core.hpp>

#include <cmath>
#include <cstdint>
#include <vector>

namespace aerie::sim {

// A texture with its mip pyramid (level k is cv::pyrDown of level k-1, so texel i of
// level k sits on texel 2i of level k-1).
class MipTexture {
 public:
  MipTexture() = default;
  MipTexture(const cv::Mat& level0, double texels_per_metre);

  int levels() const { return static_cast<int>(levels_.size()); }
  const cv::Mat& level(int k) const { return levels_[k]; }
  float texels_per_metre() const { return density_; }

  // Bilinear sample of level k at level-0 texel coordinates (u, v) (texel centres on
  // integers); clamps at the border.
  float bilinear(int k, float u, float v) const {
    const cv::Mat& m = levels_[k];
    const float s = scale_[k];
    float x = u * s, y = v * s;
    const float xmax = static_cast<float>(m.cols - 1), ymax = static_cast<float>(m.rows - 1);
    x = x < 0.f ? 0.f : (x > xmax ? xmax : x);
    y = y < 0.f ? 0.f : (y > ymax ? ymax : y);
    const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
    const int x1 = x0 + (x0 + 1 < m.cols), y1 = y0 + (y0 + 1 < m.rows);
    const float fx = x - x0, fy = y - y0;
    const uint8_t* r0 = m.ptr<uint8_t>(y0);
    const uint8_t* r1 = m.ptr<uint8_t>(y1);
    const float a = r0[x0] + fx * (r0[x1] - r0[x0]);
    const float b = r1[x0] + fx * (r1[x1] - r1[x0]);
    return a + fy * (b - a);
  }
  // Trilinear sample: lod = log2(texels per pixel footprint).
  float trilinear(float u, float v, float lod) const {
    if (lod <= 0.f) return bilinear(0, u, v);
    const int last = static_cast<int>(levels_.size()) - 1;
    const int k = static_cast<int>(lod);
    if (k >= last) return bilinear(last, u, v);
    const float f = lod - static_cast<float>(k);
    const float a = bilinear(k, u, v);
    return a + f * (bilinear(k + 1, u, v) - a);
  }

 private:
  std::vector<cv::Mat> levels_;  // CV_8UC1
  std::vector<float> scale_;     // 2^-k
  float density_ = 1.f;
};

// What a surface looks like; each kind has its own procedural generator.
enum class Material { Floor, Wall, Ceiling, Crate, Pillar };

// A procedural texture of a (width_m x height_m) surface at `texels_per_metre`, seeded.
// Multi-scale value noise plus a kind-specific pattern (tiles, bricks with posters, ceiling
// panels, crate planks, concrete) plus scattered sharp marks, none of them periodic.
cv::Mat make_texture(Material material, double width_m, double height_m, double texels_per_metre,
                     uint64_t seed);

// Multi-scale value noise in [0, 1] (CV_32F), `octaves` octaves starting at cells of
// `cell` texels, each octave half the cell size and `gain` times the amplitude.
cv::Mat value_noise(cv::Size size, double cell, int octaves, double gain, uint64_t seed);

// SplitMix64: derives independent seeds from one (deterministic everywhere).
uint64_t mix_seed(uint64_t seed, uint64_t stream);

class Textures {
 public:
  std::vector<MipTexture> surfaces;  // one per World::surfaces() entry
};

}  // namespace aerie::sim
