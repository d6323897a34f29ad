#pragma once
// The discriminative tracker of Algorithm 1 (tracking-by-detection) inside the adaptive
// multi-classifier multi-resolution framework of thesis 3.2.2 / 3.3.1 (AMCMR-CT, AM3):
//
//  * one adaptive classifier C^p per pyramid level (image halved per level), N_PL levels (eq. 3.23);
//  * the coarsest level searches the integer offsets inside its radius (Table 3.1);
//  * the best sample l^p is propagated to the next finer level as 2 l^p (eq. 3.24);
//  * each level rejects the xi^p N_S lowest-scoring samples (eq. 3.25); the best of them is the
//    critical sample, and twice its distance to l^p (the critical distance) is the next
//    level's search radius (eq. 3.26);
//  * after the search, every level's classifier is updated with positives inside beta and
//    negatives in the gamma..delta ring around the new location (Algorithm 1, steps 3-4).
//
// With one level it is the single-resolution tracker (CT, MIL). Two additions the thesis
// names as the way forward are built in and can be switched off: scale adaptation (the
// final location is re-scored at scales s / rho, s, s * rho) and re-detection after loss
// (low confidence for some frames freezes the classifiers and scans the whole coarsest
// level until the target scores high again).
#include <functional>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "air/track/features/channels.hpp"
#include "air/track/features/random.hpp"
#include "air/track/features/samples.hpp"
#include "air/track/tracker.hpp"

namespace aerie::track {

// One adaptive classifier C^p: its own features, made for the template size of its level.
class SampleClassifier {
 public:
  virtual ~SampleClassifier() = default;
  // Box that every sample's features stay inside, at the given scale of the template.
  virtual cv::Size footprint(double scale) const = 0;
  // Classifier score of every sample (higher = more target-like), features scaled by `scale`.
  virtual void score(const ChannelImages& ch, const SampleSet& samples, double scale, std::vector<float>& out) = 0;
  // Online update with positive and negative samples (the first call initialises).
  virtual void update(const ChannelImages& ch, const SampleSet& positives, const SampleSet& negatives,
                      double scale) = 0;
  // Number of weak terms summed into a score (features of CT, selected weak classifiers of MIL);
  // score / terms is the mean log-likelihood ratio per term, comparable between classifiers.
  virtual int terms() const = 0;
  // A copy of the learned model (restored when a loss shows that the last updates learned
  // the background).
  virtual std::unique_ptr<SampleClassifier> clone() const = 0;
};

// Makes the classifier of one level for a template of the given size (pixels of that level)
// whose features may use the given channels.
using ClassifierFactory =
    std::function<std::unique_ptr<SampleClassifier>(cv::Size template_size, const std::vector<int>& channels, Rng& rng)>;

struct DiscriminativeParams {
  // Feature channels: gray, gradient, color (colour is used only for colour frames).
  std::vector<std::string> channels = {"gray", "gradient"};
  // Pyramid (eq. 3.23): N_PL = min(max_levels, floor(log2(min(T_W, T_H) / min_size))), at least 1.
  int max_levels = 1;
  double min_size = 3.5;
  // Algorithm 1 radii, in full-resolution pixels; level p uses them divided by 2^p.
  double search_radius = 20;  // alpha with one level: test samples strictly inside it (Table 3.1)
  double coarse_radius = 5;   // alpha at the coarsest level when there are several, pixels of that level
  double pos_radius = 2.5;    // beta: positives strictly inside it
  double neg_inner = 8;       // gamma
  double neg_outer = 30;      // delta
  int neg_count = 50;         // negatives drawn from the ring
  double min_pos_radius = 1.5;  // floor of beta / 2^p, so that coarse levels keep a few positives
  // Multi-resolution rejection (eqs. 3.25, 3.26).
  std::vector<double> reject_ratio = {0.9};  // xi^p for p = 1, 2, ... (last value repeats)
  double min_radius = 2.5;  // clamp of alpha^(p-1) = 2 CD^p, level pixels
  double max_radius = 12;
  // Scale adaptation: "none", "flow" (Median Flow scale change of points in the box),
  // "classifier" (the final location re-scored at s / rho and s * rho, the best scale wins) or
  // "hybrid" (the classifier chooses between the current scale and the flow's).
  std::string scale_estimation = "flow";
  double scale_step = 1.05;      // rho
  double max_scale_change = 1.1; // per frame, flow
  double min_scale = 0.2, max_scale = 5;
  // Motion prediction: the search is centred on the previous location moved by the median
  // flow of the points in the box (the same Lucas-Kanade points as the flow scale), so that
  // fast motion stays inside the search radius; the classifier still decides.
  bool flow_prediction = true;
  // Occlusion, loss and re-detection. The confidence of a frame is the prominence of its best
  // sample over the coarsest level's search (best minus median score, per term) relative to the
  // running mean of that prominence over the frames tracked with confidence.
  double update_confidence = 0.5;  // below it the classifiers are not updated (occlusion, clutter)
  double confidence_rate = 0.05;   // weight of a new frame in the running mean
  bool redetection = false;        // off by default: it lowered the mean AUC (docs/results/track.md)
  int lost_frames = 3;             // frames in a row below update_confidence -> lost
  double found_confidence = 0.7;   // a re-detection scan result at least this -> re-detected
  int redetect_stride = 8;         // grid step of the scan, full-resolution pixels
  double redetect_radius = 0;      // > 0: scan only this far (px) around the last location, doubled
                                   // every lost frame; 0: the whole frame
};

class DiscriminativeTracker : public Tracker {
 public:
  DiscriminativeTracker(std::string name, DiscriminativeParams params, ClassifierFactory factory, uint64_t seed);

