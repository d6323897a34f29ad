#include "common/sim/vehicle/scenario_config.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace aerie::sim {

void require_known_keys(const util::Config& section, std::initializer_list<const char*> allowed) {
  std::vector<std::string> open;  // each allowed key with whatever it holds
  for (const char* a : allowed) open.push_back(std::string(a) + ".*");
  section.check_keys(open);
}

Scene scene_from(const util::Config& scene, Scene c) {
  require_known_keys(scene, {"wall_m", "normal_area_m", "safe_area_m", "lateral_limit_m"});
  c.wall_y_m = scene.get("wall_m", c.wall_y_m);
  c.normal_area_m = scene.get("normal_area_m", c.normal_area_m);
  c.safe_area_m = scene.get("safe_area_m", c.safe_area_m);
  c.lateral_limit_m = scene.get("lateral_limit_m", c.lateral_limit_m);
  if (!(c.normal_area_m > 0 && c.safe_area_m > 0 && c.dangerous_from() < c.wall_y_m && c.lateral_limit_m > 0))
    throw std::runtime_error(scene.origin() + ": needs 0 < normal_area_m, 0 < safe_area_m, normal + safe < wall_m and "
                             "0 < lateral_limit_m");
  return c;
}

AvoidanceConfig avoidance_config_from(const util::Config& s, AvoidanceConfig c) {
  require_known_keys(s, {"vehicle", "vehicle_params", "scene", "sensor", "camera", "gusts", "physics_substeps", "max_time_s",
                         "settle_band_deg"});
  try {
    c.vehicle = VehicleParams::by_name(s.get<std::string>("vehicle", c.vehicle.name));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(s.origin() + ": 'vehicle': " + e.what());
  }
  const auto vp = s.section("vehicle_params");
  require_known_keys(vp, {"yaw_time_constant_s", "max_yaw_rate_deg_s", "velocity_time_constant_s", "command_delay_s"});
  c.vehicle.yaw_time_constant_s = vp.get("yaw_time_constant_s", c.vehicle.yaw_time_constant_s);
  c.vehicle.max_yaw_rate_deg_s = vp.get("max_yaw_rate_deg_s", c.vehicle.max_yaw_rate_deg_s);
  c.vehicle.velocity_time_constant_s = vp.get("velocity_time_constant_s", c.vehicle.velocity_time_constant_s);
  c.vehicle.command_delay_s = vp.get("command_delay_s", c.vehicle.command_delay_s);

  c.scene = scene_from(s.section("scene"), c.scene);

  const auto sensor = s.section("sensor");
  require_known_keys(sensor, {"rate_hz", "delay_s", "noise_std_deg", "drift_deg_per_sqrt_s"});
  c.sensor.rate_hz = sensor.get("rate_hz", c.sensor.rate_hz);
  c.sensor.delay_s = sensor.get("delay_s", c.sensor.delay_s);
  c.sensor.noise_std_deg = sensor.get("noise_std_deg", c.sensor.noise_std_deg);
  c.sensor.drift_deg_per_sqrt_s = sensor.get("drift_deg_per_sqrt_s", c.sensor.drift_deg_per_sqrt_s);

  const auto camera = s.section("camera");
  require_known_keys(camera, {"fov_deg", "range_m", "angle_noise_std_deg"});
  c.camera.fov_deg = camera.get("fov_deg", c.camera.fov_deg);
  c.camera.range_m = camera.get("range_m", c.camera.range_m);
  c.camera.angle_noise_std_deg = camera.get("angle_noise_std_deg", c.camera.angle_noise_std_deg);

  const auto gusts = s.section("gusts");
  require_known_keys(gusts, {"std_per_speed", "time_constant_s"});
  c.yaw_gust_std_per_speed = gusts.get("std_per_speed", c.yaw_gust_std_per_speed);
  c.yaw_gust_time_constant_s = gusts.get("time_constant_s", c.yaw_gust_time_constant_s);

  c.physics_substeps = s.get("physics_substeps", c.physics_substeps);
  c.max_time_s = s.get("max_time_s", c.max_time_s);
  c.settle_band_deg = s.get("settle_band_deg", c.settle_band_deg);
  if (c.sensor.rate_hz <= 0 || c.sensor.delay_s < 0 || c.sensor.noise_std_deg < 0 || c.physics_substeps < 1 ||
      c.yaw_gust_time_constant_s <= 0 || c.max_time_s <= 0)
    throw std::runtime_error(s.origin() + ": rates, time constants and max_time_s must be positive, delays and noise >= 0, "
                             "physics_substeps >= 1");
  return c;
}

}  // namespace aerie::sim
