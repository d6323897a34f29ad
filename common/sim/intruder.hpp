#pragma once
// Mono "sense and avoid" scene for the trackers: a textured aircraft silhouette (fuselage,
// wings, tail) crossing a cloudy sky, seen by a camera with onboard vibration (a seeded
// random walk of the image), with scale and slight rotation changes and an exact
// ground-truth box per frame.
#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

namespace aerie::sim {

struct IntruderConfig {
  uint64_t seed = 1;
  int width = 640, height = 480;
  int frames = 300;
  double rate_hz = 20.0;
  int64_t start_utime = 0;
  double vibration_px = 2.0;     // std-dev of the per-frame random-walk step of the image (px)
  double wingspan_px = 90.0;     // apparent wingspan at the first frame (px)
  double scale_change = 1.8;     // apparent size at the last frame / at the first frame
  double max_roll_deg = 12.0;    // amplitude of the slow in-image rotation (bank)
  double noise_sigma = 1.5;      // additive Gaussian image noise (grey levels)
  bool color = false;            // BGR instead of gray
  bool draw_target = true;       // false: the same frames without the aircraft (background)
};

struct MonoFrame {
  int64_t utime = 0;
  int64_t seq = 0;
  cv::Mat image;
  cv::Rect2d target_box;          // axis-aligned bounding box of the aircraft silhouette
  bool target_visible = false;    // box entirely inside the image
  // The similarity the aircraft undergoes (the tracking state x, y, s, theta):
  cv::Point2d target_center;      // image position of the aircraft's reference point
  double target_scale = 1.0;      // relative to the first frame
  double target_angle = 0.0;      // in-image rotation (rad, counter-clockwise)
};

// The aircraft's geometry in one frame, before the vibration: the similarity of the silhouette
// (image position of its reference point, scale relative to wingspan_px, in-image rotation)
// and the camera's pan over the sky (px; the sky and the aircraft move by -pan in the image).
struct IntruderPose {
  cv::Point2d center;
  double scale = 1.0, angle = 0.0;
  cv::Point2d pan;
};

class IntruderScene {
 public:
  // The crossing: a path derived from the seed.
  explicit IntruderScene(const IntruderConfig& config);
  // The same aircraft, sky and vibration following `path` (one pose a frame; config.frames is
  // ignored); the sky is large enough for every pan of the path.
  IntruderScene(const IntruderConfig& config, const std::vector<IntruderPose>& path);
  bool next(MonoFrame& frame);
  MonoFrame frame(int k) const;   // frame k directly (deterministic, no stepping state)
  int frame_count() const { return config_.frames; }
  const IntruderConfig& config() const { return config_; }

 private:
  struct Motion {
    cv::Point2d center;
    double scale, angle;
    cv::Point2d jitter;
    cv::Point2d pan;
  };
  // Vibration, sky and sprite for `config_` and the pans of `path`; returns the seeded stream
  // for what follows.
  cv::RNG build(const std::vector<IntruderPose>& path);
  IntruderConfig config_;
  cv::Mat sky_;                     // background panorama, larger than the image
  cv::Mat sprite_, sprite_alpha_;   // aircraft at high resolution, CV_32F
  std::vector<cv::Point2d> outline_;  // silhouette polygon in sprite pixels
  cv::Point2d sprite_ref_;          // sprite pixel of the reference point
  double sprite_span_px_ = 0;       // wingspan in sprite pixels
  std::vector<cv::Point2d> jitter_;  // the vibration of each frame
  std::vector<Motion> motion_;
  cv::Point2d sky_origin_;           // sky pixel of the image origin at zero pan and vibration
  int next_ = 0;
};

}  // namespace aerie::sim
