#pragma once
// Image samples of Algorithm 1 (thesis 3.2.1): boxes of the target size at integer
// top-left positions. A SampleSet keeps them as runs of consecutive x on one row, so
// feature sums over the integral image vectorise along x.
#include <opencv2/core.hpp>
#include <vector>

#include "air/track/features/random.hpp"

namespace aerie::track {

struct SampleRun {
  int x = 0, y = 0;  // top-left of the first box of the run
  int count = 0;     // boxes at x, x+1, ..., x+count-1
};

class SampleSet {
 public:
  // Appends the box with top-left (x, y); extends the last run when contiguous.
  void add(int x, int y);
  void clear() {
    runs_.clear();
    positions_.clear();
  }
  size_t size() const { return positions_.size(); }
  bool empty() const { return positions_.empty(); }
  const std::vector<SampleRun>& runs() const { return runs_; }
  const std::vector<cv::Point>& positions() const { return positions_; }  // top-left of each box, in order

 private:
  std::vector<SampleRun> runs_;
  std::vector<cv::Point> positions_;
};

// S^alpha of Algorithm 1: the box at `origin` shifted by every integer offset strictly
// inside `radius` (Table 3.1 counts), keeping only boxes of size `box` that lie inside
// `bounds`. Row-major order of the offsets.
SampleSet disc_samples(cv::Point origin, double radius, cv::Size box, const cv::Rect& bounds);

// S^{gamma,delta} of Algorithm 1: up to `max_count` offsets with inner < |d| < outer,
// drawn without replacement, boxes inside `bounds`. Sorted row-major.
SampleSet ring_samples(cv::Point origin, double inner, double outer, int max_count, cv::Size box,
                       const cv::Rect& bounds, Rng& rng);

// Every `stride`-th position of the boxes inside `bounds` (the re-detection scan).
SampleSet grid_samples(cv::Size box, const cv::Rect& bounds, int stride);

}  // namespace aerie::track
