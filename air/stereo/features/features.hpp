#pragma once
// Bucketed FAST features with the modified BRIEF descriptor (thesis eqs. 4.5-4.7), and
// their matching between consecutive left frames by Hamming distance.
//
//  * Buckets (eq. 4.5): the centred region of interest (image minus margins O_W, O_H)
//    split into N_x x N_y rectangles of B_W = (I_W - 2 O_W) / N_x by B_H = (I_H - 2 O_H) / N_y;
//    at most `max_per_bucket` FAST corners (strongest response) are kept in each.
//  * Smoothing: the region is Gaussian-smoothed before detection and description.
//  * Modified BRIEF (eqs. 4.6-4.7): bit j is 1 when I(p + x_j) < I(p + y_j), with the test
//    offsets sampled once as x_j ~ N(0, (S_r/5)^2) and y_j ~ N(x_j, (2 S_r/25)^2) (per axis)
//    inside the S_r x S_r window.
#include <array>
#include <bit>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace aerie::stereo {

struct FeatureParams {
  int buckets_x = 6;        // N_x
  int buckets_y = 4;        // N_y
  int margin_x = 16;        // O_W (pixels); at least patch_size / 2 + 3 (FAST circle)
  int margin_y = 16;        // O_H
  int max_per_bucket = 20;  // 6 x 4 x 20 = 480 features at most (thesis defaults)
  int fast_threshold = 20;  // FAST intensity threshold
  int min_fast_threshold = 5;  // a bucket with too few corners retries down to this threshold
  double smoothing_sigma = 1.2;  // Gaussian smoothing before FAST and BRIEF (0 = off)
  // Refine corner positions to sub-pixel (cv::cornerSubPix). Off by default: the Lucas-Kanade
  // alignment of the matches (vo.hpp, klt_window) refines every tracked position anyway, and
  // the refinement cost 40 % of the feature stage for no measurable accuracy gain.
  bool subpixel = false;
  int patch_size = 25;      // S_r
  int descriptor_bits = 256;  // N_b (multiple of 64, at most 512)
  uint64_t pattern_seed = 24301;  // the sampling pattern is fixed per seed

  void validate(const std::string& what = "features") const;
};

inline constexpr int kMaxDescriptorWords = 8;  // 512 bits
using Descriptor = std::array<uint64_t, kMaxDescriptorWords>;

inline int hamming(const Descriptor& a, const Descriptor& b, int words) {
  int d = 0;
  for (int i = 0; i < words; ++i) d += std::popcount(a[i] ^ b[i]);
  return d;
}

// The test pairs (x_j, y_j) of eq. 4.7, integer offsets clipped to the S_r window.
struct BriefPattern {
  std::vector<cv::Point> x, y;
  static BriefPattern sample(int patch_size, int bits, uint64_t seed);
};

struct Feature {
  cv::Point2f pt;
  float response = 0;
  int bucket = 0;
  Descriptor desc{};
};

struct FeatureFrame {
  std::vector<Feature> features;
  std::vector<int> per_bucket;  // counts, bucket index = by * N_x + bx
  cv::Rect roi;                 // region of interest of eq. 4.5
};

class FeatureExtractor {
 public:
  explicit FeatureExtractor(const FeatureParams& params = {});
  // gray: CV_8UC1. Throws std::invalid_argument if the image is smaller than the margins
  // and one pixel per bucket.
  FeatureFrame extract(const cv::Mat& gray);

  const FeatureParams& params() const { return params_; }
  const BriefPattern& pattern() const { return pattern_; }
  int descriptor_words() const { return params_.descriptor_bits / 64; }
  // Bucket geometry of eq. 4.5 for an image size.
  static cv::Rect region_of_interest(const FeatureParams& p, cv::Size image);
  static cv::Rect bucket_rect(const FeatureParams& p, cv::Size image, int bx, int by);
  // Descriptor of a point on an already smoothed image (eq. 4.6).
  Descriptor describe(const cv::Mat& smoothed, cv::Point p) const;

 private:
  FeatureParams params_;
  BriefPattern pattern_;
  cv::Mat smoothed_;
};

struct MatchParams {
  int max_distance = 70;         // Hamming distance accepted (of descriptor_bits)
  double ratio = 0.85;           // best < ratio * second best (0 = off)
  double search_radius = 80.0;   // pixels around the (predicted) previous position
  bool mutual = true;            // i's best is j and j's best is i
};

struct Match {
  int prev = -1, cur = -1;
  int distance = 0;
};

// Matches features of the previous frame to the current one. `predicted` (optional, one per
// previous feature) is where each previous feature is expected now; otherwise its old position.
std::vector<Match> match_features(const std::vector<Feature>& prev, const std::vector<Feature>& cur, int words,
                                  const MatchParams& params, const std::vector<cv::Point2f>* predicted = nullptr);

}  // namespace aerie::stereo
