#include "common/sim/camera/camera_effects_config.hpp"

#include <stdexcept>
#include <vector>

#include "common/camera/calibration_io.hpp"

namespace aerie::sim {

CameraEffectsConfig camera_effects_preset(const std::string& part) {
  CameraEffectsConfig c;
  c.part = part;
  if (part == "ideal") return c;
  if (part == "rpi-camera-module-3") {
    // Raspberry Pi Camera Module 3 (Sony IMX708, 1.4 um pixels, rolling shutter; Raspberry Pi
    // camera documentation). Its 2304x1296 binned mode runs at up to 56.03 fps, so a frame's
    // readout takes at most 1 / 56.03 s: spread over the rows the simulated image has.
    c.motion.motion_blur = true;
    c.motion.rolling_shutter = true;
    c.motion.readout_time_s = 1.0 / 56.03;
    c.exposure.auto_exposure = true;
    c.exposure.max_exposure_time_s = 0.02;
    c.exposure.max_gain = 16.0;  // IMX708 analogue gain 1x..16x (libcamera's imx708 helper)
    // Not in the public documentation: assumed values of a 1.4 um BSI pixel.
    c.noise.enabled = true;
    c.noise.full_well_e = 6000;
    c.noise.read_noise_e = 2.0;
    return c;
  }
  if (part == "ov9281") {
    // OmniVision OV9281 (1280x800, 3 um pixels, global shutter, 120 fps; OV9281 product
    // brief): the forward stereo modules. No rolling shutter.
    c.motion.motion_blur = true;
    c.exposure.auto_exposure = true;
    c.exposure.max_exposure_time_s = 0.008;  // within the 120 fps frame period
    c.exposure.max_gain = 16.0;
    // Not in the product brief: assumed values of a 3 um global-shutter pixel.
    c.noise.enabled = true;
    c.noise.full_well_e = 10000;
    c.noise.read_noise_e = 4.0;
    return c;
  }
  throw std::invalid_argument("unknown camera part '" + part + "' (expected ideal, rpi-camera-module-3 or ov9281)");
}

namespace {

// " (line N)" of a dotted key in a section, "" when absent.
std::string line_of(const util::Config& c, const std::string& key) {
  YAML::Node n;
  n.reset(c.node());
  for (size_t start = 0; start <= key.size();) {
    size_t dot = key.find('.', start);
    if (dot == std::string::npos) dot = key.size();
    if (!n.IsMap()) return "";
    const YAML::Node& parent = n;
    const YAML::Node child = parent[key.substr(start, dot - start)];
    if (!child) return "";
    n.reset(child);
    start = dot + 1;
  }
  return " (line " + std::to_string(n.Mark().line + 1) + ")";
}

[[noreturn]] void fail(const util::Config& c, const std::string& key, const std::string& msg) {
  throw std::runtime_error(c.origin() + ": key '" + key + "' " + msg + line_of(c, key));
}

camera::CameraModel lens_from_calibration(const util::Config& c) {
  const std::string path = c.get<std::string>("lens.calibration", "");
  const std::string side = c.get<std::string>("lens.camera", "left");
  if (side != "left" && side != "right") fail(c, "lens.camera", "must be left or right (got '" + side + "')");
  try {
    if (path.size() >= 11 && path.compare(path.size() - 11, 11, "sensor.yaml") == 0)
      return camera::read_euroc_camera(path).model;
    const camera::StereoCalibration s = camera::read_stereo_calibration(path);
    return side == "left" ? s.left : s.right;
  } catch (const std::exception& e) {
    fail(c, "lens.calibration", std::string("cannot be used: ") + e.what());
  }
}

}  // namespace

CameraEffectsConfig load_camera_effects(const util::Config& c) {
  c.check_keys({"part", "effects", "lens.enabled", "lens.calibration", "lens.camera", "lens.model", "lens.coeffs",
                "motion_blur.enabled", "motion_blur.max_samples", "rolling_shutter.enabled",
                "rolling_shutter.line_delay_s", "rolling_shutter.readout_time_s", "exposure.auto",
                "exposure.exposure_time_s", "exposure.gain", "exposure.min_exposure_time_s",
                "exposure.max_exposure_time_s", "exposure.max_gain", "exposure.target_mean",
                "exposure.time_constant_s", "noise.enabled", "noise.full_well_e", "noise.read_noise_e", "noise.seed",
                "jpeg.enabled", "jpeg.quality"});
  CameraEffectsConfig f;
  try {
    f = camera_effects_preset(c.get<std::string>("part", "ideal"));
  } catch (const std::invalid_argument& e) {
    fail(c, "part", e.what());
  }
  const std::string effects = c.get<std::string>("effects", "real");
  if (effects != "real" && effects != "ideal") fail(c, "effects", "must be real or ideal (got '" + effects + "')");

  auto& L = f.lens;
  L.enabled = c.get<bool>("lens.enabled", L.enabled);
  if (c.has("lens.calibration") && c.has("lens.coeffs"))
    fail(c, "lens.coeffs", "and lens.calibration exclude each other (the calibration holds the coefficients)");
  if (L.enabled && c.has("lens.calibration")) {
    L.model = lens_from_calibration(c);
  } else if (L.enabled) {
    try {
      L.model.distortion = camera::distortion_from_string(c.get<std::string>("lens.model", "radial-tangential"));
    } catch (const std::invalid_argument& e) {
      fail(c, "lens.model", e.what());
    }
    L.model.coeffs = c.get<std::vector<double>>("lens.coeffs", {});
    const size_t n = L.model.coeffs.size();
    const bool ok = L.model.distortion == camera::Distortion::Equidistant ? n == 4
                    : L.model.distortion == camera::Distortion::RadTan   ? (n == 4 || n == 5 || n == 8)
                                                                          : n == 0;
    if (!ok) fail(c, "lens.coeffs", "needs 4 (equidistant), 4, 5 or 8 (radial-tangential) numbers, got " + std::to_string(n));
  }

  auto& M = f.motion;
  M.motion_blur = c.get<bool>("motion_blur.enabled", M.motion_blur);
  M.max_blur_samples = c.get_in("motion_blur.max_samples", M.max_blur_samples, 1, 256);
  M.rolling_shutter = c.get<bool>("rolling_shutter.enabled", M.rolling_shutter);
  M.line_delay_s = c.get_in("rolling_shutter.line_delay_s", M.line_delay_s, 0.0, 0.01);
  M.readout_time_s = c.get_in("rolling_shutter.readout_time_s", M.readout_time_s, 0.0, 1.0);
  if (c.has("rolling_shutter.line_delay_s") && !c.has("rolling_shutter.readout_time_s")) M.readout_time_s = 0;

  auto& E = f.exposure;
  E.auto_exposure = c.get<bool>("exposure.auto", E.auto_exposure);
  E.exposure_time_s = c.get_in("exposure.exposure_time_s", E.exposure_time_s, 1e-6, 0.5);
  E.gain = c.get_in("exposure.gain", E.gain, 1.0, 256.0);
  E.min_exposure_time_s = c.get_in("exposure.min_exposure_time_s", E.min_exposure_time_s, 1e-6, 0.5);
  E.max_exposure_time_s = c.get_in("exposure.max_exposure_time_s", E.max_exposure_time_s, 1e-6, 0.5);
  E.max_gain = c.get_in("exposure.max_gain", E.max_gain, 1.0, 256.0);
  E.target_mean = c.get_in("exposure.target_mean", E.target_mean, 0.01, 0.99);
  E.time_constant_s = c.get_in("exposure.time_constant_s", E.time_constant_s, 1e-3, 60.0);

  auto& N = f.noise;
  N.enabled = c.get<bool>("noise.enabled", N.enabled);
  N.full_well_e = c.get_in("noise.full_well_e", N.full_well_e, 100.0, 1e6);
  N.read_noise_e = c.get_in("noise.read_noise_e", N.read_noise_e, 0.0, 1000.0);
  N.seed = c.get<uint64_t>("noise.seed", N.seed);

  f.jpeg.enabled = c.get<bool>("jpeg.enabled", f.jpeg.enabled);
  f.jpeg.quality = c.get_in("jpeg.quality", f.jpeg.quality, 1, 100);

  if (effects == "ideal") {  // one line reverts to today's frames
    const std::string part = f.part;
    f = CameraEffectsConfig{};
    f.part = part;
  }
  try {
    f.validate(c.origin());
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(e.what());
  }
  return f;
}

}  // namespace aerie::sim
