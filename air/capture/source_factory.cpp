#include "air/capture/source_factory.hpp"

#include <stdexcept>

#include "air/capture/image_folder_source.hpp"
#include "air/capture/sim_source.hpp"
#include "air/capture/stereo_sequence_source.hpp"
#include "air/capture/video_source.hpp"

namespace aerie::capture {

std::unique_ptr<FrameSource> make_source(const SourceOptions& o) {
  auto need_path = [&](const char* what) {
    if (o.path.empty()) throw std::invalid_argument("source '" + o.type + "' needs a path (" + what + ")");
  };
  if (!o.groundtruth.empty() && o.type != "euroc" && o.type != "kitti")
    throw std::invalid_argument("source.groundtruth (--groundtruth) applies to euroc and kitti sources, not to '" +
                                o.type + "'");
  if (o.type == "sim") return std::make_unique<SimSource>(o.sim, o.width, o.height, o.color, o.fps);
  if (o.type == "folder") {
    need_path("image folder");
    return std::make_unique<ImageFolderSource>(o.path, o.timestamps, o.fps, o.color);
  }
  if (o.type == "euroc") {
    need_path("EuRoC ASL folder");
    return std::make_unique<StereoSequenceSource>(load_euroc(o.path, o.groundtruth), o.color);
  }
  if (o.type == "kitti") {
    need_path("KITTI odometry folder");
    return std::make_unique<StereoSequenceSource>(load_kitti(o.path, o.groundtruth), o.color);
  }
  if (o.type == "video") {
    need_path("video file");
    return std::make_unique<VideoFileSource>(o.path, o.fps, o.color);
  }
  if (o.type == "v4l2") {
    need_path("camera device, e.g. /dev/video0");
    return std::make_unique<V4l2Source>(V4l2Options{o.path, o.right, o.calib, o.width, o.height, o.fps, o.color});
  }
  throw std::invalid_argument("unknown source type '" + o.type + "' (expected sim, v4l2, video, folder, euroc or kitti)");
}

}  // namespace aerie::capture
