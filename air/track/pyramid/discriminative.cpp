#include "air/track/pyramid/discriminative.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "air/track/pyramid/flow_scale.hpp"
#include "air/track/pyramid/pyramid.hpp"

namespace aerie::track {
namespace {

cv::Point top_left(const cv::Point2d& centre, const cv::Size2d& box) {
  return {static_cast<int>(std::lround(centre.x - box.width / 2)), static_cast<int>(std::lround(centre.y - box.height / 2))};
}

cv::Point2d centre_of(const cv::Point& tl, const cv::Size2d& box) { return {tl.x + box.width / 2, tl.y + box.height / 2}; }

// True when the box region of a BGR frame has colour (not grey stored as three channels).
bool has_colour(const cv::Mat& frame, const cv::Rect2d& box) {
  if (frame.channels() != 3) return false;
  const cv::Mat roi = frame(cv::Rect(box) & cv::Rect(0, 0, frame.cols, frame.rows));
  cv::Mat planes[3], d1, d2;
  cv::split(roi, planes);
  cv::absdiff(planes[0], planes[1], d1);
  cv::absdiff(planes[1], planes[2], d2);
  return cv::mean(d1)[0] + cv::mean(d2)[0] > 2.0;
}

// Keeps a top-left position where a footprint-sized box fits inside bounds (when it can).
cv::Point clamp_into(cv::Point tl, cv::Size footprint, const cv::Rect& bounds) {
  tl.x = std::clamp(tl.x, bounds.x, std::max(bounds.x, bounds.x + bounds.width - footprint.width));
  tl.y = std::clamp(tl.y, bounds.y, std::max(bounds.y, bounds.y + bounds.height - footprint.height));
  return tl;
}

// (best - median) / terms: how far the best sample stands out of the searched region.
double prominence(std::vector<float> scores, int terms) {
  const float best = *std::max_element(scores.begin(), scores.end());
  std::nth_element(scores.begin(), scores.begin() + scores.size() / 2, scores.end());
  return (best - scores[scores.size() / 2]) / std::max(1, terms);
}

}  // namespace

DiscriminativeTracker::DiscriminativeTracker(std::string name, DiscriminativeParams params, ClassifierFactory factory,
                                             uint64_t seed)
    : name_(std::move(name)), params_(std::move(params)), factory_(std::move(factory)), rng_(seed), seed_(seed) {
  const auto& p = params_;
  auto require = [&](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument(name_ + ": parameter " + what);
  };
  require(p.max_levels >= 1 && p.max_levels <= 6, "max_levels must be in [1, 6]");
  require(p.min_size >= 2, "min_size must be >= 2 pixels");
  require(p.search_radius >= 1 && p.coarse_radius >= 1, "search_radius and coarse_radius must be >= 1");
  require(p.pos_radius > 0 && p.pos_radius < p.neg_inner && p.neg_inner < p.neg_outer,
          "radii must satisfy 0 < pos_radius < neg_inner < neg_outer");
  require(p.neg_count >= 1, "neg_count must be >= 1");
  require(!p.reject_ratio.empty(), "reject_ratio needs at least one value");
  for (double r : p.reject_ratio) require(r >= 0 && r < 1, "reject_ratio values must be in [0, 1)");
  require(p.min_radius >= 1 && p.max_radius >= p.min_radius, "need 1 <= min_radius <= max_radius");
  require(p.scale_estimation == "none" || p.scale_estimation == "classifier" || p.scale_estimation == "flow" ||
              p.scale_estimation == "hybrid",
          "scale_estimation must be none, flow, classifier or hybrid");
  require(p.scale_step > 1 && p.max_scale_change > 1, "scale_step and max_scale_change must be > 1");
  require(p.min_scale > 0 && p.max_scale > p.min_scale, "need 0 < min_scale < max_scale");
  require(p.lost_frames >= 1 && p.redetect_stride >= 1, "lost_frames and redetect_stride must be >= 1");
  require(p.redetect_radius >= 0, "redetect_radius must be >= 0");
  require(p.update_confidence >= 0 && p.update_confidence <= 1 && p.found_confidence >= 0 && p.found_confidence <= 1,
          "update_confidence and found_confidence must be in [0, 1]");
  require(p.confidence_rate > 0 && p.confidence_rate <= 1, "confidence_rate must be in (0, 1]");
  if (!factory_) throw std::invalid_argument(name_ + ": no classifier factory");
}

double DiscriminativeTracker::largest_scale() const {
  // The sample boxes must fit into the frame: a target that grows past it keeps the largest
  // scale that fits (e.g. the helipad at the end of a descent).
  const cv::Size2d t = levels_[0].template_size;
  return std::min(params_.max_scale,
                  0.95 * std::min((frame_size_.width - 2) / t.width, (frame_size_.height - 2) / t.height));
}

void DiscriminativeTracker::init(const cv::Mat& frame, const cv::Rect2d& box) {
  validate_init(frame, box);
  const cv::Mat gray = to_gray(frame);
  frame_size_ = frame.size();
  init_size_ = box.size();
  centre_ = {box.x + box.width / 2, box.y + box.height / 2};
  scale_ = 1;
  lost_ = false;
  lost_count_ = 0;
  low_frames_ = 0;
  mean_prominence_ = 0;
  scored_frames_ = 0;
  rng_.seed(seed_);

  channels_ = parse_channels(params_.channels);
  if (frame.channels() == 1 || !has_colour(frame, box))  // no colour features for grey content
    channels_.erase(std::remove_if(channels_.begin(), channels_.end(), [](int c) { return c >= kChromaCr; }),
                    channels_.end());
  if (channels_.empty()) channels_ = {kGray};
  // eq. 3.23, capped; every level's template must stay at least 4x4 pixels.
  int n = std::min(params_.max_levels, pyramid::num_levels(box.width, box.height, params_.min_size));
  while (n > 1 && std::min(box.width, box.height) / (1 << (n - 1)) < 4) --n;
  levels_.clear();
  trusted_.clear();
  levels_.resize(n);
  for (int p = 0; p < n; ++p) {
    const double f = 1.0 / (1 << p);
    levels_[p].template_size = {std::max(4, static_cast<int>(std::lround(box.width * f))),
                                std::max(4, static_cast<int>(std::lround(box.height * f)))};
    levels_[p].classifier = factory_(levels_[p].template_size, channels_, rng_);
  }
  build_pyramid(frame, gray, {0, 0, gray.cols, gray.rows});
  learn();
  gray.copyTo(previous_gray_);
}

void DiscriminativeTracker::build_pyramid(const cv::Mat& frame, const cv::Mat& gray, const cv::Rect& roi) {
  // Align the crop to the coarsest level's grid so that level p sees exactly crop / 2^p.
  const int a = 1 << (levels() - 1);
  cv::Rect r = roi & cv::Rect(0, 0, gray.cols, gray.rows);
  const int x0 = r.x / a * a, y0 = r.y / a * a;
  r = cv::Rect(x0, y0, r.x + r.width - x0, r.y + r.height - y0);
  const bool colour = std::any_of(channels_.begin(), channels_.end(), [](int c) { return c >= kChromaCr; });
  cv::Mat img = gray(r), chroma;
  if (colour) {
    cv::Mat ycrcb;
    cv::cvtColor(frame(r), ycrcb, cv::COLOR_BGR2YCrCb);
    cv::mixChannels(ycrcb, chroma = cv::Mat(r.size(), CV_8UC2), std::vector<int>{1, 0, 2, 1});
  }
  auto halve = [](const cv::Mat& m) {
    cv::Mat half;
    const cv::Mat even = m(cv::Rect(0, 0, m.cols & ~1, m.rows & ~1));
    cv::resize(even, half, cv::Size(even.cols / 2, even.rows / 2), 0, 0, cv::INTER_AREA);  // 2x2 mean
    return half;
  };
  for (int p = 0; p < levels(); ++p) {
    if (p > 0) {
      img = halve(img);
      if (colour) chroma = halve(chroma);
    }
    levels_[p].ch.compute(img, chroma, channels_, cv::Point(x0 >> p, y0 >> p));
  }
}

DiscriminativeTracker::Search DiscriminativeTracker::search(bool scan) {
  Search out;
  const int top = levels() - 1;
  cv::Point2d c = centre_ * (1.0 / (1 << top));  // eq. 3.13: previous frame's location at the coarsest level
  double radius = top == 0 ? params_.search_radius : params_.coarse_radius;
  std::vector<float> scores;
  for (int p = top; p >= 0; --p) {
    Level& L = levels_[p];
    const cv::Size2d box = cv::Size2d(L.template_size) * scale_;
    const cv::Size fp = L.classifier->footprint(scale_);
    const cv::Rect bounds = L.ch.roi();
    if (scan && p == top) {  // re-detection: a grid over the whole level, then refine below
      const int stride = std::max(1, params_.redetect_stride >> top);  // full-resolution pixels -> level
      const SampleSet grid = grid_samples(fp, bounds, stride);
      if (!grid.empty()) {
        L.classifier->score(L.ch, grid, scale_, scores);
        const size_t b = std::max_element(scores.begin(), scores.end()) - scores.begin();
        c = centre_of(grid.positions()[b], box);
        radius = std::max(radius, stride + 0.5);  // the usual disc around the best grid sample
        LevelStats scan_stats;
        scan_stats.level = p;
        scan_stats.evaluated = static_cast<int>(grid.size());
        scan_stats.search_radius = 0;
        out.levels.push_back(scan_stats);
      }
    }
    const SampleSet samples = disc_samples(clamp_into(top_left(c, box), fp, bounds), radius, fp, bounds);
    if (samples.empty()) {  // the box does not fit into the searched region: no estimate
      out.ok = false;
      return out;
    }
    L.classifier->score(L.ch, samples, scale_, scores);
    const size_t n = scores.size();
    const size_t best = std::max_element(scores.begin(), scores.end()) - scores.begin();
    const cv::Point l = samples.positions()[best];

    LevelStats st;
    st.level = p;
    st.evaluated = static_cast<int>(n);
    st.search_radius = static_cast<float>(radius);
    st.samples.reserve(n);
    for (const auto& q : samples.positions()) st.samples.emplace_back(centre_of(q, box) * static_cast<double>(1 << p));
    st.scores = scores;

    c = centre_of(l, box);
    if (p == top) out.prominence = prominence(scores, L.classifier->terms());  // same disc as when tracking
    if (p > 0) {
      // eq. 3.25: reject the xi^p N_S lowest-scoring samples; the best rejected one is the
      // critical sample and its distance to l^p the critical distance CD^p.
      const auto& xi = params_.reject_ratio;
      const double ratio = xi[std::min<size_t>(p - 1, xi.size() - 1)];
      const size_t rejected = static_cast<size_t>(std::floor(ratio * static_cast<double>(n)));
      double cd = radius;
      if (rejected >= 1 && rejected < n) {
        std::vector<size_t> order(n);
        std::iota(order.begin(), order.end(), size_t{0});
        std::nth_element(order.begin(), order.begin() + (rejected - 1), order.end(),
                         [&](size_t i, size_t j) { return scores[i] < scores[j]; });
        const cv::Point cs = samples.positions()[order[rejected - 1]];
        cd = std::hypot(cs.x - l.x, cs.y - l.y);
      }
      st.rejected = static_cast<int>(rejected);
      radius = std::clamp(pyramid::next_search_range(cd), params_.min_radius, params_.max_radius);  // eq. 3.26
      c *= 2.0;  // eq. 3.24
    } else {
      out.score = scores[best];
    }
    out.levels.push_back(std::move(st));
  }
  out.centre = c;
  return out;
}

double DiscriminativeTracker::adapt_scale(const cv::Point2d& centre, const std::vector<double>& candidates) {
  // Re-score the best location at s / rho and s * rho (with a 1-pixel neighbourhood);
  // the scale of the highest score wins.
  Level& L = levels_[0];
  std::vector<float> scores;
  double best_scale = scale_;
  float best_score = -std::numeric_limits<float>::infinity();
  cv::Point2d best_centre = centre;
  for (double s : candidates) {
    if (s < params_.min_scale || s > largest_scale()) continue;
    const cv::Size2d box = cv::Size2d(L.template_size) * s;
    const cv::Size fp = L.classifier->footprint(s);
    const SampleSet samples = disc_samples(top_left(centre, box), 1.5, fp, L.ch.roi());
    if (samples.empty()) continue;
    L.classifier->score(L.ch, samples, s, scores);
    const size_t b = std::max_element(scores.begin(), scores.end()) - scores.begin();
    if (scores[b] > best_score) {
      best_score = scores[b];
      best_scale = s;
      best_centre = centre_of(samples.positions()[b], box);
    }
  }
  scale_ = best_scale;
  centre_ = best_centre;
  return best_score;
}

void DiscriminativeTracker::learn() {
  // Algorithm 1, steps 3-4, at every level around the current location.
  for (int p = 0; p < levels(); ++p) {
    Level& L = levels_[p];
    const double f = 1.0 / (1 << p);
    const double beta = std::max(params_.pos_radius * f, params_.min_pos_radius);
    const double gamma = std::max(params_.neg_inner * f, beta + 1);
    const double delta = std::max(params_.neg_outer * f, gamma + 2);
    const cv::Size2d box = cv::Size2d(L.template_size) * scale_;
    const cv::Size fp = L.classifier->footprint(scale_);
    const cv::Point tl = top_left(centre_ * f, box);
    const SampleSet pos = disc_samples(tl, beta, fp, L.ch.roi());
    const SampleSet neg = ring_samples(tl, gamma, delta, params_.neg_count, fp, L.ch.roi(), rng_);
    if (pos.empty() || neg.empty()) continue;  // target (partly) outside the image: keep the model
    L.classifier->update(L.ch, pos, neg, scale_);
  }
}

TrackState DiscriminativeTracker::update(const cv::Mat& frame) {
  if (levels_.empty()) throw std::invalid_argument(name_ + ": update() before init()");
  validate_update(name_, frame, frame_size_);
  const cv::Mat gray = to_gray(frame);

  TrackState state;
  state.initial_size = init_size_;
  scale_ = std::min(scale_, largest_scale());
  // Scale candidates for the classifier to choose from (the first is searched).
  std::vector<double> scales = {scale_};
  const bool flow_scale_on = params_.scale_estimation == "flow" || params_.scale_estimation == "hybrid";
  const bool flow = flow_scale_on || params_.flow_prediction;
  if (params_.scale_estimation == "classifier") {
    scales.push_back(scale_ / params_.scale_step);
    scales.push_back(scale_ * params_.scale_step);
  }
  if (flow && !lost_) {
    const cv::Size2d size = init_size_ * scale_;
    const FlowScale f = flow_scale(previous_gray_, gray,
                                   {centre_.x - size.width / 2, centre_.y - size.height / 2, size.width, size.height});
    if (f.ok && flow_scale_on) {
      const double s = std::clamp(scale_ * std::clamp(f.ratio, 1 / params_.max_scale_change, params_.max_scale_change),
                                  params_.min_scale, largest_scale());
      if (params_.scale_estimation == "flow") scales[0] = scale_ = s; else scales.push_back(s);
    }
    if (f.ok && params_.flow_prediction) {
      centre_ += f.shift;
      centre_.x = std::clamp(centre_.x, 0.0, frame_size_.width - 1.0);
      centre_.y = std::clamp(centre_.y, 0.0, frame_size_.height - 1.0);
    }
  }
  if (flow) gray.copyTo(previous_gray_);
  // Region that the search, the scale candidates and the training samples can reach; while
  // lost, the re-detection scan region (the whole frame, or redetect_radius doubled per lost frame).
  const int top = levels() - 1;
  const double radius = top == 0 ? params_.search_radius
                                 : std::max(params_.coarse_radius * (1 << top), params_.max_radius * (1 << (top - 1)));
  double reach = radius + params_.neg_outer + (2 << top) + 2;
  if (lost_) {
    reach = params_.redetect_radius > 0 ? reach + params_.redetect_radius * std::pow(2.0, std::min(lost_count_, 16))
                                        : frame_size_.width + frame_size_.height;
    ++lost_count_;
  }
  const cv::Size2d half = init_size_ * (scale_ * params_.scale_step / 2);
  build_pyramid(frame, gray, cv::Rect(cv::Point(static_cast<int>(centre_.x - half.width - reach),
                                         static_cast<int>(centre_.y - half.height - reach)),
                               cv::Point(static_cast<int>(std::ceil(centre_.x + half.width + reach)),
                                         static_cast<int>(std::ceil(centre_.y + half.height + reach)))));
  // While lost, the target is still searched around its last location (an uncertain
  // stretch is often the target itself changing) and the scan proposes a re-detection.
  Search s = search(false);
  Search scan;
  scan.ok = false;
  if (lost_) scan = search(true);
  state.levels = std::move(s.levels);
  if (lost_) state.levels.insert(state.levels.end(), scan.levels.begin(), scan.levels.end());
  if (!s.ok && !scan.ok) {
    state.pose = {centre_.x, centre_.y, scale_, 0.0};
    state.lost = true;
    return state;
  }
  // Confidence: the prominence of the best sample relative to its running mean while tracking well.
  auto confidence = [&](const Search& r) {
    return scored_frames_ == 0 ? 1.0 : std::clamp(r.prominence / std::max(mean_prominence_, 1e-6), 0.0, 1.0);
  };
  double z = s.prominence, conf = s.ok ? confidence(s) : 0.0;
  auto confident_frame = [&] {
    const double rate = std::max(params_.confidence_rate, 1.0 / ++scored_frames_);
    mean_prominence_ += rate * (z - mean_prominence_);
    learn();
    if (params_.redetection && conf >= params_.found_confidence) {
      std::vector<std::unique_ptr<SampleClassifier>> models;
      for (const auto& level : levels_) models.push_back(level.classifier->clone());
      trusted_.push_back(std::move(models));
      if (trusted_.size() > 2) trusted_.pop_front();
    }
  };
  // Without confident frames the reference drifts slowly towards what is seen, so that a
  // lasting change of appearance ends the freeze (and a loss) instead of making it permanent.
  auto drift = [&] { mean_prominence_ += 0.25 * params_.confidence_rate * (z - mean_prominence_); };

  if (!lost_) {
    centre_ = s.centre;
    if (scales.size() > 1) adapt_scale(s.centre, scales);
    // Hysteresis: once below update_confidence, learning resumes only at found_confidence.
    const bool uncertain = low_frames_ > 0 ? conf < params_.found_confidence : conf < params_.update_confidence;
    low_frames_ = uncertain ? low_frames_ + 1 : 0;
    if (low_frames_ == 0) {
      confident_frame();
    } else {
      drift();
      if (params_.redetection && low_frames_ >= params_.lost_frames) {
        lost_ = true;
        lost_count_ = 0;
        // Frames between update_confidence and found_confidence were still learned; the
        // loss says they were the background: search with a trusted model.
        if (!trusted_.empty())
          for (size_t p = 0; p < levels_.size(); ++p) levels_[p].classifier = trusted_.front()[p]->clone();
      }
    }
  } else {
    // A re-detection elsewhere must score above the local search and reach found_confidence.
    const double conf_scan = scan.ok ? confidence(scan) : 0.0;
    const bool redetected = conf_scan >= params_.found_confidence && (!s.ok || scan.score > s.score);
    if (redetected) {
      z = scan.prominence;
      conf = conf_scan;
      state.redetected = true;
    }
    if (s.ok || redetected) centre_ = redetected ? scan.centre : s.centre;
    if (redetected || conf >= params_.found_confidence) {  // found again
      lost_ = false;
      low_frames_ = 0;
      confident_frame();
    } else {
      drift();
    }
  }
  state.pose = {centre_.x, centre_.y, scale_, 0.0};
  state.confidence = conf;
  state.lost = lost_;
  return state;
}

}  // namespace aerie::track
