#pragma once
// Rectangle features over an integral image: the compressive features of CT (a row of
// the very sparse measurement matrix R, eq. 3.19, applied to rectangle filters, eq. 3.17)
// and the Haar-like features of MIL (2..4 weighted rectangles, Babenko et al. 2011).
// Both are weighted sums of rectangle sums, evaluated for whole sample sets at once.
#include <array>
#include <opencv2/core.hpp>
#include <vector>

#include "air/track/features/channels.hpp"
#include "air/track/features/random.hpp"
#include "air/track/features/samples.hpp"

namespace aerie::track {

struct WeightedRect {
  int x = 0, y = 0, w = 1, h = 1;  // relative to the sample's top-left corner
  float weight = 0;
};

struct RectFeature {
  static constexpr int kMaxRects = 6;
  std::array<WeightedRect, kMaxRects> rects{};
  int count = 0;
  int channel = kGray;  // the channel every rectangle sums over
};

// n rows of the measurement matrix R (eq. 3.19) for a `box`-sized sample, as in Zhang et
// al. 2012: each row has c non-zero entries, c uniform in [min_rects, max_rects] (s = m/c:
// "very sparse"), each selecting a random rectangle filter h_{i,j} inside the box (eq. 3.17)
// with sign +1 or -1 at equal probability. The common factor sqrt(s) of eq. 3.19 scales every
// feature alike and is left out (the naive Bayes log-ratio of eq. 3.20 does not depend on it).
// Each feature draws its channel uniformly from `channels`.
std::vector<RectFeature> make_compressive_features(cv::Size box, int n, int min_rects, int max_rects,
                                                   const std::vector<int>& channels, Rng& rng);

// n Haar-like features (thesis 3.3.1): min_rects..max_rects rectangles inside the box, each
// with a real weight uniform in [-1, 1] applied to the rectangle's mean intensity.
std::vector<RectFeature> make_haar_features(cv::Size box, int n, int min_rects, int max_rects,
                                            const std::vector<int>& channels, Rng& rng);

// The features of a box scaled by s about its top-left corner: rectangles scaled and
// rounded, weights divided by the area ratio so that values stay comparable across scales.
std::vector<RectFeature> scale_features(const std::vector<RectFeature>& features, double s);

// sum_r |weight_r| * area_r: a feature's change when the intensity under all its rectangles
// changes by one grey level (scales a noise level in grey levels to feature units).
double feature_gain(const RectFeature& f);
// sigma floors of a feature set: grey_levels * feature_gain(f) for each feature.
std::vector<float> sigma_floors(const std::vector<RectFeature>& features, double grey_levels);

// Smallest box that contains every rectangle of the features (for checking the samples fit).
cv::Size features_extent(const std::vector<RectFeature>& features);

// out (CV_32F, features.size() x samples.size()): out(f, i) = feature f of sample i.
// Every sample box (plus features_extent) must lie inside ch.roi(); vectorised along x.
void evaluate_features(const ChannelImages& ch, const std::vector<RectFeature>& features, const SampleSet& samples,
                       cv::Mat& out);
// The same for the subset of features listed in `which` (row k of out = feature which[k]).
void evaluate_features(const ChannelImages& ch, const std::vector<RectFeature>& features, const std::vector<int>& which,
                       const SampleSet& samples, cv::Mat& out);

// A feature set made for a template box, with its versions for other scales of the box
// (scale_features) cached, since a frame uses a few scales many times.
class ScaledFeatures {
 public:
  ScaledFeatures(std::vector<RectFeature> base, cv::Size box);
  const std::vector<RectFeature>& base() const { return base_; }
  const std::vector<RectFeature>& at(double scale);
  // The sample box at `scale` (the template box scaled and rounded, grown to hold every rectangle).
  cv::Size footprint(double scale);

 private:
  struct Entry {
    double scale;
    std::vector<RectFeature> features;
    cv::Size footprint;
  };
  Entry& entry(double scale);
  std::vector<RectFeature> base_;
  cv::Size box_;
  std::vector<Entry> cache_;  // most recently used first
};

}  // namespace aerie::track
