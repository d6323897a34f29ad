#pragma once
// Renderers of the camera image pane: the camera image itself (mono channel or the left
// image of a stereo pair), the tracker overlay and the ground-truth box.
#include <aerie/gt_box_t.hpp>
#include <aerie/pilot_state_t.hpp>
#include <aerie/track_t.hpp>

#include "ground/viewer/latest.hpp"
#include "ground/viewer/renderer.hpp"

namespace aerie::viewer {

// Latest image of `channel` (aerie.image_t, or aerie.stereo_image_t for CAM_STEREO*:
// its left image). Decoding happens in the LCM thread; only the newest frame is kept.
class CameraRenderer : public Renderer {
 public:
  explicit CameraRenderer(std::string channel);
  void subscribe(bus::Bus& bus) override;
  // Copies the newest image when it changed since the last call.
  bool take_image(cv::Mat& out);
  const std::string& channel() const { return channel_; }
  int64_t latest_utime() const override { return utime_; }

 private:
  std::string channel_;
  Latest<cv::Mat> image_;
  uint64_t seen_ = 0;
  std::atomic<int64_t> utime_{0};
};

// TRACK: box, rotated corners, confidence, and the samples/particles evaluated per
// pyramid level as dots coloured by level (like the thesis' confidence maps, Fig. 3.35).
class TrackOverlay : public Renderer {
 public:
  explicit TrackOverlay(std::string channel = "TRACK");
  void subscribe(bus::Bus& bus) override;
  bool update() override;
  void draw_image(cv::Mat& canvas) override;
  int64_t latest_utime() const override;

  static const cv::Scalar kBoxColor;  // BGR

 private:
  std::string channel_;
  Latest<aerie::track_t> track_;
  uint64_t seen_ = 0;
  std::optional<aerie::track_t> current_;
};

// PILOT_STATE: the flight manager's state, why it is there, and what it sees of the target
// (height, horizontal offset, yaw error, losses) as a banner over the camera image; HOLD and
// the abort states in orange.
class PilotOverlay : public Renderer {
 public:
  explicit PilotOverlay(std::string channel = "PILOT_STATE");
  void subscribe(bus::Bus& bus) override;
  bool update() override;
  void draw_image(cv::Mat& canvas) override;
  static std::string banner(const aerie::pilot_state_t& s);

 private:
  std::string channel_;
  Latest<aerie::pilot_state_t> state_;
  uint64_t seen_ = 0;
  std::optional<aerie::pilot_state_t> current_;
};

// GT_TRACK: the ground-truth target box when a source publishes one.
class GtBoxOverlay : public Renderer {
 public:
  explicit GtBoxOverlay(std::string channel = "GT_TRACK");
  void subscribe(bus::Bus& bus) override;
  bool update() override;
  void draw_image(cv::Mat& canvas) override;

  static const cv::Scalar kBoxColor;  // BGR

 private:
  std::string channel_;
  Latest<aerie::gt_box_t> box_;
  uint64_t seen_ = 0;
  std::optional<aerie::gt_box_t> current_;
};

}  // namespace aerie::viewer
