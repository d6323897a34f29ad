#include "air/stereo/features/features.hpp"

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace aerie::stereo {

void FeatureParams::validate(const std::string& what) const {
  auto fail = [&](const std::string& field, const std::string& expected) {
    throw std::invalid_argument(what + "." + field + ": " + expected);
  };
  if (buckets_x < 1 || buckets_y < 1) fail("buckets_x/buckets_y", ">= 1");
  if (max_per_bucket < 1) fail("max_per_bucket", ">= 1");
  if (patch_size < 5 || patch_size % 2 == 0) fail("patch_size", "odd, >= 5");
  if (margin_x < patch_size / 2 + 3 || margin_y < patch_size / 2 + 3)
    fail("margin_x/margin_y", "at least patch_size / 2 + 3 = " + std::to_string(patch_size / 2 + 3));
  if (descriptor_bits < 64 || descriptor_bits % 64 != 0 || descriptor_bits > 64 * kMaxDescriptorWords)
    fail("descriptor_bits", "a multiple of 64 in [64, 512]");
  if (fast_threshold < 1 || min_fast_threshold < 1 || min_fast_threshold > fast_threshold)
    fail("fast_threshold/min_fast_threshold", "1 <= min_fast_threshold <= fast_threshold");
  if (smoothing_sigma < 0) fail("smoothing_sigma", ">= 0");
}

BriefPattern BriefPattern::sample(int patch_size, int bits, uint64_t seed) {
  // Eq. 4.7: x_j ~ N(0, (S_r / 5)^2), y_j ~ N(x_j, (2 S_r / 25)^2), each axis independent,
  // rounded to pixels and kept inside the S_r x S_r window.
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gx(0.0, patch_size / 5.0), gy(0.0, 2.0 * patch_size / 25.0);
  const int half = patch_size / 2;
  auto clip = [half](double v) { return std::clamp(static_cast<int>(std::lround(v)), -half, half); };
  BriefPattern p;
  while (static_cast<int>(p.x.size()) < bits) {
    const double x0 = gx(rng), x1 = gx(rng);
    const double y0 = x0 + gy(rng), y1 = x1 + gy(rng);
    const cv::Point a(clip(x0), clip(x1)), b(clip(y0), clip(y1));
    if (a == b) continue;  // a test of a pixel against itself carries no information
    p.x.push_back(a);
    p.y.push_back(b);
  }
  return p;
}

FeatureExtractor::FeatureExtractor(const FeatureParams& params) : params_(params) {
  params_.validate();
  pattern_ = BriefPattern::sample(params_.patch_size, params_.descriptor_bits, params_.pattern_seed);
}

cv::Rect FeatureExtractor::region_of_interest(const FeatureParams& p, cv::Size image) {
  return {p.margin_x, p.margin_y, image.width - 2 * p.margin_x, image.height - 2 * p.margin_y};
}

cv::Rect FeatureExtractor::bucket_rect(const FeatureParams& p, cv::Size image, int bx, int by) {
  // Eq. 4.5 with integer edges: bucket bx spans [O_W + bx B_W, O_W + (bx+1) B_W).
  const cv::Rect roi = region_of_interest(p, image);
  const int x0 = roi.x + roi.width * bx / p.buckets_x, x1 = roi.x + roi.width * (bx + 1) / p.buckets_x;
  const int y0 = roi.y + roi.height * by / p.buckets_y, y1 = roi.y + roi.height * (by + 1) / p.buckets_y;
  return {x0, y0, x1 - x0, y1 - y0};
}

Descriptor FeatureExtractor::describe(const cv::Mat& smoothed, cv::Point p) const {
  Descriptor d{};
  const uint8_t* centre = smoothed.ptr<uint8_t>(p.y) + p.x;
  const ptrdiff_t step = static_cast<ptrdiff_t>(smoothed.step);
  for (size_t j = 0; j < pattern_.x.size(); ++j) {
    const cv::Point& a = pattern_.x[j];
    const cv::Point& b = pattern_.y[j];
    if (centre[a.y * step + a.x] < centre[b.y * step + b.x]) d[j / 64] |= uint64_t{1} << (j % 64);
  }
  return d;
}

FeatureFrame FeatureExtractor::extract(const cv::Mat& gray) {
  if (gray.empty() || gray.type() != CV_8UC1) throw std::invalid_argument("features: expected an 8-bit gray image");
  const FeatureParams& p = params_;
  FeatureFrame out;
  out.roi = region_of_interest(p, gray.size());
  if (out.roi.width < p.buckets_x * 8 || out.roi.height < p.buckets_y * 8)
    throw std::invalid_argument("features: image " + std::to_string(gray.cols) + "x" + std::to_string(gray.rows) +
                                " is too small for the margins and " + std::to_string(p.buckets_x) + "x" +
                                std::to_string(p.buckets_y) + " buckets");
  if (p.smoothing_sigma > 0)
    cv::GaussianBlur(gray, smoothed_, cv::Size(0, 0), p.smoothing_sigma);
  else
    smoothed_ = gray;

  out.per_bucket.assign(static_cast<size_t>(p.buckets_x) * p.buckets_y, 0);
  std::vector<cv::KeyPoint> kps, inside;
  std::vector<cv::Point2f> corners;
  const cv::Rect image(0, 0, gray.cols, gray.rows);
  for (int by = 0; by < p.buckets_y; ++by)
    for (int bx = 0; bx < p.buckets_x; ++bx) {
      const cv::Rect b = bucket_rect(p, gray.size(), bx, by);
      // FAST needs 3 pixels around a candidate: detect on the bucket grown by 3, keep the inside.
      const cv::Rect grown = cv::Rect(b.x - 3, b.y - 3, b.width + 6, b.height + 6) & image;
      for (int thr = p.fast_threshold;; thr = std::max(p.min_fast_threshold, thr / 2)) {
        kps.clear();
        cv::FAST(smoothed_(grown), kps, thr, true);
        inside.clear();
        for (auto& k : kps) {
          k.pt += cv::Point2f(static_cast<float>(grown.x), static_cast<float>(grown.y));
          if (b.contains(cv::Point(cvRound(k.pt.x), cvRound(k.pt.y)))) inside.push_back(k);
        }
        // Too few corners (a weakly textured bucket): retry with a lower threshold.
        if (static_cast<int>(inside.size()) >= p.max_per_bucket / 2 || thr == p.min_fast_threshold) break;
      }
      cv::KeyPointsFilter::retainBest(inside, p.max_per_bucket);
      if (static_cast<int>(inside.size()) > p.max_per_bucket) inside.resize(p.max_per_bucket);  // ties
      const int bucket = by * p.buckets_x + bx;
      if (p.subpixel && !inside.empty()) {
        // FAST corners are whole pixels; the corner refinement (Foerstner, cv::cornerSubPix)
        // moves each to the sub-pixel saddle point, which the matches then share.
        corners.clear();
        for (const auto& k : inside) corners.push_back(k.pt);
        cv::cornerSubPix(smoothed_, corners, cv::Size(2, 2), cv::Size(-1, -1),
                         cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 10, 0.01));
        for (size_t i = 0; i < inside.size(); ++i)
          if (cv::norm(corners[i] - inside[i].pt) < 1.0) inside[i].pt = corners[i];
      }
      for (const auto& k : inside) {
        Feature f;
        f.pt = k.pt;
        f.response = k.response;
        f.bucket = bucket;
        f.desc = describe(smoothed_, cv::Point(cvRound(k.pt.x), cvRound(k.pt.y)));
        out.features.push_back(f);
      }
      out.per_bucket[bucket] = static_cast<int>(inside.size());
    }
  return out;
}

