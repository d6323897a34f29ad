#pragma once
// The YAML of one simulated camera's effects (a `camera_effects.<camera>` section, docs/sim.md):
//   part: ideal | rpi-camera-module-3 | ov9281   the real part whose defaults to start from
//   effects: real | ideal                        ideal: every effect off, whatever else is set
//   lens: {enabled, calibration, camera, model, coeffs}
//   motion_blur: {enabled, max_samples}
//   rolling_shutter: {enabled, line_delay_s, readout_time_s}
//   exposure: {auto, exposure_time_s, gain, min_exposure_time_s, max_exposure_time_s, max_gain,
//              target_mean, time_constant_s}
//   noise: {enabled, full_well_e, read_noise_e, seed}
//   jpeg: {enabled, quality}
// Unknown keys, values out of range and unreadable calibrations are refused naming the file,
// the key and its line.
#include <string>

#include "common/sim/camera/camera_effects.hpp"
#include "common/util/config.hpp"

namespace aerie::sim {

// The defaults of a named part (throws std::invalid_argument listing the known names).
CameraEffectsConfig camera_effects_preset(const std::string& part);
// An absent or empty section: ideal (every effect off).
CameraEffectsConfig load_camera_effects(const util::Config& section);

}  // namespace aerie::sim
