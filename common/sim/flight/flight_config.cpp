#include "common/sim/flight/flight_config.hpp"

#include "common/sim/camera/camera_effects_config.hpp"
#include "common/sim/sim_config.hpp"
#include "common/util/section_reader.hpp"

namespace aerie::sim {

namespace {

MultirotorParams load_vehicle(const util::Config& c) {
  MultirotorParams p = MultirotorParams::by_name(c.get<std::string>("class", "ardrone"));
  using M = MultirotorParams;
  util::SectionReader<M>(c, p)
      .known("class")("vertical_time_constant_s", &M::vertical_time_constant_s)(
          "max_horizontal_speed_m_s", &M::max_horizontal_speed_m_s)("max_vertical_speed_m_s", &M::max_vertical_speed_m_s)(
          "max_tilt_deg", &M::max_tilt_deg)("drag_per_s", &M::drag_per_s)(
          "velocity_integral_per_s2", &M::velocity_integral_per_s2)("position_hold_per_s", &M::position_hold_per_s)(
          "hold_drift_m_per_sqrt_s", &M::hold_drift_m_per_sqrt_s)(
          "attitude_time_constant_s", &M::attitude_time_constant_s)("takeoff_height_m", &M::takeoff_height_m)(
          "takeoff_speed_m_s", &M::takeoff_speed_m_s)("land_speed_m_s", &M::land_speed_m_s)("radius_m", &M::radius_m)(
          "max_touchdown_speed_m_s", &M::max_touchdown_speed_m_s)("command_timeout_s", &M::command_timeout_s)(
          "max_height_m", &M::max_height_m)
      .known("yaw_time_constant_s")
      .known("velocity_time_constant_s")
      .known("max_yaw_rate_deg_s")
      .known("command_delay_s")
      .finish();
  using V = VehicleParams;
  util::SectionReader<V>(c, p.base)("yaw_time_constant_s", &V::yaw_time_constant_s)(
      "velocity_time_constant_s", &V::velocity_time_constant_s)("max_yaw_rate_deg_s", &V::max_yaw_rate_deg_s)(
      "command_delay_s", &V::command_delay_s);
  p.validate();
  return p;
}

ImuParams load_imu(const util::Config& c) {
  ImuParams p;
  using I = ImuParams;
  util::SectionReader<I>(c, p)("rate_hz", &I::rate_hz)("gyro_noise_density", &I::gyro_noise_density)(
      "gyro_random_walk", &I::gyro_random_walk)("accel_noise_density", &I::accel_noise_density)(
      "accel_random_walk", &I::accel_random_walk)("gyro_initial_bias", &I::gyro_initial_bias)(
      "accel_initial_bias", &I::accel_initial_bias)("attitude_error_deg", &I::attitude_error_deg)(
      "heading_error_deg", &I::heading_error_deg)("attitude_error_time_constant_s", &I::attitude_error_time_constant_s)
      .finish();
  p.validate();
  return p;
}

}  // namespace

FlightSimConfig load_flight_config(const util::Config& cfg) {
  FlightSimConfig f;
  using F = FlightSimConfig;
  util::SectionReader<F>(cfg, f)
      .known("world")
      .known("vehicle")
      .known("imu")
      .known("down_camera")
      .known("calibration_error")
      .known("stereo_rig")
      .known("wind")
      .known("vibration")
      .known("placement")
      .known("platform")
      .known("camera_effects")("stereo", &F::stereo)("frame_rate_hz", &F::frame_rate_hz)("max_time_s", &F::max_time_s)(
          "seed", &F::seed)("start_utime", &F::start_utime)
      .finish();
  f.world = load_world_config(cfg.section("world"));
  f.vehicle = load_vehicle(cfg.section("vehicle"));
  f.imu = load_imu(cfg.section("imu"));
  f.down_camera = load_rig_config(cfg.section("down_camera"), FlightSimConfig::down_rig());
  f.stereo_rig = load_rig_config(cfg.section("stereo_rig"));
  const util::Config effects = cfg.section("camera_effects");
  effects.check_keys({"down.*", "stereo.*"});
  f.down_effects = load_camera_effects(effects.section("down"));
  f.stereo_effects = load_camera_effects(effects.section("stereo"));
  using C = CalibrationError;
  util::SectionReader<C>(cfg.section("calibration_error"), f.calibration_error)("focal_rel", &C::focal_rel)(
      "principal_px", &C::principal_px)
      .finish();
  using W = WindParams;
  util::SectionReader<W>(cfg.section("wind"), f.wind)("mean_m_s", &W::mean_m_s)("gust_std_m_s", &W::gust_std_m_s)(
      "gust_time_constant_s", &W::gust_time_constant_s)("yaw_gust_std_per_speed", &W::yaw_gust_std_per_speed)(
      "yaw_gust_time_constant_s", &W::yaw_gust_time_constant_s)("model", &W::model)("w20_m_s", &W::w20_m_s)
      .finish();
  using T = PlatformParams;
  util::SectionReader<T>(cfg.section("platform"), f.platform)("motion", &T::motion)("speed_m_s", &T::speed_m_s)(
      "heading_deg", &T::heading_deg)("start_time_s", &T::start_time_s)("turn_rate_deg_s", &T::turn_rate_deg_s)(
      "brake_time_s", &T::brake_time_s)("deceleration_m_s2", &T::deceleration_m_s2)
      .finish();
  using V = VibrationParams;
  util::SectionReader<V>(cfg.section("vibration"), f.vibration)("enabled", &V::enabled)(
      "amplitude_deg", &V::amplitude_deg)("frequency_hz", &V::frequency_hz)
      .finish();
  using P = PlacementParams;
  util::SectionReader<P>(cfg.section("placement"), f.placement)("pad_yaw_deg", &P::pad_yaw_deg)(
      "start_distance_min_m", &P::start_distance_min_m)("start_distance_max_m", &P::start_distance_max_m)(
      "start_yaw_deg", &P::start_yaw_deg)("clearance_radius_m", &P::clearance_radius_m)(
      "exposure_jitter", &P::exposure_jitter)("start_x_m", &P::start_x_m)("start_y_m", &P::start_y_m)(
      "start_height_m", &P::start_height_m)
      .finish();
  f.validate();
  return f;
}

}  // namespace aerie::sim
