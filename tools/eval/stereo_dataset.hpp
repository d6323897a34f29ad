#pragma once
// Readers of stereo sequences with ground truth, for offline evaluation:
//  * KITTI odometry folders: image_0/image_1 (or image_l/image_r), calib.txt (P0, P1 with or
//    without labels), times.txt, poses.txt when present (ground truth of the left camera);
//  * EuRoC ASL folders: mav0/cam0, mav0/cam1 (data.csv + raw distorted PNGs, sensor.yaml),
//    rectified here with common/camera; ground truth from groundtruth/*.txt (TUM) or
//    mav0/state_groundtruth_estimate0/data.csv, turned into poses of the rectified left camera.
// An explicit ground-truth file (any format read_trajectory detects) replaces those: for KITTI
// the left camera's poses (KITTI poses stamped with times.txt), for EuRoC the body's (TUM or
// EuRoC CSV).
// Images come out rectified and 8-bit gray.
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "common/camera/rectification.hpp"
#include "tools/eval/trajectory.hpp"

namespace aerie::eval {

class StereoSequence {
 public:
  virtual ~StereoSequence() = default;
  const std::string& name() const { return name_; }
  size_t size() const { return utimes_.size(); }
  // The rectified rig: fx, fy, cx, cy, baseline, image size.
  const camera::RectifiedStereo& rig() const { return rig_; }
  // Ground truth of the rectified left camera (T_world_cam), empty when the folder has none.
  const Trajectory& ground_truth() const { return ground_truth_; }
  int64_t utime(size_t i) const { return utimes_.at(i); }
  // Loads pair i (rectified gray). Throws std::runtime_error naming a missing/bad file.
  virtual void load(size_t i, cv::Mat& left, cv::Mat& right) const = 0;

 protected:
  std::string name_;
  camera::RectifiedStereo rig_;
  Trajectory ground_truth_;
  std::vector<int64_t> utimes_;
};

// Where the readers find ground truth by themselves, for help texts and messages.
inline constexpr const char* kGroundTruthLayouts =
    "kitti:DIR reads DIR/poses.txt; euroc:DIR reads DIR/groundtruth/*.txt (TUM) or "
    "DIR/mav0/state_groundtruth_estimate0/data.csv";

// groundtruth: "" = the layouts above.
std::unique_ptr<StereoSequence> open_kitti(const std::string& dir, const std::string& groundtruth = "");
std::unique_ptr<StereoSequence> open_euroc(const std::string& dir, const std::string& groundtruth = "");
// "kitti:DIR" or "euroc:DIR".
std::unique_ptr<StereoSequence> open_sequence(const std::string& spec, const std::string& groundtruth = "");

}  // namespace aerie::eval