  std::string name() const override { return name_; }
  void init(const cv::Mat& frame, const cv::Rect2d& box) override;
  TrackState update(const cv::Mat& frame) override;

  int levels() const { return static_cast<int>(levels_.size()); }
  const DiscriminativeParams& params() const { return params_; }

  // The multi-resolution search of one frame over given level images (exposed for tests):
  // returns the best sample centre at level 0 (full-resolution pixels) and fills stats.
  struct Search {
    bool ok = true;  // false when no sample fits into the image
    cv::Point2d centre;
    float score = 0;        // best score at level 0
    double prominence = 0;  // (best - median) score per term over the coarsest level's search
    std::vector<LevelStats> levels;  // coarsest first
  };

 private:
  struct Level {
    std::unique_ptr<SampleClassifier> classifier;
    cv::Size template_size;  // target box at scale 1, pixels of this level
    ChannelImages ch;
  };

  void build_pyramid(const cv::Mat& frame, const cv::Mat& gray, const cv::Rect& roi0);
  double largest_scale() const;
  Search search(bool scan);
  double adapt_scale(const cv::Point2d& centre, const std::vector<double>& candidates);
  void learn();

  std::string name_;
  DiscriminativeParams params_;
  ClassifierFactory factory_;
  Rng rng_;
  uint64_t seed_;
  std::vector<Level> levels_;
  std::vector<int> channels_;
  cv::Size frame_size_;
  cv::Size2d init_size_;
  cv::Point2d centre_;  // target centre, full-resolution pixels
  double scale_ = 1;
  bool lost_ = false;
  int low_frames_ = 0;
  // With redetection: every level's classifier as of the last two frames at found_confidence
  // (oldest first). A loss restores the older one: the frame just before an uncertain
  // stretch may already have learned the background.
  std::deque<std::vector<std::unique_ptr<SampleClassifier>>> trusted_;
  int lost_count_ = 0;  // frames since the target was lost
  double mean_prominence_ = 0;  // running mean of Search::prominence on confident frames
  int scored_frames_ = 0;
  cv::Mat previous_gray_;
};

}  // namespace aerie::track
