#pragma once
// The aerie-capture node: plays a FrameSource onto LCM.
//   stereo source -> CAM_STEREO (aerie.stereo_image_t: the rectified pair, its intrinsics and
//                    baseline); CAM_LEFT, CAM_RIGHT (aerie.image_t) only when split_stereo is
//                    set or there is no CAM_STEREO (no calibration, or the channel turned off),
//                    so that each image is on the wire (and in the log) once
//   one camera    -> CAM_MONO
//   ground truth  -> GT_POSE (aerie.gt_pose_t), GT_TRACK (aerie.gt_box_t)
// All messages of one frame share its utime and seq. An empty channel name turns
// that output off. Status (frames published, unreadable, late) on STATUS_CAPTURE.
#include <aerie/gt_box_t.hpp>
#include <aerie/gt_pose_t.hpp>
#include <aerie/image_t.hpp>
#include <aerie/stereo_image_t.hpp>

#include <memory>
#include <optional>
#include <string>

#include "air/capture/frame_source.hpp"
#include "air/capture/output_format.hpp"
#include "air/capture/source_factory.hpp"
#include "common/bus/bus.hpp"
#include "common/bus/channels.hpp"
#include "common/image/image_message.hpp"
#include "common/util/config.hpp"

namespace aerie::capture {

struct ChannelNames {
  std::string left = channels::kCamLeft;
  std::string right = channels::kCamRight;
  std::string stereo = channels::kCamStereo;
  std::string mono = channels::kCamMono;
  std::string gt_pose = channels::kGtPose;
  std::string gt_track = channels::kGtTrack;
  // A source whose rectified pair goes out on `stereo` also publishes its images alone on
  // `left` / `right` (each image then twice on the wire).
  bool split_stereo = false;
};

struct CaptureConfig {
  SourceOptions source;
  OutputOptions output;
  std::string encoding = "raw";  // raw | jpeg | png
  int jpeg_quality = 90;
  double rate = 1.0;             // 1 = real time, k = k times, 0 = as fast as possible
  int64_t start = 0;             // first frame (index in the source)
  int64_t stop = -1;             // frame index to stop before (-1 = the end)
  double duration_s = 0;         // stop after this much source time (0 = no limit)
  bool loop = false;             // recorded sources: start again at the end (times and seq go on)
  std::string stamp = "source";  // source: the frames' own times; wall: wall clock at publication
  int max_consecutive_errors = 50;  // unreadable frames in a row before giving up
  ChannelNames channels;

  // The source's options with the output size and colour as its request (a camera is
  // asked for that size, the simulator renders at it).
  SourceOptions source_options() const {
    SourceOptions s = source;
    s.width = output.width;
    s.height = output.height;
    s.color = output.color;
    return s;
  }
};

// Reads config/capture.yaml's keys (see that file); absent keys keep the defaults.
// Throws std::runtime_error naming the file and key.
CaptureConfig load_capture_config(const util::Config& cfg);

// The messages of one frame.
struct FrameMessages {
  std::optional<aerie::image_t> left, right, mono;
  std::optional<aerie::stereo_image_t> stereo;
  std::optional<aerie::gt_pose_t> gt_pose;
  std::optional<aerie::gt_box_t> gt_box;
};

// Frame -> messages, independent of the transport (tested without a bus).
class MessageBuilder {
 public:
  // `rectified`: the published pair's intrinsics (already scaled to the output size).
  MessageBuilder(const CaptureConfig& cfg, bool stereo, std::optional<camera::RectifiedStereo> rectified);
  FrameMessages build(const Frame& frame, int64_t utime, int64_t seq) const;

 private:
  CaptureConfig cfg_;
  bool stereo_;
  std::optional<camera::RectifiedStereo> rectified_;
  image::Encoding encoding_;
};

struct RunStats {
  int64_t published = 0;
  int64_t unreadable = 0;
  int64_t late = 0;  // published more than one frame interval after it was due
  double wall_s = 0;
};

class CaptureNode {
 public:
  // Throws std::runtime_error / std::invalid_argument for bad options.
  CaptureNode(bus::Bus& bus, const CaptureConfig& cfg, std::unique_ptr<FrameSource> source);
  // Plays until the source ends, the stop frame/duration is reached or a stop is
  // requested (SIGINT/SIGTERM). Throws when max_consecutive_errors is exceeded.
  RunStats run();
  const FrameSource& source() const { return *source_; }

 private:
  void publish(const FrameMessages& m);

  bus::Bus& bus_;
  CaptureConfig cfg_;
  std::unique_ptr<FrameSource> source_;
  OutputFormat format_;
  MessageBuilder builder_;
};

}  // namespace aerie::capture
