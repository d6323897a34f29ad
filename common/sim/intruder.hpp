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

class IntruderScene {
 public:
  explicit IntruderScene(const IntruderConfig& config);
  bool next(MonoFrame& frame);
  MonoFrame frame(int k) const;   // frame k directly (deterministic, no stepping state)
  int frame_count() const { return config_.frames; }
  const IntruderConfig& config() const { return config_; }

 private:
  struct Motion {
    cv::Point2d center;
    double scale, angle;
    cv::Point2d jitter;
  };
  IntruderConfig config_;
  cv::Mat sky_;                     // background panorama, larger than the image
  cv::Mat sprite_, sprite_alpha_;   // aircraft at high resolution, CV_32F
  std::vector<cv::Point2d> outline_;  // silhouette polygon in sprite pixels
  cv::Point2d sprite_ref_;          // sprite pixel of the reference point
  double sprite_span_px_ = 0;       // wingspan in sprite pixels
  std::vector<Motion> motion_;
  int background_margin_ = 0;
  int next_ = 0;
};

}  // namespace aerie::sim
