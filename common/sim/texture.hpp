#pragma once
// Procedural textures of the simulated world, stored as mip-mapped 8-bit images and
// sampled with trilinear filtering (anti-aliasing keeps the stereo pair consistent).
#include <opencv2/core.hpp>

#include <cmath>
#include <cstddef>
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
  // Level k without its replicated border.
  cv::Mat level(int k) const { return padded_[k](cv::Rect(0, 0, levels_[k].width, levels_[k].height)); }
  float texels_per_metre() const { return density_; }

  // Bilinear sample of level k at level-0 texel coordinates (u, v) (texel centres on
  // integers); clamps at the border.
  float bilinear(int k, float u, float v) const {
    const Level& l = levels_[k];
    float x = u * l.scale, y = v * l.scale;
    x = x < 0.f ? 0.f : (x > l.x_max ? l.x_max : x);
    y = y < 0.f ? 0.f : (y > l.y_max ? l.y_max : y);
    const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
    const float fx = x - static_cast<float>(x0), fy = y - static_cast<float>(y0);
    // The replicated right/bottom border makes x0 + 1 and y0 + 1 always valid.
    const uint8_t* r0 = l.data + static_cast<ptrdiff_t>(y0) * l.stride + x0;
    const uint8_t* r1 = r0 + l.stride;
    const float a = r0[0] + fx * static_cast<float>(r0[1] - r0[0]);
    const float b = r1[0] + fx * static_cast<float>(r1[1] - r1[0]);
    return a + fy * (b - a);
  }
  // Trilinear sample: lod = log2(texels per pixel footprint).
  float trilinear(float u, float v, float lod) const {
    if (lod <= 0.f) return bilinear(0, u, v);
    const int k = static_cast<int>(lod);
    if (k >= last_) return bilinear(last_, u, v);
    const float f = lod - static_cast<float>(k);
    const float a = bilinear(k, u, v);
    return a + f * (bilinear(k + 1, u, v) - a);
  }

 private:
  struct Level {
    const uint8_t* data;
    ptrdiff_t stride;
    int width, height;
    float x_max, y_max;  // width - 1, height - 1
    float scale;         // 2^-k
  };
  std::vector<cv::Mat> padded_;  // CV_8UC1, one replicated column/row right and below
  std::vector<Level> levels_;
  int last_ = 0;
  float density_ = 1.f;
};

// What a surface looks like; each kind has its own procedural generator.
// Room: Floor, Wall, Ceiling, Crate, Pillar. Field: Grass (ground), Asphalt (a road strip:
// rows across the road, white edge lines and a dashed centre line), Sky (bright, nearly
// uniform, faint clouds; emissive, not lit), Horizon (Sky with a dark treeline along the
// bottom rows: the field's side faces), Vehicle (smooth car paint with panel seams).
enum class Material { Floor, Wall, Ceiling, Crate, Pillar, Grass, Asphalt, Sky, Horizon, Vehicle };

// A procedural texture of a (width_m x height_m) surface at `texels_per_metre`, seeded.
// Multi-scale value noise plus a kind-specific pattern (tiles, bricks with posters, ceiling
// panels, crate planks, concrete, grass blades, road markings, clouds, treeline, car
// panels) plus scattered sharp marks, none of them periodic. Image rows run along
// height_m; for Horizon the last rows are the bottom of the face.
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
