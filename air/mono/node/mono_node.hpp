#pragma once
// aerie-mono's LCM side: an aerie.image_t channel in (CAM_MONO, or CAM_LEFT of a stereo
// source), aerie.pose_t out (MONO_POSE) with pose_t.SCALE_ARBITRARY in its status, and
// STATUS_MONO with the map's keyframe and landmark counts and why frames were refused or
// skipped. The odometry itself is air/mono; this class checks the input, converts and reports.
#include <aerie/image_t.hpp>

#include <memory>
#include <optional>
#include <string>

#include "air/mono/mono.hpp"
#include "common/bus/node.hpp"
#include "common/util/config.hpp"

namespace aerie::mono {

struct MonoNodeConfig {
  MonoParams mono;
  std::string input = "CAM_MONO";
  std::string pose = "MONO_POSE";
  int queue = 4;
  // Intrinsics of the (undistorted) images; 0: from the image metadata "fx", "fy", "cx", "cy".
  double fx = 0, fy = 0, cx = 0, cy = 0;
};
// config/mono.yaml: the odometry's keys and the "node" section.
MonoNodeConfig load_mono_node_config(const util::Config& cfg);

class MonoNode final : public bus::Node {
 public:
  MonoNode(bus::Bus& bus, const MonoNodeConfig& cfg);

  // Handles one image (also called by the subscription). Never throws: refused images are
  // counted ("refused_images") with the reason in status.
  void on_image(const aerie::image_t& msg, int64_t receive_utime);

  int64_t processed() const { return processed_; }
  int64_t refused() const { return refused_; }
  const std::optional<MonoResult>& last() const { return last_; }

 private:
  PinholeCamera camera_for(const aerie::image_t& msg, const cv::Mat& gray) const;  // throws with the reason
  void publish(const MonoResult& r, int64_t seq, int64_t receive_utime);

  MonoNodeConfig cfg_;
  std::unique_ptr<MonoOdometry> vo_;
  int64_t last_utime_ = -1;
  int64_t processed_ = 0, refused_ = 0;
  std::optional<MonoResult> last_;
};

}  // namespace aerie::mono
