#pragma once
// The tracker's LOST flag scored like a detector of target loss. The target is lost on the
// frames where the ground truth says it is absent (no valid box, e.g. a NaN row) or where the
// predicted box does not overlap it (IoU = 0); a lost episode is a maximal run of such frames.
// Frame 1 (the initialisation) belongs to no episode and is never scored.
#include <cmath>
#include <opencv2/core.hpp>
#include <vector>

namespace aerie::track::eval {

struct LostScore {
  int episodes = 0;          // lost episodes
  int flagged = 0;           // of which state.lost on at least one of the episode's first `within` frames
  int frames_iou_gt_05 = 0;  // frames with IoU > 0.5 (the target is clearly tracked)
  int false_alarms = 0;      // of which state.lost
  // NaN when there is nothing to divide by.
  double recall() const { return episodes > 0 ? static_cast<double>(flagged) / episodes : NAN; }
  double false_alarm_rate() const {
    return frames_iou_gt_05 > 0 ? static_cast<double>(false_alarms) / frames_iou_gt_05 : NAN;
  }
  // Pooling over sequences adds the counts (not the ratios).
  LostScore& operator+=(const LostScore& o);
};

// lost_flags[i], predicted[i] and groundtruth[i] belong to frame i (frame 0 = the init frame);
// sizes must match and within >= 1. An episode shorter than `within` counts with the frames it has.
LostScore lost_detection(const std::vector<bool>& lost_flags, const std::vector<cv::Rect2d>& predicted,
                         const std::vector<cv::Rect2d>& groundtruth, int within = 5);

}  // namespace aerie::track::eval
