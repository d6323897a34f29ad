#include "air/track/features/rect_features.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "air/track/features/kernels.hpp"

namespace aerie::track {
namespace {

// Scratch rows for the kernels, one per thread (trackers may run in several threads).
cv::Mat& padded_buffer() {
  thread_local cv::Mat buffer;
  return buffer;
}

void check_box(cv::Size box, int min_rects, int max_rects, const char* what) {
  if (box.width < 4 || box.height < 4)
    throw std::invalid_argument(std::string(what) + ": sample box " + std::to_string(box.width) + "x" +
                                std::to_string(box.height) + " is smaller than 4x4 pixels");
  if (min_rects < 1 || max_rects < min_rects || max_rects > RectFeature::kMaxRects)
    throw std::invalid_argument(std::string(what) + ": rectangles per feature must satisfy 1 <= min <= max <= " +
                                std::to_string(RectFeature::kMaxRects));
}

// A random rectangle inside the box, as both reference implementations draw them:
// top-left in [0, W-3] x [0, H-3], size at least 1 and at most up to 2 pixels from the border.
WeightedRect random_rect(cv::Size box, Rng& rng) {
  WeightedRect r;
  r.x = uniform_int(rng, 0, box.width - 3);
  r.y = uniform_int(rng, 0, box.height - 3);
  r.w = uniform_int(rng, 1, box.width - r.x - 2);
  r.h = uniform_int(rng, 1, box.height - r.y - 2);
  return r;
}

// Random features of min_rects..max_rects rectangles inside the box, each on a random
// channel; `weight` gives each rectangle its weight.
template <typename Weight>
std::vector<RectFeature> make_features(cv::Size box, int n, int min_rects, int max_rects,
                                       const std::vector<int>& channels, Rng& rng, const char* what, Weight weight) {
  check_box(box, min_rects, max_rects, what);
  if (channels.empty()) throw std::invalid_argument(std::string(what) + ": no channels");
  std::vector<RectFeature> out(n);
  for (auto& f : out) {
    f.channel = channels[uniform_int(rng, 0, static_cast<int>(channels.size()) - 1)];
    f.count = uniform_int(rng, min_rects, max_rects);
    for (int r = 0; r < f.count; ++r) {
      f.rects[r] = random_rect(box, rng);
      f.rects[r].weight = weight(f.rects[r]);
    }
  }
  return out;
}

}  // namespace

std::vector<RectFeature> make_compressive_features(cv::Size box, int n, int min_rects, int max_rects,
                                                   const std::vector<int>& channels, Rng& rng) {
  // eq. 3.19: +-sqrt(s), each with p = 1/(2s)
  return make_features(box, n, min_rects, max_rects, channels, rng, "compressive features",
                       [&](const auto&) { return uniform_int(rng, 0, 1) ? 1.0f : -1.0f; });
}

std::vector<RectFeature> make_haar_features(cv::Size box, int n, int min_rects, int max_rects,
                                            const std::vector<int>& channels, Rng& rng) {
  return make_features(box, n, min_rects, max_rects, channels, rng, "Haar features", [&](const auto& rect) {
    const double weight = 2 * uniform01(rng) - 1;
    return static_cast<float>(weight / (rect.w * rect.h));  // weight x rectangle mean
  });
}

std::vector<RectFeature> scale_features(const std::vector<RectFeature>& features, double s) {
  std::vector<RectFeature> out = features;
  for (auto& f : out)
    for (int r = 0; r < f.count; ++r) {
      WeightedRect& q = f.rects[r];
      const int area = q.w * q.h;
      q.x = static_cast<int>(std::lround(q.x * s));
      q.y = static_cast<int>(std::lround(q.y * s));
      q.w = std::max(1, static_cast<int>(std::lround(q.w * s)));
      q.h = std::max(1, static_cast<int>(std::lround(q.h * s)));
      q.weight = static_cast<float>(q.weight * static_cast<double>(area) / (q.w * q.h));
    }
  return out;
}

double feature_gain(const RectFeature& f) {
  double g = 0;
  for (int r = 0; r < f.count; ++r) g += std::abs(f.rects[r].weight) * f.rects[r].w * f.rects[r].h;
  return g;
}

std::vector<float> sigma_floors(const std::vector<RectFeature>& features, double grey_levels) {
  std::vector<float> out;
  for (const auto& f : features) out.push_back(static_cast<float>(grey_levels * feature_gain(f)));
  return out;
}

cv::Size features_extent(const std::vector<RectFeature>& features) {
  cv::Size e(0, 0);
  for (const auto& f : features)
    for (int r = 0; r < f.count; ++r) {
      e.width = std::max(e.width, f.rects[r].x + f.rects[r].w);
      e.height = std::max(e.height, f.rects[r].y + f.rects[r].h);
    }
  return e;
}

void evaluate_features(const ChannelImages& ch, const std::vector<RectFeature>& features, const std::vector<int>& which,
                       const SampleSet& samples, cv::Mat& out) {
  // Rows padded for the kernel's whole-vector stores; `out` is the view of the valid columns.
  const int n = static_cast<int>(samples.size());
  cv::Mat& buffer = padded_buffer();
  const cv::Size need(n + static_cast<int>(kernels::kOutputPad), static_cast<int>(which.size()));
  if (buffer.rows < need.height || buffer.cols < need.width) buffer.create(std::max(need.height, buffer.rows), std::max(need.width, buffer.cols), CV_32F);
  std::vector<const RectFeature*> fs;
  cv::Size extent(0, 0);
  for (int k : which) {
    fs.push_back(&features[k]);
    for (int r = 0; r < features[k].count; ++r) {
      extent.width = std::max(extent.width, features[k].rects[r].x + features[k].rects[r].w);
      extent.height = std::max(extent.height, features[k].rects[r].y + features[k].rects[r].h);
    }
  }
  const cv::Rect roi = ch.roi();
  int first = 0;
  for (const SampleRun& run : samples.runs()) {
    // The kernels read the integral image without bounds checks: every footprint must fit.
    if (run.x < roi.x || run.y < roi.y || run.x + run.count - 1 + extent.width > roi.x + roi.width ||
        run.y + extent.height > roi.y + roi.height)
      throw std::logic_error("evaluate_features: samples reach outside the integral image");
    kernels::features_run(ch, fs.data(), fs.size(), run, buffer.ptr<float>(0) + first, buffer.step1());
    first += run.count;
  }
  buffer(cv::Rect(0, 0, n, need.height)).copyTo(out);
}

void evaluate_features(const ChannelImages& ch, const std::vector<RectFeature>& features, const SampleSet& samples,
                       cv::Mat& out) {
  std::vector<int> all(features.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  evaluate_features(ch, features, all, samples, out);
}

ScaledFeatures::ScaledFeatures(std::vector<RectFeature> base, cv::Size box) : base_(std::move(base)), box_(box) {}

ScaledFeatures::Entry& ScaledFeatures::entry(double scale) {
  for (size_t i = 0; i < cache_.size(); ++i)
    if (cache_[i].scale == scale) {
      std::rotate(cache_.begin(), cache_.begin() + i, cache_.begin() + i + 1);
      return cache_.front();
    }
  Entry e{scale, scale == 1.0 ? base_ : scale_features(base_, scale), {}};
  const cv::Size extent = features_extent(e.features);
  e.footprint = {std::max({4, extent.width, static_cast<int>(std::lround(box_.width * scale))}),
                 std::max({4, extent.height, static_cast<int>(std::lround(box_.height * scale))})};
  if (cache_.size() == 4) cache_.pop_back();
  cache_.insert(cache_.begin(), std::move(e));
  return cache_.front();
}

const std::vector<RectFeature>& ScaledFeatures::at(double scale) { return entry(scale).features; }
cv::Size ScaledFeatures::footprint(double scale) { return entry(scale).footprint; }

}  // namespace aerie::track
