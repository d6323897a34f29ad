#include "common/sim/texture.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace aerie::sim {

uint64_t mix_seed(uint64_t seed, uint64_t stream) {
  uint64_t z = seed + 0x9E3779B97F4A7C15ull * (stream + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

MipTexture::MipTexture(const cv::Mat& level0, double texels_per_metre)
    : density_(static_cast<float>(texels_per_metre)) {
  CV_Assert(level0.type() == CV_8UC1 && !level0.empty());
  std::vector<cv::Mat> pyramid{level0};
  while (pyramid.back().cols > 1 || pyramid.back().rows > 1) {
    const cv::Mat& prev = pyramid.back();
    cv::Mat next;
    if (prev.cols >= 2 && prev.rows >= 2) {
      cv::pyrDown(prev, next);
    } else {
      // pyrDown needs 2x2; keep halving the long side by averaging.
      cv::resize(prev, next, cv::Size((prev.cols + 1) / 2, (prev.rows + 1) / 2), 0, 0, cv::INTER_AREA);
    }
    pyramid.push_back(next);
  }
  float scale = 1.f;
  for (const cv::Mat& m : pyramid) {
    cv::Mat padded;
    cv::copyMakeBorder(m, padded, 0, 1, 0, 1, cv::BORDER_REPLICATE);
    padded_.push_back(padded);
    levels_.push_back({padded.data, static_cast<ptrdiff_t>(padded.step[0]), m.cols, m.rows,
                       static_cast<float>(m.cols - 1), static_cast<float>(m.rows - 1), scale});
    scale *= 0.5f;
  }
  last_ = static_cast<int>(levels_.size()) - 1;
}

cv::Mat value_noise(cv::Size size, double cell, int octaves, double gain, uint64_t seed) {
  cv::Mat acc = cv::Mat::zeros(size, CV_32F);
  cv::RNG rng(mix_seed(seed, 7));
  double amp = 1.0, total = 0.0;
  for (int o = 0; o < octaves; ++o, cell *= 0.5, amp *= gain) {
    const double c = std::max(cell, 1.0);
    const cv::Size small(static_cast<int>(std::ceil(size.width / c)) + 3,
                         static_cast<int>(std::ceil(size.height / c)) + 3);
    cv::Mat grid(small, CV_32F);
    rng.fill(grid, cv::RNG::UNIFORM, 0.0, 1.0);
    cv::Mat up;
    if (c <= 1.0) {
      up = grid;
    } else {
      cv::resize(grid, up,
                 cv::Size(static_cast<int>(std::ceil(small.width * c)),
                          static_cast<int>(std::ceil(small.height * c))),
                 0, 0, cv::INTER_CUBIC);
    }
    // Random offset so that octaves do not share their grid origin.
    const int ox = static_cast<int>(rng.uniform(0.0, c)), oy = static_cast<int>(rng.uniform(0.0, c));
    acc += amp * up(cv::Rect(ox, oy, size.width, size.height));
    total += amp;
  }
  acc /= total;
  return acc;
}

namespace {

// Scales a float image to [lo, hi] from its robust range.
cv::Mat stretch(const cv::Mat& f, double lo, double hi) {
  double mn, mx;
  cv::minMaxLoc(f, &mn, &mx);
  cv::Mat out;
  f.convertTo(out, CV_32F, (hi - lo) / std::max(mx - mn, 1e-6), lo - mn * (hi - lo) / std::max(mx - mn, 1e-6));
  return out;
}

// Sharp random marks (dots, dashes, squares, triangles, rings) of 1-12 cm at `per_m2`
// per square metre: the corners FAST finds at every distance.
void scatter_marks(cv::Mat& img, double density, double per_m2, cv::RNG& rng, double contrast) {
  const double area = img.cols * img.rows / (density * density);
  const int n = static_cast<int>(area * per_m2);
  constexpr int kShift = 4;  // sub-texel drawing precision
  const double sub = 1 << kShift;
  for (int i = 0; i < n; ++i) {
    const double size = density * std::exp(rng.uniform(std::log(0.01), std::log(0.12)));
    // One draw per statement: a call's arguments are evaluated in an unspecified order (x86-64
    // GCC right to left, arm64 left to right); this is x86's order, now on every architecture.
    const double cy = rng.uniform(0.0, 1.0 * img.rows);
    const cv::Point2d c(rng.uniform(0.0, 1.0 * img.cols), cy);
    const float below = img.at<float>(std::min(static_cast<int>(c.y), img.rows - 1),
                                      std::min(static_cast<int>(c.x), img.cols - 1));
    // Dark on bright, bright on dark.
    const double shade = below > 0.5f ? rng.uniform(0.0, 0.5 - 0.3 * contrast) : rng.uniform(0.5 + 0.3 * contrast, 1.0);
    const cv::Scalar col(shade);
    auto P = [&](double x, double y) { return cv::Point(cvRound(x * sub), cvRound(y * sub)); };
    switch (rng.uniform(0, 5)) {
      case 0:
        cv::circle(img, P(c.x, c.y), cvRound(0.5 * size * sub), col, cv::FILLED, cv::LINE_AA, kShift);
        break;
      case 1: {
        const double a = rng.uniform(0.0, CV_PI);
        cv::line(img, P(c.x, c.y), P(c.x + size * std::cos(a), c.y + size * std::sin(a)), col,
                 std::max(1, cvRound(size * 0.15)), cv::LINE_AA, kShift);
        break;
      }
      case 2: {
        const double w = size * rng.uniform(0.4, 1.0);
        cv::rectangle(img, P(c.x, c.y), P(c.x + size, c.y + w), col, cv::FILLED, cv::LINE_AA, kShift);
        break;
      }
      case 3: {
        std::vector<cv::Point> tri;
        for (int k = 0; k < 3; ++k) {
          const double a = rng.uniform(0.0, 2 * CV_PI);
          tri.push_back(P(c.x + size * std::cos(a), c.y + size * std::sin(a)));
        }
        cv::fillConvexPoly(img, tri, col, cv::LINE_AA, kShift);
        break;
      }
      default:
        cv::circle(img, P(c.x, c.y), cvRound(0.5 * size * sub), col, std::max(1, cvRound(size * 0.12)),
                   cv::LINE_AA, kShift);
    }
  }
}

// Bricks of random length in courses of 12 cm with staggered joints; each brick its own shade.
void draw_bricks(cv::Mat& img, double density, cv::RNG& rng) {
  const double course = 0.12 * density, mortar = std::max(1.0, 0.012 * density);
  for (double y = 0; y < img.rows; y += course) {
    double x = -rng.uniform(0.0, 0.3) * density;
    while (x < img.cols) {
      const double len = rng.uniform(0.18, 0.42) * density;
      const cv::Rect r(cvRound(x + mortar), cvRound(y + mortar), cvRound(len - mortar), cvRound(course - mortar));
      const cv::Rect clip = r & cv::Rect(0, 0, img.cols, img.rows);
      if (clip.area() > 0) img(clip) += cv::Scalar(rng.uniform(-0.25, 0.25));
      x += len;
    }
    cv::rectangle(img, cv::Rect(0, cvRound(y), img.cols, cvRound(mortar)), cv::Scalar(0.85), cv::FILLED);
  }
}

// Poster-like rectangles: random stripes, discs, checker-free blocks and "text" lines.
void draw_posters(cv::Mat& img, double density, cv::RNG& rng) {
  const double area = img.cols * img.rows / (density * density);
  const int n = std::max(1, static_cast<int>(area / 2.5));
  for (int i = 0; i < n; ++i) {
    const int w = cvRound(rng.uniform(0.4, 1.3) * density), h = cvRound(rng.uniform(0.4, 1.0) * density);
    const int top = cvRound(rng.uniform(0.05, 0.5) * img.rows);  // one draw per statement (scatter_marks)
    const cv::Rect r(cvRound(rng.uniform(0.0, std::max(1.0, img.cols - 1.0 * w))), top, w, h);
    const cv::Rect clip = r & cv::Rect(0, 0, img.cols, img.rows);
    if (clip.area() <= 0) continue;
    cv::Mat roi = img(clip);
    roi.setTo(cv::Scalar(rng.uniform(0.6, 0.95)));
    const int kind = rng.uniform(0, 3);
    const int items = rng.uniform(6, 20);
    for (int k = 0; k < items; ++k) {
      const cv::Scalar col(rng.uniform(0.0, 0.45));
      const int py = rng.uniform(0, clip.height);
      const cv::Point p(rng.uniform(0, clip.width), py);
      if (kind == 0) {
        cv::circle(roi, p, rng.uniform(2, std::max(3, clip.width / 5)), col, cv::FILLED, cv::LINE_AA);
      } else if (kind == 1) {
        const double a = rng.uniform(0.0, CV_PI);
        const int len = clip.width;
        cv::line(roi, p, p + cv::Point(cvRound(len * std::cos(a)), cvRound(len * std::sin(a))), col,
                 rng.uniform(1, std::max(2, clip.width / 25)), cv::LINE_AA);
      } else {
        // a line of "words": blocks of random widths
        int x = p.x;
        const int hh = std::max(2, clip.height / 14);
        while (x < clip.width) {
          const int ww = rng.uniform(hh, 5 * hh);
          cv::rectangle(roi, cv::Rect(x, p.y, ww, hh), col, cv::FILLED);
          x += ww + rng.uniform(hh / 2 + 1, 2 * hh);
        }
      }
    }
    cv::rectangle(img, clip, cv::Scalar(0.1), std::max(1, cvRound(0.01 * density)));
  }
}

// Floor tiles of 60 cm, each with its own shade, dark grout.
void draw_tiles(cv::Mat& img, double density, cv::RNG& rng) {
  const double tile = 0.6 * density, grout = std::max(1.0, 0.01 * density);
  for (double y = 0; y < img.rows; y += tile)
    for (double x = 0; x < img.cols; x += tile) {
      const cv::Rect r(cvRound(x), cvRound(y), cvRound(tile), cvRound(tile));
      const cv::Rect clip = r & cv::Rect(0, 0, img.cols, img.rows);
      if (clip.area() <= 0) continue;
      img(clip) += cv::Scalar(rng.uniform(-0.2, 0.2));
      cv::rectangle(img, cv::Rect(clip.x, clip.y, clip.width, cvRound(grout)) & cv::Rect(0, 0, img.cols, img.rows),
                    cv::Scalar(0.15), cv::FILLED);
      cv::rectangle(img, cv::Rect(clip.x, clip.y, cvRound(grout), clip.height) & cv::Rect(0, 0, img.cols, img.rows),
                    cv::Scalar(0.15), cv::FILLED);
    }
}

// Wooden planks of random width with grain stretched along them.
void draw_planks(cv::Mat& img, double density, cv::RNG& rng, uint64_t seed) {
  cv::Mat grain = value_noise(cv::Size(img.cols, std::max(2, img.rows / 8)), 0.1 * density, 4, 0.6, seed);
  cv::resize(grain, grain, img.size(), 0, 0, cv::INTER_LINEAR);
  img = 0.5 * img + 0.6 * grain;
  double y = 0;
  while (y < img.rows) {
    const double h = rng.uniform(0.08, 0.2) * density;
    const cv::Rect r = cv::Rect(0, cvRound(y), img.cols, cvRound(h)) & cv::Rect(0, 0, img.cols, img.rows);
    if (r.area() > 0) img(r) += cv::Scalar(rng.uniform(-0.2, 0.2));
    cv::rectangle(img, cv::Rect(0, cvRound(y), img.cols, std::max(1, cvRound(0.008 * density))), cv::Scalar(0.05),
                  cv::FILLED);
    y += h;
  }
}

// Bright light panels in a jittered layout.
void draw_panels(cv::Mat& img, double density, cv::RNG& rng) {
  for (double y = 0.5 * density; y < img.rows; y += 2.0 * density)
    for (double x = 0.5 * density; x < img.cols; x += 2.0 * density) {
      // One draw per statement, the last argument first (scatter_marks).
      const int h = cvRound(rng.uniform(0.3, 0.6) * density);
      const int w = cvRound(rng.uniform(0.6, 1.2) * density);
      const int top = cvRound(y + rng.uniform(-0.3, 0.3) * density);
      const cv::Rect r(cvRound(x + rng.uniform(-0.3, 0.3) * density), top, w, h);
      const cv::Rect clip = r & cv::Rect(0, 0, img.cols, img.rows);
      if (clip.area() > 0) img(clip).setTo(cv::Scalar(rng.uniform(0.9, 1.0)));
    }
}

// Grass: many short blades (anti-aliased strokes, lighter or darker than the ground under
// them) in clumps, on a dark multi-scale noise.
void draw_grass(cv::Mat& img, double density, cv::RNG& rng) {
  const double area = img.cols * img.rows / (density * density);
  const int n = static_cast<int>(area * 200.0);
  constexpr int kShift = 4;
  const double sub = 1 << kShift;
  for (int i = 0; i < n; ++i) {
    const double cy = rng.uniform(0.0, 1.0 * img.rows);  // one draw per statement (scatter_marks)
    const cv::Point2d c(rng.uniform(0.0, 1.0 * img.cols), cy);
    const double len = density * rng.uniform(0.015, 0.05), a = rng.uniform(0.0, CV_PI);
    const float below = img.at<float>(std::min(static_cast<int>(c.y), img.rows - 1),
                                      std::min(static_cast<int>(c.x), img.cols - 1));
    const cv::Scalar col(std::clamp(below + rng.uniform(-0.14, 0.18), 0.0, 1.0));
    cv::line(img, cv::Point(cvRound(c.x * sub), cvRound(c.y * sub)),
             cv::Point(cvRound((c.x + len * std::cos(a)) * sub), cvRound((c.y + len * std::sin(a)) * sub)), col,
             1, cv::LINE_AA, kShift);
  }
}

// Road markings on an asphalt strip whose rows run across the road: white edge lines
// 0.25 m from both edges and a dashed centre line (dashes and gaps of random length).
void draw_road_markings(cv::Mat& img, double density, cv::RNG& rng) {
  const int w = std::max(1, cvRound(0.12 * density));
  auto paint = [&](cv::Rect r) {
    r &= cv::Rect(0, 0, img.cols, img.rows);
    if (r.area() > 0) img(r) = 0.3 * img(r) + 0.62;  // worn white paint: the asphalt shows through
  };
  if (img.rows > 4 * w + cvRound(density)) {
    const int edge = cvRound(0.25 * density);
    paint(cv::Rect(0, edge, img.cols, w));
    paint(cv::Rect(0, img.rows - edge - w, img.cols, w));
  }
  double x = -rng.uniform(0.0, 3.0) * density;
  while (x < img.cols) {
    const double dash = rng.uniform(2.5, 3.5) * density;
    paint(cv::Rect(cvRound(x), (img.rows - w) / 2, cvRound(dash), w));
    x += dash + rng.uniform(3.0, 4.5) * density;
  }
}

// Bright, nearly uniform sky with faint clouds of a few metres.
cv::Mat sky(cv::Size size, double density, uint64_t seed) {
  return stretch(value_noise(size, 6.0 * density, 4, 0.5, mix_seed(seed, 11)), 0.84, 0.88);
}

// A dark treeline, 1.5-5 m high with a ragged top, along the bottom rows of a sky face.
void draw_treeline(cv::Mat& img, const cv::Mat& foliage, double density, uint64_t seed) {
  const cv::Mat profile = value_noise(cv::Size(img.cols, 2), 3.0 * density, 6, 0.6, mix_seed(seed, 12));
  for (int u = 0; u < img.cols; ++u) {
    const double top = img.rows - (1.5 + 3.5 * profile.at<float>(0, u)) * density;  // row of the tree tops
    for (int v = std::max(0, static_cast<int>(top)); v < img.rows; ++v) {
      const float cover = static_cast<float>(std::clamp(v + 1.0 - top, 0.0, 1.0));  // anti-aliased top
      const float leaf = 0.1f + 0.3f * (foliage.at<float>(v, u) - 0.2f);
      img.at<float>(v, u) += cover * (leaf - img.at<float>(v, u));
    }
  }
}

// Car panel seams: a few dark lines across and along the face.
void draw_seams(cv::Mat& img, double density, cv::RNG& rng) {
  const int w = std::max(1, cvRound(0.006 * density));
  const int across = rng.uniform(2, 5), along = rng.uniform(1, 3);
  for (int i = 0; i < across; ++i)
    cv::rectangle(img, cv::Rect(rng.uniform(0, img.cols), 0, w, img.rows), cv::Scalar(0.15), cv::FILLED);
  for (int i = 0; i < along; ++i)
    cv::rectangle(img, cv::Rect(0, rng.uniform(0, img.rows), img.cols, w), cv::Scalar(0.15), cv::FILLED);
}

}  // namespace

cv::Mat make_texture(Material material, double width_m, double height_m, double density, uint64_t seed) {
  const cv::Size size(std::max(2, static_cast<int>(std::ceil(width_m * density))),
                      std::max(2, static_cast<int>(std::ceil(height_m * density))));
  cv::RNG rng(mix_seed(seed, 3));
  // Multi-scale noise from 1.2 m blobs down to texel grain.
  cv::Mat img = stretch(value_noise(size, 1.2 * density, 7, 0.62, seed), 0.2, 0.8);
  switch (material) {
    case Material::Floor:
      draw_tiles(img, density, rng);
      scatter_marks(img, density, 60.0, rng, 0.6);
      break;
    case Material::Wall:
      draw_bricks(img, density, rng);
      scatter_marks(img, density, 25.0, rng, 0.5);
      draw_posters(img, density, rng);
      break;
    case Material::Ceiling:
      img = 0.6 * img;
      scatter_marks(img, density, 15.0, rng, 0.4);
      draw_panels(img, density, rng);
      break;
    case Material::Crate:
      draw_planks(img, density, rng, mix_seed(seed, 5));
      scatter_marks(img, density, 60.0, rng, 0.7);
      break;
    case Material::Pillar:
      scatter_marks(img, density, 80.0, rng, 0.6);
      break;
    case Material::Grass:
      img = 0.5 * img + 0.05;  // darker than indoor surfaces
      draw_grass(img, density, rng);
      scatter_marks(img, density, 2.0, rng, 0.2);  // stones, flowers
      break;
    case Material::Asphalt: {
      img = 0.12 * img + 0.12;  // darker and smoother than the grass
      cv::Mat grain(size, CV_32F);
      rng.fill(grain, cv::RNG::UNIFORM, -0.05, 0.05);
      img += grain;
      scatter_marks(img, density, 8.0, rng, 0.4);  // stains, cracks
      draw_road_markings(img, density, rng);
      break;
    }
    case Material::Sky:
      img = sky(size, density, seed);
      break;
    case Material::Horizon: {
      const cv::Mat foliage = img;
      img = sky(size, density, seed);
      draw_treeline(img, foliage, density, seed);
      break;
    }
    case Material::Vehicle:
      img = 0.2 * img + 0.4;  // smooth paint
      draw_seams(img, density, rng);
      scatter_marks(img, density, 6.0, rng, 0.4);  // dirt
      break;
  }
  cv::Mat out;
  img.convertTo(out, CV_8U, 255.0);
  return out;
}

}  // namespace aerie::sim
