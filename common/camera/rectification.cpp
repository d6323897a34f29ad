#include "common/camera/rectification.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace aerie::camera {

StereoRectifier::StereoRectifier(const StereoCalibration& calib, double alpha) : calib_(calib) {
  calib_.validate();
  const cv::Size size = calib.left.size();
  out_.size = size;
  out_.baseline = calib.baseline();

  const Eigen::Matrix3d Re = calib.T_right_left.rotation_matrix();
  const bool no_rotation = (Re - Eigen::Matrix3d::Identity()).norm() < 1e-12;
  const bool no_distortion = calib.left.distortion == Distortion::None && calib.right.distortion == Distortion::None;
  const auto& t = calib.T_right_left.translation();
  if (no_rotation && no_distortion && std::abs(t.y()) < 1e-12 && std::abs(t.z()) < 1e-12 &&
      calib.left.fx == calib.right.fx && calib.left.fy == calib.right.fy && calib.left.cy == calib.right.cy) {
    // Already rectified (e.g. KITTI); only a principal-point shift in x may remain,
    // which is a constant disparity offset the consumer folds into cx.
    identity_ = true;
    out_.fx = calib.left.fx;
    out_.fy = calib.left.fy;
    out_.cx = calib.left.cx;
    out_.cy = calib.left.cy;
    return;
  }

  cv::Mat R(3, 3, CV_64F), T(3, 1, CV_64F);
  for (int i = 0; i < 9; ++i) R.at<double>(i / 3, i % 3) = Re(i / 3, i % 3);
  for (int i = 0; i < 3; ++i) T.at<double>(i) = t[i];
  cv::Mat R1, R2, P1, P2, Q;
  if (calib.left.distortion == Distortion::Equidistant) {
    if (calib.right.distortion != Distortion::Equidistant)
      throw std::invalid_argument(calib.source + ": mixed equidistant and other distortion models are not supported");
    cv::fisheye::stereoRectify(calib.left.K(), calib.left.D(), calib.right.K(), calib.right.D(), size, R, T, R1, R2, P1,
                               P2, Q, cv::CALIB_ZERO_DISPARITY, size, alpha);
    cv::fisheye::initUndistortRectifyMap(calib.left.K(), calib.left.D(), R1, P1, size, CV_16SC2, map_lx_, map_ly_);
    cv::fisheye::initUndistortRectifyMap(calib.right.K(), calib.right.D(), R2, P2, size, CV_16SC2, map_rx_, map_ry_);
  } else {
    cv::stereoRectify(calib.left.K(), calib.left.D(), calib.right.K(), calib.right.D(), size, R, T, R1, R2, P1, P2, Q,
                      cv::CALIB_ZERO_DISPARITY, alpha, size);
    cv::initUndistortRectifyMap(calib.left.K(), calib.left.D(), R1, P1, size, CV_16SC2, map_lx_, map_ly_);
    cv::initUndistortRectifyMap(calib.right.K(), calib.right.D(), R2, P2, size, CV_16SC2, map_rx_, map_ry_);
  }
  R1_ = cv::Matx33d(R1);
  out_.fx = P1.at<double>(0, 0);
  out_.fy = P1.at<double>(1, 1);
  out_.cx = P1.at<double>(0, 2);
  out_.cy = P1.at<double>(1, 2);
}

void StereoRectifier::rectify(const cv::Mat& left_raw, const cv::Mat& right_raw, cv::Mat& left, cv::Mat& right) const {
  const cv::Size expected = calib_.left.size();
  if (left_raw.size() != expected || right_raw.size() != expected) {
    throw std::invalid_argument("stereo images are " + std::to_string(left_raw.cols) + "x" +
                                std::to_string(left_raw.rows) + " / " + std::to_string(right_raw.cols) + "x" +
                                std::to_string(right_raw.rows) + " but the calibration " + calib_.source + " is for " +
                                std::to_string(expected.width) + "x" + std::to_string(expected.height));
  }
  if (identity_) {
    left = left_raw;
    right = right_raw;
    return;
  }
  cv::remap(left_raw, left, map_lx_, map_ly_, cv::INTER_LINEAR);
  cv::remap(right_raw, right, map_rx_, map_ry_, cv::INTER_LINEAR);
}

}  // namespace aerie::camera
