#pragma once
// OTB one-pass evaluation (Wu et al. 2013): success (IoU) and precision (centre location
// error) curves of one tracker on one sequence.
#include <opencv2/core.hpp>
#include <vector>

namespace aerie::track::eval {

double iou(const cv::Rect2d& a, const cv::Rect2d& b);
double centre_error(const cv::Rect2d& a, const cv::Rect2d& b);

// IoU thresholds 0, 0.05, ..., 1 and centre-error thresholds 0, 1, ..., 50 pixels.
std::vector<double> success_thresholds();
std::vector<double> precision_thresholds();

struct Score {
  int frames = 0;                 // frames with a valid ground-truth box (the others are skipped)
  std::vector<double> success;    // fraction of frames with IoU > threshold
  std::vector<double> precision;  // fraction of frames with centre error <= threshold
  double auc = 0;                 // mean of the success curve
  double precision20 = 0;         // precision at 20 pixels
  double mean_centre_error = 0;   // pixels
};

// predicted[i] is the box for ground truth groundtruth[i]; sizes must match.
Score score(const std::vector<cv::Rect2d>& predicted, const std::vector<cv::Rect2d>& groundtruth);

// The three figures the tables report for a sequence (AUC, P@20, CLE) and their mean over sequences.
struct Figures {
  double auc = 0, precision20 = 0, mean_centre_error = 0;
};
Figures figures(const Score& s);
// NaN figures for an empty list.
Figures mean(const std::vector<Figures>& per_sequence);

}  // namespace aerie::track::eval
