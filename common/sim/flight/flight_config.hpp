#pragma once
// The closed-loop simulator's YAML (config/sim/flight.yaml, config/sim/flight_field.yaml):
// sections world, vehicle, imu, down_camera, stereo_rig, camera_effects (down, stereo:
// common/sim/camera/camera_effects_config.hpp), wind, vibration, placement, platform and
// the top-level keys stereo, frame_rate_hz, max_time_s, seed. Every key is optional
// (defaults: FlightSimConfig's); unknown keys are rejected naming the file and the key.
#include "common/sim/flight/flight_sim.hpp"
#include "common/util/config.hpp"

namespace aerie::sim {

FlightSimConfig load_flight_config(const util::Config& cfg);

}  // namespace aerie::sim
