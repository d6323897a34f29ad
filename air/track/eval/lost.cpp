#include "air/track/eval/lost.hpp"

#include <stdexcept>
#include <string>

#include "air/track/eval/metrics.hpp"
#include "air/track/eval/sequence.hpp"

namespace aerie::track::eval {

LostScore& LostScore::operator+=(const LostScore& o) {
  episodes += o.episodes;
  flagged += o.flagged;
  frames_iou_gt_05 += o.frames_iou_gt_05;
  false_alarms += o.false_alarms;
  return *this;
}

LostScore lost_detection(const std::vector<bool>& lost_flags, const std::vector<cv::Rect2d>& predicted,
                         const std::vector<cv::Rect2d>& groundtruth, int within) {
  if (lost_flags.size() != groundtruth.size() || predicted.size() != groundtruth.size())
    throw std::invalid_argument("lost_detection: " + std::to_string(lost_flags.size()) + " flags and " +
                                std::to_string(predicted.size()) + " predicted boxes for " +
                                std::to_string(groundtruth.size()) + " ground-truth boxes");
  if (within < 1) throw std::invalid_argument("lost_detection: within must be >= 1, got " + std::to_string(within));
  LostScore s;
  int run = 0;  // frames into the current episode (0 = not in one)
  bool flagged = false;
  for (size_t i = 1; i < groundtruth.size(); ++i) {
    const bool present = is_valid_box(groundtruth[i]);
    const double o = present && is_valid_box(predicted[i]) ? iou(predicted[i], groundtruth[i]) : 0;
    if (!present || o <= 0) {
      if (run++ == 0) {
        ++s.episodes;
        flagged = false;
      }
      if (run <= within && lost_flags[i] && !flagged) {
        flagged = true;
        ++s.flagged;
      }
      continue;
    }
    run = 0;
    if (o > 0.5) {
      ++s.frames_iou_gt_05;
      s.false_alarms += lost_flags[i];
    }
  }
  return s;
}

}  // namespace aerie::track::eval
