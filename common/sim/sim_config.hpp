#pragma once
// The simulator's YAML configuration (config/sim/*.yaml): sections `world`, `rig`,
// `trajectory` and `intruder` (and `exits` on its own), every key optional (defaults are the structs' defaults),
// unknown keys rejected with the file and key named. The world's `kind` (room | field)
// chooses World::room or World::field (make_simulation builds it with World::make).
#include <cstdint>
#include <string>

#include "common/sim/exits.hpp"
#include "common/sim/intruder.hpp"
#include "common/sim/simulation.hpp"
#include "common/util/config.hpp"

namespace aerie::sim {

struct TrajectoryConfig {
  std::string kind = "demo";  // demo | loops | landing
  double speed = 0.8;         // m/s
  int loops = 10;             // for kind == loops
  double rate_hz = 20.0;      // frame rate
  int64_t start_utime = 0;    // utime of frame 0 (us)
};

struct SimulationConfig {
  WorldConfig world;
  RigConfig rig;
  TrajectoryConfig trajectory;
};

WorldConfig load_world_config(const util::Config& section);
// Keys absent from the section keep the values of `base`.
RigConfig load_rig_config(const util::Config& section, RigConfig base = {});
TrajectoryConfig load_trajectory_config(const util::Config& section);
IntruderConfig load_intruder_config(const util::Config& section);
// A file with the one section `exits` (config/sim/exits.yaml); other sections are refused.
ExitsConfig load_exits_config(const util::Config& config);
// The `world`, `rig` and `trajectory` sections of a file (or of an empty Config: defaults).
SimulationConfig load_simulation_config(const util::Config& config);

Trajectory make_trajectory(const World& world, const TrajectoryConfig& config);
StereoSimulation make_simulation(const SimulationConfig& config);

}  // namespace aerie::sim
