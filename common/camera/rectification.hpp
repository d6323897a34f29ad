#pragma once
// Stereo rectification maps from a calibration (OpenCV stereoRectify /
// fisheye::stereoRectify + initUndistortRectifyMap). After rectify(), a scene point
// lies on the same row in both images and the rectified pair is an ideal pinhole
// rig with focal f, principal point (cx, cy) and baseline b (eq. 4.1).
#include <opencv2/core.hpp>

#include "common/camera/camera_model.hpp"

namespace aerie::camera {

struct RectifiedStereo {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  double baseline = 0;  // metres
  cv::Size size;
};

class StereoRectifier {
 public:
  // alpha: 0 keeps only valid pixels, 1 keeps every source pixel (OpenCV's meaning).
  explicit StereoRectifier(const StereoCalibration& calib, double alpha = 0.0);

  // Raw images of the calibrated size (gray or colour) to the rectified pair.
  // Throws std::invalid_argument when a size does not match the calibration.
  void rectify(const cv::Mat& left_raw, const cv::Mat& right_raw, cv::Mat& left, cv::Mat& right) const;

  const RectifiedStereo& rectified() const { return out_; }
  // Rotation from the raw left camera frame into the rectified left frame.
  const cv::Matx33d& R_left() const { return R1_; }
  bool is_identity() const { return identity_; }

 private:
  StereoCalibration calib_;
  RectifiedStereo out_;
  cv::Matx33d R1_ = cv::Matx33d::eye();
  cv::Mat map_lx_, map_ly_, map_rx_, map_ry_;
  bool identity_ = false;
};

}  // namespace aerie::camera
