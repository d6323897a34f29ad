#pragma once
// One interface for every place frames come from: cameras, video files, image
// folders, datasets (EuRoC, KITTI) and the simulator. A source delivers frames in
// order, each with its capture time (utime) and, when it has them, ground truth.
// Stereo sources deliver the pair already rectified and say so with rectified().
#include <array>
#include <cstdint>
#include <optional>
#include <opencv2/core.hpp>
#include <stdexcept>
#include <string>

#include "common/camera/rectification.hpp"
#include "common/geometry/se3.hpp"

namespace aerie::capture {

// Pose of the (rectified) left camera in the source's world frame.
struct GroundTruthPose {
  geometry::SE3 T_world_camera;
  std::string frame_id;  // "sim", "kitti", "euroc"
};

// Image box of a target in the left image.
struct GroundTruthBox {
  std::string target;  // e.g. "helipad"
  bool visible = false;
  cv::Rect2d box;                          // axis-aligned: top-left corner and size, pixels
  std::array<cv::Point2d, 4> corners{};    // projected corners of the target
};

struct Frame {
  int64_t index = 0;  // position in the source, 0-based
  int64_t utime = 0;  // capture time, microseconds (source time base)
  cv::Mat left;       // CV_8UC1 or CV_8UC3 (BGR); the only image of a one-camera source
  cv::Mat right;      // empty for one camera
  std::optional<GroundTruthPose> gt_pose;
  std::optional<GroundTruthBox> gt_box;
};

// An unreadable frame in the middle of a run: the source has already moved past it,
// so the caller may count it and go on. The message names the file.
class FrameError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;

  // One line for logs and status, e.g. "KITTI folder /data/06 (1101 stereo frames, 1226x370)".
  virtual std::string describe() const = 0;
  virtual bool stereo() const = 0;
  // Size of the delivered (rectified) images.
  virtual cv::Size size() const = 0;
  // Intrinsics and baseline of the rectified pair (stereo sources with a calibration).
  virtual std::optional<camera::RectifiedStereo> rectified() const { return std::nullopt; }
  // Number of frames, or -1 when unknown (cameras).
  virtual int64_t frame_count() const { return -1; }
  // Cameras deliver frames at their own pace; recorded sources are paced by the caller.
  virtual bool live() const { return false; }

  // Makes `index` the next frame. The default reads and discards frames.
  virtual void seek(int64_t index);
  // The next frame; false at the end. Throws FrameError for an unreadable frame
  // (skipped: the next call returns the frame after it).
  virtual bool next(Frame& frame) = 0;
};

}  // namespace aerie::capture
