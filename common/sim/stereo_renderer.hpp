#pragma once
// Display-less ray-casting renderer of a World seen by an ideal rectified stereo pair.
// Camera optical frame: x right, y down, z forward. The right camera sits at +baseline
// along the left camera's x axis with the same orientation (rectified pinhole pair), so a
// point at depth z seen at column u in the left image is at u - fx * baseline / z in the right.
#include <opencv2/core.hpp>

#include <array>
#include <cstdint>
#include <vector>

#include "common/camera/camera_model.hpp"
#include "common/geometry/se3.hpp"
#include "common/sim/world.hpp"

namespace aerie::sim {

struct RigConfig {
  int width = 376;                 // 376x240 or 752x480 (the thesis' cameras), any size works
  int height = 240;
  double baseline = 0.12;          // m
  double hfov_deg = 98.0;          // fx = (width / 2) / tan(hfov / 2)
  double vfov_deg = 73.0;          // fy = (height / 2) / tan(vfov / 2)
  double pitch_deg = 20.0;         // downward tilt of the rig on the body (90 = looking down)
  bool color = false;              // BGR (CV_8UC3) instead of gray (CV_8UC1)
  double noise_sigma = 0.0;        // additive Gaussian image noise (grey levels)
  double exposure = 1.0;           // global gain on the rendered radiance
  double illumination_amplitude = 0.0;  // relative gain swing over time (0 = constant light)
  double illumination_period = 10.0;    // s, period of that swing
  double right_gain = 1.0;         // extra gain of the right camera (photometric mismatch)
  int motion_blur_samples = 0;     // > 1: average this many poses over the exposure (0 = off)
  double exposure_time = 0.01;     // s, the shutter time motion blur spans (ending at the frame time)
  bool disparity = false;          // also output the exact left disparity map
  uint64_t noise_seed = 1;         // seed of the image noise (frame seq is mixed in)

  static RigConfig vga_half() { return {}; }  // 376x240
  static RigConfig wvga() {                   // 752x480
    RigConfig r;
    r.width = 752;
    r.height = 480;
    return r;
  }
};

struct Intrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0, baseline = 0;
  int width = 0, height = 0;
  // The same rig as a calibrated, already rectified stereo pair (no distortion).
  camera::StereoCalibration calibration() const;
};

struct StereoFrame {
  int64_t utime = 0;
  int64_t seq = 0;
  cv::Mat left, right;   // CV_8UC1 (or CV_8UC3 BGR when RigConfig::color)
  cv::Mat depth;         // CV_32F, left camera, metres along z; NaN where nothing is hit
  cv::Mat disparity;     // CV_32F, fx * b / depth (only when RigConfig::disparity)
  geometry::SE3 T_world_left;   // left camera optical frame -> world
  geometry::SE3 T_world_body;   // vehicle body (x forward, y left, z up) -> world
  // The helipad in the left image: all four corners in front of the camera, inside the
  // image and not occluded -> target_visible. The box is the axis-aligned bounding box of
  // the projected corners (x, y, w, h, pixels); corners follow Helipad::corners() order
  // (NaN when behind the camera).
  bool target_visible = false;
  cv::Rect2d target_box;
  std::array<cv::Point2d, 4> target_corners;
};

// Rigid transform body -> left camera of a rig: rig centred on the body origin, optical
// axis along body x tilted down by pitch_deg, left camera at +baseline/2 along body y.
geometry::SE3 body_to_left(const RigConfig& rig);

class StereoRenderer {
 public:
  StereoRenderer(const World& world, const RigConfig& rig);

  Intrinsics intrinsics() const { return K_; }
  const RigConfig& rig() const { return rig_; }
  const World& world() const { return world_; }

  // Renders both views for the given left camera pose. utime drives the illumination
  // change, seq the image noise; both are copied into the frame. With blur_poses (left
  // camera poses spread over the exposure) the images are their average (motion blur);
  // depth and ground truth stay those of T_world_left.
  StereoFrame render(const geometry::SE3& T_world_left, int64_t utime, int64_t seq,
                     const std::vector<geometry::SE3>& blur_poses = {}) const;
  // The left view alone (a mono camera with this rig's intrinsics and photometry); right
  // stays empty.
  StereoFrame render_mono(const geometry::SE3& T_world_cam, int64_t utime, int64_t seq,
                          const std::vector<geometry::SE3>& blur_poses = {}) const;

  // One view into a float radiance image (0..255 scale, before gain, noise and
  // quantisation) and optionally its depth; the building block of render().
  void render_view(const geometry::SE3& T_world_cam, cv::Mat& radiance, cv::Mat* depth) const;

  // Helipad ground truth for a left camera pose (fills the target_* fields).
  void project_helipad(const geometry::SE3& T_world_left, StereoFrame& frame) const;

 private:
  StereoFrame render_views(const geometry::SE3& T_world_left, int64_t utime, int64_t seq,
                           const std::vector<geometry::SE3>& blur_poses, bool with_right) const;

  World world_;
  RigConfig rig_;
  Intrinsics K_;
};

}  // namespace aerie::sim
