#include "common/sim/sim_config.hpp"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "common/util/section_reader.hpp"

namespace aerie::sim {

using util::SectionReader;

WorldConfig load_world_config(const util::Config& c) {
  WorldConfig w;
  using W = WorldConfig;
  SectionReader<W>(c, w)("kind", &W::kind)("seed", &W::seed)("room_x", &W::room_x)("room_y", &W::room_y)(
      "room_z", &W::room_z)("n_obstacles", &W::n_obstacles)("helipad_size", &W::helipad_size)(
      "helipad_yaw_deg", &W::helipad_yaw_deg)("helipad_x", &W::helipad_x)("helipad_y", &W::helipad_y)("helipad_image", &W::helipad_image)(
      "texels_per_metre", &W::texels_per_metre)("route_margin", &W::route_margin)(
      "route_clearance", &W::route_clearance)("cruise_altitude", &W::cruise_altitude)("field_x", &W::field_x)(
      "field_y", &W::field_y)("sky_z", &W::sky_z)("field_texels_per_metre", &W::field_texels_per_metre)(
      "vehicle_texels_per_metre", &W::vehicle_texels_per_metre)("vehicle_length", &W::vehicle_length)(
      "vehicle_width", &W::vehicle_width)("vehicle_height", &W::vehicle_height)(
      "vehicle_yaw_deg", &W::vehicle_yaw_deg)("road_width", &W::road_width)("sun_azimuth_deg", &W::sun_azimuth_deg)(
      "sun_elevation_deg", &W::sun_elevation_deg)
      .finish();
  if (w.kind != "room" && w.kind != "field")
    throw std::runtime_error(c.origin() + ": key 'kind' must be room or field (got '" + w.kind + "')");
  return w;
}

RigConfig load_rig_config(const util::Config& c, RigConfig r) {
  using R = RigConfig;
  SectionReader<R>(c, r)("width", &R::width)("height", &R::height)("baseline", &R::baseline)(
      "hfov_deg", &R::hfov_deg)("vfov_deg", &R::vfov_deg)("pitch_deg", &R::pitch_deg)("color", &R::color)(
      "noise_sigma", &R::noise_sigma)("noise_seed", &R::noise_seed)("exposure", &R::exposure)(
      "illumination_amplitude", &R::illumination_amplitude)("illumination_period", &R::illumination_period)(
      "right_gain", &R::right_gain)("motion_blur_samples", &R::motion_blur_samples)(
      "exposure_time", &R::exposure_time)("disparity", &R::disparity)
      .finish();
  return r;
}

TrajectoryConfig load_trajectory_config(const util::Config& c) {
  TrajectoryConfig t;
  using T = TrajectoryConfig;
  SectionReader<T>(c, t)("kind", &T::kind)("speed", &T::speed)("loops", &T::loops)("rate_hz", &T::rate_hz)(
      "start_utime", &T::start_utime)
      .finish();
  if (t.kind != "demo" && t.kind != "loops" && t.kind != "landing")
    throw std::runtime_error(c.origin() + ": key 'kind' must be demo, loops or landing (got '" + t.kind + "')");
  return t;
}

namespace {

// The intruder's look (sky, aircraft, camera, image), shared by the intruder and the exit sequences.
SectionReader<IntruderConfig> read_look(const util::Config& c, IntruderConfig& i) {
  using I = IntruderConfig;
  SectionReader<I> r(c, i);
  r("seed", &I::seed)("width", &I::width)("height", &I::height)("rate_hz", &I::rate_hz)(
      "start_utime", &I::start_utime)("vibration_px", &I::vibration_px)("wingspan_px", &I::wingspan_px)(
      "max_roll_deg", &I::max_roll_deg)("noise_sigma", &I::noise_sigma)("color", &I::color);
  return r;
}

}  // namespace

IntruderConfig load_intruder_config(const util::Config& c) {
  IntruderConfig i;
  using I = IntruderConfig;
  read_look(c, i)("frames", &I::frames)("scale_change", &I::scale_change).finish();
  return i;
}

ExitsConfig load_exits_config(const util::Config& config) {
  config.check_keys({"exits.*"});
  const util::Config c = config.section("exits");
  ExitsConfig e;
  using E = ExitsConfig;
  SectionReader<E> r(c, e);
  const SectionReader<IntruderConfig> look = read_look(c, e.look);
  for (const auto& key : look.keys()) r.known(key);
  r("scale_amplitude", &E::scale_amplitude)("exits", &E::exits)("kinds", &E::kinds)(
      "in_frames_min", &E::in_frames_min)("in_frames_max", &E::in_frames_max)("out_frames_min", &E::out_frames_min)(
      "out_frames_max", &E::out_frames_max)("min_visible", &E::min_visible)("pan_speed_px", &E::pan_speed_px)(
      "drift_speed_px", &E::drift_speed_px)("reenter_elsewhere", &E::reenter_elsewhere)
      .finish();
  try {
    validate_exits_config(e);
  } catch (const std::invalid_argument& x) {
    throw std::runtime_error(c.origin() + ": " + x.what());
  }
  return e;
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
  World world = World::make(s.world);
  Trajectory trajectory = make_trajectory(world, s.trajectory);
  return StereoSimulation(std::move(world), s.rig, std::move(trajectory), s.trajectory.rate_hz,
                          s.trajectory.start_utime);
}

}  // namespace aerie::sim
