#pragma once
// Frames through OpenCV's VideoCapture: a video file (one camera), or V4L2 cameras,
// one or a stereo pair. A pair is grabbed back to back and then decoded, so that the
// two exposures are as close in time as the driver allows; with a stereo calibration
// the pair is rectified.
#include <memory>
#include <opencv2/videoio.hpp>
#include <optional>
#include <string>

#include "air/capture/frame_source.hpp"

namespace aerie::capture {

class VideoFileSource final : public FrameSource {
 public:
  // fps_fallback: used when the file does not state its frame rate.
  VideoFileSource(const std::string& file, double fps_fallback, bool color);
  std::string describe() const override;
  bool stereo() const override { return false; }
  cv::Size size() const override { return size_; }
  int64_t frame_count() const override { return count_; }
  void seek(int64_t index) override;
  bool next(Frame& frame) override;

 private:
  std::string file_;
  cv::VideoCapture cap_;
  double fps_;
  int64_t count_;
  cv::Size size_;
  bool color_;
  int64_t next_ = 0;
};

struct V4l2Options {
  std::string left;   // "/dev/video0" or a device index "0"
  std::string right;  // second camera of a stereo pair ("" = one camera)
  std::string calib;  // stereo calibration (sensor.yaml folder, calib.txt, OpenCV YAML); "" = none
  int width = 0, height = 0;  // requested capture size (0 = the driver's default)
  double fps = 0;             // requested frame rate (0 = the driver's default)
  bool color = false;
};

class V4l2Source final : public FrameSource {
 public:
  // Throws std::runtime_error naming the device or calibration file.
  explicit V4l2Source(const V4l2Options& options);
  std::string describe() const override;
  bool stereo() const override { return right_.isOpened(); }
  cv::Size size() const override { return size_; }
  std::optional<camera::RectifiedStereo> rectified() const override;
  bool live() const override { return true; }
  bool next(Frame& frame) override;

 private:
  V4l2Options opt_;
  cv::VideoCapture left_, right_;
  std::unique_ptr<camera::StereoRectifier> rectifier_;
  cv::Size size_;
  int64_t next_ = 0;
};

}  // namespace aerie::capture
