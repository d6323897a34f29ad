#include "common/sim/sim_config.hpp"

#include <algorithm>
#include <stdexcept>
#include <vector>

namespace aerie::sim {

namespace {

// Every key of the section must be one we know (a typo would otherwise be ignored).
void check_keys(const util::Config& section, const std::vector<std::string>& known) {
  const YAML::Node& n = section.node();
  if (!n || n.IsNull()) return;
  if (!n.IsMap()) throw std::runtime_error(section.origin() + ": expected a map of keys");
  for (const auto& kv : n) {
    const std::string key = kv.first.as<std::string>();
    if (std::find(known.begin(), known.end(), key) == known.end()) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      throw std::runtime_error(section.origin() + ": unknown key '" + key + "' (known: " + list + ")");
    }
  }
}

template <typename T>
void read(const util::Config& c, const std::string& key, T& value) {
  value = c.get<T>(key, value);
}

}  // namespace

WorldConfig load_world_config(const util::Config& c) {
  check_keys(c, {"seed", "room_x", "room_y", "room_z", "n_obstacles", "helipad_size", "helipad_yaw_deg",
                 "texels_per_metre", "route_margin", "route_clearance", "cruise_altitude"});
  WorldConfig w;
  read(c, "seed", w.seed);
  read(c, "room_x", w.room_x);
  read(c, "room_y", w.room_y);
  read(c, "room_z", w.room_z);
  read(c, "n_obstacles", w.n_obstacles);
  read(c, "helipad_size", w.helipad_size);
  read(c, "helipad_yaw_deg", w.helipad_yaw_deg);
  read(c, "texels_per_metre", w.texels_per_metre);
  read(c, "route_margin", w.route_margin);
  read(c, "route_clearance", w.route_clearance);
  read(c, "cruise_altitude", w.cruise_altitude);
  return w;
}

RigConfig load_rig_config(const util::Config& c) {
  check_keys(c, {"width", "height", "baseline", "hfov_deg", "vfov_deg", "pitch_deg", "color", "noise_sigma",
                 "exposure", "illumination_amplitude", "illumination_period", "right_gain", "disparity",
                 "noise_seed", "motion_blur_samples", "exposure_time"});
  RigConfig r;
  read(c, "width", r.width);
  read(c, "height", r.height);
  read(c, "baseline", r.baseline);
  read(c, "hfov_deg", r.hfov_deg);
  read(c, "vfov_deg", r.vfov_deg);
  read(c, "pitch_deg", r.pitch_deg);
  read(c, "color", r.color);
  read(c, "noise_sigma", r.noise_sigma);
  read(c, "exposure", r.exposure);
  read(c, "illumination_amplitude", r.illumination_amplitude);
  read(c, "illumination_period", r.illumination_period);
  read(c, "right_gain", r.right_gain);
  read(c, "disparity", r.disparity);
  read(c, "noise_seed", r.noise_seed);
  read(c, "motion_blur_samples", r.motion_blur_samples);
  read(c, "exposure_time", r.exposure_time);
  return r;
}

TrajectoryConfig load_trajectory_config(const util::Config& c) {
  check_keys(c, {"kind", "speed", "loops", "rate_hz", "start_utime"});
  TrajectoryConfig t;
  read(c, "kind", t.kind);
  read(c, "speed", t.speed);
  read(c, "loops", t.loops);
  read(c, "rate_hz", t.rate_hz);
  read(c, "start_utime", t.start_utime);
  if (t.kind != "demo" && t.kind != "loops" && t.kind != "landing")
    throw std::runtime_error(c.origin() + ": key 'kind' must be demo, loops or landing (got '" + t.kind + "')");
  return t;
}

IntruderConfig load_intruder_config(const util::Config& c) {
  check_keys(c, {"seed", "width", "height", "frames", "rate_hz", "start_utime", "vibration_px", "wingspan_px",
                 "scale_change", "max_roll_deg", "noise_sigma", "color"});
  IntruderConfig i;
  read(c, "seed", i.seed);
  read(c, "width", i.width);
  read(c, "height", i.height);
  read(c, "frames", i.frames);
  read(c, "rate_hz", i.rate_hz);
  read(c, "start_utime", i.start_utime);
  read(c, "vibration_px", i.vibration_px);
  read(c, "wingspan_px", i.wingspan_px);
  read(c, "scale_change", i.scale_change);
  read(c, "max_roll_deg", i.max_roll_deg);
  read(c, "noise_sigma", i.noise_sigma);
  read(c, "color", i.color);
  return i;
}

SimulationConfig load_simulation_config(const util::Config& c) {
  const YAML::Node& root = c.node();
  if (root && root.IsMap())
    for (const auto& kv : root) {
      const std::string key = kv.first.as<std::string>();
      if (key != "world" && key != "rig" && key != "trajectory" && key != "intruder")
        throw std::runtime_error(c.origin() + ": unknown section '" + key +
                                 "' (known: world, rig, trajectory, intruder)");
    }
  SimulationConfig s;
  s.world = load_world_config(c.section("world"));
  s.rig = load_rig_config(c.section("rig"));
  s.trajectory = load_trajectory_config(c.section("trajectory"));
  return s;
}

Trajectory make_trajectory(const World& world, const TrajectoryConfig& t) {
  if (t.kind == "loops") return Trajectory::survey_loops(world, t.loops, t.speed);
  if (t.kind == "landing") return Trajectory::landing(world, t.speed);
  return Trajectory::demo_flight(world, t.speed);
}

StereoSimulation make_simulation(const SimulationConfig& s) {
  World world = World::room(s.world);
  Trajectory trajectory = make_trajectory(world, s.trajectory);
  return StereoSimulation(std::move(world), s.rig, std::move(trajectory), s.trajectory.rate_hz,
                          s.trajectory.start_utime);
}

}  // namespace aerie::sim