std::vector<Match> match_features(const std::vector<Feature>& prev, const std::vector<Feature>& cur, int words,
                                  const MatchParams& params, const std::vector<cv::Point2f>* predicted) {
  if (predicted && predicted->size() != prev.size())
    throw std::invalid_argument("match_features: one predicted position per previous feature expected");
  std::vector<Match> out;
  if (prev.empty() || cur.empty()) return out;
  // Grid of current features, cells of the search radius.
  const float cell = static_cast<float>(std::max(8.0, params.search_radius));
  float maxx = 0, maxy = 0;
  for (const auto& f : cur) {
    maxx = std::max(maxx, f.pt.x);
    maxy = std::max(maxy, f.pt.y);
  }
  const int gw = static_cast<int>(maxx / cell) + 1, gh = static_cast<int>(maxy / cell) + 1;
  std::vector<std::vector<int>> grid(static_cast<size_t>(gw) * gh);
  for (int j = 0; j < static_cast<int>(cur.size()); ++j)
    grid[static_cast<int>(cur[j].pt.y / cell) * gw + static_cast<int>(cur[j].pt.x / cell)].push_back(j);

  constexpr int kNone = 1 << 20;
  std::vector<int> best_i(prev.size(), kNone), second_i(prev.size(), kNone), arg_i(prev.size(), -1);
  std::vector<int> best_j(cur.size(), kNone), arg_j(cur.size(), -1);
  const float r2 = static_cast<float>(params.search_radius * params.search_radius);
  for (int i = 0; i < static_cast<int>(prev.size()); ++i) {
    const cv::Point2f at = predicted ? (*predicted)[i] : prev[i].pt;
    const int cx = static_cast<int>(std::floor(at.x / cell)), cy = static_cast<int>(std::floor(at.y / cell));
    for (int gy = std::max(0, cy - 1); gy <= std::min(gh - 1, cy + 1); ++gy)
      for (int gx = std::max(0, cx - 1); gx <= std::min(gw - 1, cx + 1); ++gx)
        for (int j : grid[gy * gw + gx]) {
          const cv::Point2f dv = cur[j].pt - at;
          if (dv.dot(dv) > r2) continue;
          const int dist = hamming(prev[i].desc, cur[j].desc, words);
          if (dist < best_i[i]) {
            second_i[i] = best_i[i];
            best_i[i] = dist;
            arg_i[i] = j;
          } else if (dist < second_i[i]) {
            second_i[i] = dist;
          }
          if (dist < best_j[j]) {
            best_j[j] = dist;
            arg_j[j] = i;
          }
        }
  }
  for (int i = 0; i < static_cast<int>(prev.size()); ++i) {
    const int j = arg_i[i];
    if (j < 0 || best_i[i] > params.max_distance) continue;
    if (params.mutual && arg_j[j] != i) continue;
    if (params.ratio > 0 && second_i[i] < kNone && best_i[i] >= params.ratio * second_i[i]) continue;
    out.push_back({i, j, best_i[i]});
  }
  return out;
}

}  // namespace aerie::stereo
