#include "air/track/features/samples.hpp"

#include <algorithm>
#include <cmath>

namespace aerie::track {

void SampleSet::add(int x, int y) {
  if (!runs_.empty()) {
    SampleRun& last = runs_.back();
    if (last.y == y && last.x + last.count == x) {
      ++last.count;
      positions_.emplace_back(x, y);
      return;
    }
  }
  runs_.push_back({x, y, 1});
  positions_.emplace_back(x, y);
}

namespace {
// Top-left positions for which a `box` lies inside `bounds`.
cv::Rect valid_origins(cv::Size box, const cv::Rect& bounds) {
  return {bounds.x, bounds.y, bounds.width - box.width + 1, bounds.height - box.height + 1};
}
}  // namespace

SampleSet disc_samples(cv::Point origin, double radius, cv::Size box, const cv::Rect& bounds) {
  SampleSet out;
  const cv::Rect valid = valid_origins(box, bounds);
  const int R = static_cast<int>(std::ceil(radius));
  const double r2 = radius * radius;
  for (int dy = -R; dy <= R; ++dy) {
    const int y = origin.y + dy;
    if (y < valid.y || y >= valid.y + valid.height) continue;
    for (int dx = -R; dx <= R; ++dx) {
      const int x = origin.x + dx;
      if (dx * dx + dy * dy < r2 && x >= valid.x && x < valid.x + valid.width) out.add(x, y);
    }
  }
  return out;
}

SampleSet ring_samples(cv::Point origin, double inner, double outer, int max_count, cv::Size box,
                       const cv::Rect& bounds, Rng& rng) {
  const cv::Rect valid = valid_origins(box, bounds);
  const int R = static_cast<int>(std::ceil(outer));
  std::vector<cv::Point> ring;
  for (int dy = -R; dy <= R; ++dy)
    for (int dx = -R; dx <= R; ++dx) {
      const double d2 = dx * dx + dy * dy;
      const cv::Point p(origin.x + dx, origin.y + dy);
      if (d2 > inner * inner && d2 < outer * outer && valid.contains(p)) ring.push_back(p);
    }
  // Partial Fisher-Yates: the first n entries become a uniform draw without replacement.
  const int n = std::min<int>(max_count, static_cast<int>(ring.size()));
  for (int i = 0; i < n; ++i) std::swap(ring[i], ring[uniform_int(rng, i, static_cast<int>(ring.size()) - 1)]);
  ring.resize(n);
  std::sort(ring.begin(), ring.end(), [](cv::Point a, cv::Point b) { return a.y != b.y ? a.y < b.y : a.x < b.x; });
  SampleSet out;
  for (const auto& p : ring) out.add(p.x, p.y);
  return out;
}

SampleSet grid_samples(cv::Size box, const cv::Rect& bounds, int stride) {
  SampleSet out;
  const cv::Rect valid = valid_origins(box, bounds);
  for (int y = valid.y; y < valid.y + valid.height; y += stride)
    for (int x = valid.x; x < valid.x + valid.width; x += stride) out.add(x, y);
  return out;
}

}  // namespace aerie::track
