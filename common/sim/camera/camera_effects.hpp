#pragma once
// The camera-effects stage (docs/sim.md, "Camera effects"): turns a rendered ideal frame
// (pinhole, global shutter, fixed exposure, noise-free) into what a real camera delivers,
// each effect from its physics and each switchable:
//   lens      the calibrated projection (radial-tangential or equidistant, common/camera):
//             output pixel p_d sees the ray unproject(p_d), read in the ideal image at K_ideal * ray;
//   motion    blur over the exposure time and a rolling shutter (row r exposed (r - r_c) * line
//             delay after the centre row): the ideal image is shifted by the image-space flow
//             of the static scene, from the per-pixel depth and the camera's velocity (first
//             order in the motion during one frame; exact for pure rotation and for a plane);
//   exposure  auto-exposure and gain as a first-order loop on the mean brightness;
//   noise     Poisson shot noise and Gaussian read noise in electrons (full well, gain), seeded;
//   jpeg      OpenCV's imencode/imdecode at a quality.
// No LCM, no I/O (but the calibration file the config names, read by config.cpp).
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "common/camera/camera_model.hpp"

namespace aerie::sim {

struct LensEffect {
  bool enabled = false;
  // The real camera: intrinsics and distortion of its calibration (file or coefficients),
  // of the rendered image's size.
  camera::CameraModel model;
};

struct MotionEffect {
  bool motion_blur = false;       // integrate over the exposure time
  int max_blur_samples = 32;      // sub-exposure samples, one per pixel of blur up to this
  bool rolling_shutter = false;   // false: global shutter
  double line_delay_s = 0.0;      // start-of-exposure delay between successive rows
  double readout_time_s = 0.0;    // > 0 and line_delay_s == 0: line delay = readout / rows
};

struct ExposureEffect {
  bool auto_exposure = false;
  double exposure_time_s = 0.005;  // the ideal frame's exposure (and the fixed one without AE)
  double gain = 1.0;               // analog gain without AE (the ideal frame: 1)
  double min_exposure_time_s = 2e-5;
  double max_exposure_time_s = 0.02;
  double max_gain = 16.0;
  double target_mean = 0.45;       // AE set point: mean output level / full scale
  double time_constant_s = 0.15;   // AE first-order lag
};

struct NoiseEffect {
  bool enabled = false;
  double full_well_e = 6000;     // electrons at full scale (255 DN) at unity gain
  double read_noise_e = 2.0;     // RMS, electrons
  uint64_t seed = 1;             // the frame's seq is mixed in
};

struct JpegEffect {
  bool enabled = false;
  int quality = 90;
};

struct CameraEffectsConfig {
  std::string part = "ideal";    // the real part the defaults model (presets in config.cpp)
  LensEffect lens;
  MotionEffect motion;
  ExposureEffect exposure;
  NoiseEffect noise;
  JpegEffect jpeg;

  // Any effect on (false: the stage returns the ideal frame untouched).
  bool any() const {
    return lens.enabled || motion.motion_blur || motion.rolling_shutter || exposure.auto_exposure ||
           exposure.gain != 1.0 || noise.enabled || jpeg.enabled;
  }
  // Throws std::invalid_argument naming `what` and the field.
  void validate(const std::string& what) const;
};

// The camera's motion at the frame time, in its own optical frame (x right, y down, z forward):
// velocity of its centre (m/s) and angular velocity (rad/s).
struct CameraMotion {
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
};

// Image-space flow (px/s) of a static point at pixel (u, v) and depth z (NaN/inf: at
// infinity) seen by a pinhole (fx, fy, cx, cy) moving with `m`: the interaction matrix of
// a point feature, d(x, y)/dt with P' = -v - w x P.
Eigen::Vector2d image_flow(const CameraMotion& m, double fx, double fy, double cx, double cy, double u, double v,
                           double z);

class CameraEffects {
 public:
  // ideal: the pinhole the frames are rendered with (distortion None). With the lens on, its
  // model's size must be the ideal's (refused naming both sizes).
  CameraEffects(const CameraEffectsConfig& config, const camera::CameraModel& ideal, const std::string& what);

  // One frame: ideal CV_8UC1/CV_8UC3 of the ideal size, its depth (CV_32F metres along z;
  // empty: the scene at infinity), the motion at the frame time; utime drives the AE loop
  // (frames in order), seq the noise. All effects off: `ideal` itself is returned.
  cv::Mat apply(const cv::Mat& ideal, const cv::Mat& depth, const CameraMotion& motion, int64_t utime,
                int64_t seq);

  const CameraEffectsConfig& config() const { return cfg_; }
  // Pinhole FOV (deg, symmetric about the ideal's centre) an ideal of this size must have to
  // see every ray of `lens` (rays beyond 89 deg are capped there).
  static std::pair<double, double> fov_to_cover(const camera::CameraModel& lens);
  // Fraction of output pixels whose ray lies inside the ideal image (1 without the lens).
  double coverage() const { return coverage_; }
  // The exposure time and gain the last frame was taken with.
  double exposure_time_s() const { return exposure_time_; }
  double gain() const { return gain_; }
  double line_delay_s() const { return line_delay_; }

 private:
  CameraEffectsConfig cfg_;
  camera::CameraModel ideal_;
  cv::Mat lens_x_, lens_y_;  // CV_32F: output pixel -> ideal pixel (identity without the lens)
  double coverage_ = 1.0;
  double line_delay_ = 0.0;
  double exposure_time_, gain_;
  int64_t last_utime_ = 0;
  bool has_last_ = false;
  double last_mean_ = 0.0;
};

}  // namespace aerie::sim
