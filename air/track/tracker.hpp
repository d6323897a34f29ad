#pragma once
// The interface every Aerie tracker implements: init(frame, box), update(frame) -> state.
// State is the similarity (x, y, s, theta) of the target template with its box corners,
// a confidence and, per pyramid level, how many samples/particles were evaluated and
// rejected. All randomness comes from the seed given at construction.
#include <array>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace aerie::track {

struct Similarity {
  double x = 0, y = 0;   // target centre, pixels
  double scale = 1;      // relative to the initial box
  double theta = 0;      // rotation, radians (image x towards y)
};

struct LevelStats {
  int level = 0;               // 0 = finest (full resolution)
  int evaluated = 0;           // samples / particles scored at this level
  int rejected = 0;            // of which rejected at this level (eqs. 3.14, 3.25)
  float search_radius = 0;     // pixels at this level's resolution
  std::vector<cv::Point2f> samples;  // evaluated positions in full-resolution pixels (for display)
  std::vector<float> scores;
};

struct TrackState {
  Similarity pose;
  cv::Size2d initial_size;     // width, height of the init box
  double confidence = 0;       // 0..1
  bool lost = false;           // true when the tracker believes the target is lost
  bool redetected = false;     // true on the frame the target was recovered after a loss
  std::vector<LevelStats> levels;

  cv::Size2d size() const { return initial_size * pose.scale; }
  // Rotated box corners: top-left, top-right, bottom-right, bottom-left.
  std::array<cv::Point2d, 4> corners() const;
  // Axis-aligned box of the (unrotated) target at the current scale, OTB style x,y,w,h.
  cv::Rect2d box() const;
  int samples_evaluated() const;
};

class Tracker {
 public:
  virtual ~Tracker() = default;
  virtual std::string name() const = 0;
  // frame: 8-bit gray or BGR. Throws std::invalid_argument for an empty frame or a box that
  // is empty, not finite, or not inside the image (validate_init).
  virtual void init(const cv::Mat& frame, const cv::Rect2d& box) = 0;
  // Throws std::invalid_argument for an empty frame, a frame of a different size than at
  // init, or when called before init.
  virtual TrackState update(const cv::Mat& frame) = 0;
};

// The checks every init() starts with; throws std::invalid_argument naming the problem.
void validate_init(const cv::Mat& frame, const cv::Rect2d& box);
// The checks every update() starts with: a non-empty 8-bit gray or BGR frame of the size seen
// at init; throws std::invalid_argument starting with the tracker's name.
void validate_update(const std::string& tracker, const cv::Mat& frame, cv::Size init_size);
// 8-bit single-channel view or conversion of an 8-bit gray/BGR frame.
cv::Mat to_gray(const cv::Mat& frame);

}  // namespace aerie::track
