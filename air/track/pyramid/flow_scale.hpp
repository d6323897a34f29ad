#pragma once
// Scale change of the target between two frames from the motion of points inside its box,
// as Median Flow does (Kalal et al. 2010): a grid of points is tracked forward and backward
// with pyramidal Lucas-Kanade; points whose forward-backward error exceeds the median are
// dropped, and the scale change is the median ratio of the pairwise point distances.
#include <opencv2/core.hpp>

namespace aerie::track {

struct FlowScale {
  bool ok = false;     // enough reliable points
  double ratio = 1;    // size in `next` / size in `prev`
  cv::Point2d shift;   // median displacement of the points, pixels
  int points = 0;      // points kept
};

// prev, next: 8-bit gray frames of the same size; box: the target in prev.
FlowScale flow_scale(const cv::Mat& prev, const cv::Mat& next, const cv::Rect2d& box, int grid = 10);

}  // namespace aerie::track
