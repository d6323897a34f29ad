#pragma once
// Stereo datasets stored as files: EuRoC ASL folders (raw, distorted images,
// rectified on the fly from sensor.yaml) and KITTI odometry folders (already
// rectified). Both load into a StereoSequence, which one source plays.
#include <optional>
#include <string>
#include <vector>

#include "air/capture/frame_source.hpp"
#include "common/camera/camera_model.hpp"
#include "common/camera/rectification.hpp"

namespace aerie::capture {

struct StereoSequence {
  std::string description;              // "EuRoC ASL folder /data/V1_01 (cam0/data.csv)"
  std::vector<std::string> left, right;  // image files; an empty right name = no image for that frame
  std::vector<int64_t> utimes;
  camera::StereoCalibration calib;
  // Ground truth per frame: pose of the raw left camera in the world (empty = none).
  std::vector<std::optional<geometry::SE3>> gt;
  std::string frame_id;
};

// EuRoC ASL folder (the folder holding mav0/, or mav0 itself). Frames are driven by
// cam0/data.csv; cam1 images are matched by timestamp (cam1 rows without a cam0 row
// are ignored, a cam0 row without cam1 gives an unreadable frame). Ground truth from
// mav0/state_groundtruth_estimate0/data.csv when present, or from `gt_tum` (body
// pose in the world, TUM format), composed with cam0's T_BS.
StereoSequence load_euroc(const std::string& dir, const std::string& gt_tum = "");

// KITTI odometry folder: image_0/ + image_1/ (or image_l/ + image_r/), calib.txt,
// optional times.txt (else 10 Hz) and ground truth (T_0_i of the left camera): `poses_file`
// when given (it must exist), else the folder's poses.txt, else, in KITTI's download layout
// (dataset/sequences/NN with dataset/poses/NN.txt), that NN.txt.
StereoSequence load_kitti(const std::string& dir, const std::string& poses_file = "");

class StereoSequenceSource final : public FrameSource {
 public:
  // Checks the calibration against the first pair; throws std::runtime_error naming
  // the calibration file and the image when they do not match.
  StereoSequenceSource(StereoSequence seq, bool color);

  std::string describe() const override;
  bool stereo() const override { return true; }
  cv::Size size() const override { return rectifier_.rectified().size; }
  std::optional<camera::RectifiedStereo> rectified() const override { return rectifier_.rectified(); }
  int64_t frame_count() const override { return static_cast<int64_t>(seq_.left.size()); }
  void seek(int64_t index) override { next_ = index; }
  bool next(Frame& frame) override;

  const StereoSequence& sequence() const { return seq_; }

 private:
  StereoSequence seq_;
  bool color_;
  camera::StereoRectifier rectifier_;
  geometry::SE3 T_raw_rect_;  // rectified left camera in the raw left camera frame
  int64_t next_ = 0;
};

}  // namespace aerie::capture
