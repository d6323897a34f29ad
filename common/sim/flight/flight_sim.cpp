#include "common/sim/flight/flight_sim.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "common/sim/texture.hpp"

namespace aerie::sim {

namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

camera::CameraModel pinhole_of(const Intrinsics& K) { return K.calibration().left; }

// The real camera a stage models: the lens calibration, or the rig's pinhole with the lens'
// coefficients, or the rig's pinhole (no lens).
camera::CameraModel real_camera(const CameraEffectsConfig& fx, const Intrinsics& rig) {
  if (!fx.lens.enabled) return pinhole_of(rig);
  if (fx.lens.model.width > 0) return fx.lens.model;
  camera::CameraModel m = pinhole_of(rig);
  m.distortion = fx.lens.model.distortion;
  m.coeffs = fx.lens.model.coeffs;
  return m;
}

// A rig whose ideal (pinhole) frames cover every ray of the real camera: the lens' field of
// view when it is wider; without noise of its own when the stage adds the sensor's.
RigConfig ideal_rig(RigConfig rig, const CameraEffectsConfig& fx, const camera::CameraModel& real) {
  if (!fx.any()) return rig;
  if (fx.noise.enabled) rig.noise_sigma = 0;
  if (fx.lens.enabled) {
    const auto [h, v] = CameraEffects::fov_to_cover(real);
    rig.hfov_deg = std::min(178.0, std::max(rig.hfov_deg, h + 0.5));
    rig.vfov_deg = std::min(178.0, std::max(rig.vfov_deg, v + 0.5));
  }
  return rig;
}

// The ground truth of the pad in the ideal image moved into the real camera's image.
void distort_truth(const camera::CameraModel& real, const Intrinsics& ideal, StereoFrame& f) {
  double umin = 1e18, umax = -1e18, vmin = 1e18, vmax = -1e18;
  for (auto& c : f.target_corners) {
    if (std::isnan(c.x)) continue;
    const Eigen::Vector2d p = real.project({(c.x - ideal.cx) / ideal.fx, (c.y - ideal.cy) / ideal.fy, 1.0});
    c = {p.x(), p.y()};
    umin = std::min(umin, p.x());
    umax = std::max(umax, p.x());
    vmin = std::min(vmin, p.y());
    vmax = std::max(vmax, p.y());
    if (p.x() < -0.5 || p.y() < -0.5 || p.x() > real.width - 0.5 || p.y() > real.height - 0.5)
      f.target_visible = false;
  }
  if (umin <= umax) f.target_box = cv::Rect2d(umin, vmin, umax - umin, vmax - vmin);
}

// Wraps an angle to (-pi/2, pi/2]: the helipad's H looks the same after half a turn.
double wrap_half_turn(double a) {
  a = std::remainder(a, kPi);
  return a <= -kPi / 2 ? a + kPi : a;
}
}  // namespace

RigConfig FlightSimConfig::down_rig() {
  RigConfig r;
  r.width = 376;
  r.height = 240;
  r.baseline = 0.01;  // unused by a mono camera (the renderer needs one; it offsets the camera 5 mm)
  r.hfov_deg = 90.0;
  r.vfov_deg = 65.0;
  r.pitch_deg = 90.0;  // optical axis along body -z; image top = forward
  r.noise_sigma = 2.0;
  return r;
}

void FlightSimConfig::validate() const {
  auto need = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("flight simulator: " + what);
  };
  vehicle.validate();
  imu.validate();
  need(frame_rate_hz > 0 && frame_rate_hz <= imu.rate_hz, "frame_rate_hz must be in (0, imu.rate_hz]");
  const double ratio = imu.rate_hz / frame_rate_hz;
  need(std::abs(ratio - std::round(ratio)) < 1e-9, "imu.rate_hz must be a whole multiple of frame_rate_hz");
  need(wind.mean_m_s >= 0 && wind.mean_m_s <= 15, "wind.mean_m_s must be in [0, 15]");
  need(wind.gust_time_constant_s > 0, "wind.gust_time_constant_s must be > 0");
  need(wind.model == "gauss_markov" || wind.model == "dryden",
       "wind.model must be gauss_markov or dryden (got '" + wind.model + "')");
  need(wind.w20_m_s <= 15, "wind.w20_m_s must be <= 15 (< 0: mean_m_s)");
  platform.validate();
  need(!platform.moving() || world.kind == "field",
       "platform: a moving platform needs world.kind field (the room's helipad is the floor)");
  need(wind.yaw_gust_std_per_speed >= 0 && wind.yaw_gust_std_per_speed <= 50,
       "wind.yaw_gust_std_per_speed must be in [0, 50] (deg/s per m/s)");
  need(wind.yaw_gust_time_constant_s > 0, "wind.yaw_gust_time_constant_s must be > 0");
  need(std::isnan(placement.start_x_m) == std::isnan(placement.start_y_m),
       "placement: give both start_x_m and start_y_m, or neither");
  need(placement.start_height_m >= 0 && placement.start_height_m <= 50, "placement.start_height_m must be in [0, 50]");
  need(vibration.amplitude_deg >= 0 && vibration.amplitude_deg <= 10, "vibration.amplitude_deg must be in [0, 10]");
  need(vibration.frequency_hz > 0, "vibration.frequency_hz must be > 0");
  need(placement.start_distance_min_m >= 0 && placement.start_distance_max_m >= placement.start_distance_min_m,
       "placement: need 0 <= start_distance_min_m <= start_distance_max_m");
  need(placement.exposure_jitter >= 0 && placement.exposure_jitter < 0.9, "placement.exposure_jitter must be in [0, 0.9)");
  need(max_time_s > 0, "max_time_s must be > 0");
  need(down_camera.width > 0 && down_camera.height > 0, "down_camera size must be > 0");
  need(calibration_error.focal_rel >= 0 && calibration_error.focal_rel < 0.2 && calibration_error.principal_px >= 0,
       "calibration_error: focal_rel must be in [0, 0.2), principal_px >= 0");
}

// The world of layout `layout` (0, then 1, 2, ... when a layout has no free take-off
// point): its obstacles and textures, the pad's place and yaw all come from the seed.
World FlightSim::draw_world(int layout) {
  WorldConfig w = cfg_.world;
  w.seed = mix_seed(cfg_.seed, 7000 + 10 * static_cast<uint64_t>(layout));
  std::mt19937_64 placement(mix_seed(cfg_.seed, 7001 + 10 * static_cast<uint64_t>(layout)));
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  w.helipad_yaw_deg = cfg_.placement.pad_yaw_deg < 0 ? 180.0 * u01(placement) : cfg_.placement.pad_yaw_deg;
  if (w.kind == "room" && std::isnan(cfg_.world.helipad_x) && std::isnan(cfg_.world.helipad_y)) {
    // Anywhere in the middle half of the room (the field places its car itself).
    w.helipad_x = (u01(placement) - 0.5) * 0.5 * w.room_x;
    w.helipad_y = (u01(placement) - 0.5) * 0.5 * w.room_y;
  }
  return World::make(w);
}

bool FlightSim::column_free(const Eigen::Vector3d& p) const {
  // On the ground, not on an object; the column it climbs (or starts in) clear; nothing within
  // clearance_radius_m of the column at the take-off height (room to search).
  const double r = cfg_.vehicle.radius_m;
  const double top = std::max(cfg_.vehicle.takeoff_height_m, cfg_.placement.start_height_m);
  bool free = p.z() <= world_.bounds().min.z() + 1e-9;
  for (double h = 0.2; free && h <= top + 0.3; h += 0.1)
    free = world_.signed_distance(p + Eigen::Vector3d(0, 0, r + h)) > r + 0.15;
  const double z = p.z() + top + r;
  for (double rad = 0.5; free && rad <= cfg_.placement.clearance_radius_m + 1e-9; rad += 0.5)
    for (int k = 0; free && k < 16; ++k)
      free = world_.signed_distance({p.x() + rad * std::cos(k * kPi / 8), p.y() + rad * std::sin(k * kPi / 8), z}) > r + 0.2;
  return free;
}

std::optional<Eigen::Vector3d> FlightSim::takeoff_point() {
  if (cfg_.placement.given_start()) {
    Eigen::Vector3d p(cfg_.placement.start_x_m, cfg_.placement.start_y_m, 10.0);
    p.z() = support_height(p);
    return column_free(p) ? std::optional(p) : std::nullopt;
  }
  // On free ground at the drawn distance from the pad.
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const Helipad& pad = world_.helipad();
  for (int attempt = 0; attempt < 500; ++attempt) {
    const double d = cfg_.placement.start_distance_min_m +
                     (cfg_.placement.start_distance_max_m - cfg_.placement.start_distance_min_m) * u01(rng_);
    const double phi = 2 * kPi * u01(rng_);
    Eigen::Vector3d p(pad.center.x() + d * std::cos(phi), pad.center.y() + d * std::sin(phi), 10.0);
    p.z() = support_height(p);
    if (column_free(p)) return p;
  }
  return std::nullopt;
}

FlightSim::FlightSim(const FlightSimConfig& config)
    : cfg_(config),
      world_((cfg_.validate(), draw_world(0))),
      down_(world_, cfg_.down_camera),
      forward_(world_, cfg_.stereo_rig),
      vehicle_(cfg_.vehicle, {}),
      imu_(cfg_.imu, mix_seed(cfg_.seed, 7002)),
      rng_(mix_seed(cfg_.seed, 7003)) {
  std::optional<Eigen::Vector3d> start_point = takeoff_point();
  constexpr int kLayouts = 10;
  for (int layout = 1; !start_point && layout < kLayouts; ++layout) {
    world_ = draw_world(layout);
    start_point = takeoff_point();
  }
  if (!start_point && cfg_.placement.given_start())
    throw std::invalid_argument("flight simulator: the given start (" + std::to_string(cfg_.placement.start_x_m) + ", " +
                                std::to_string(cfg_.placement.start_y_m) + ") is not free ground with " +
                                "clearance_radius_m around it in " + std::to_string(kLayouts) +
                                " layouts; move it or lower n_obstacles");
  if (!start_point)
    throw std::invalid_argument("flight simulator: no free take-off point between " +
                                std::to_string(cfg_.placement.start_distance_min_m) + " and " +
                                std::to_string(cfg_.placement.start_distance_max_m) + " m from the pad in " +
                                std::to_string(kLayouts) + " layouts; lower n_obstacles or clearance_radius_m");
  cfg_.world = world_.config();

  // Lighting, image noise.
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const double j = cfg_.placement.exposure_jitter;
  RigConfig down = cfg_.down_camera;
  down.exposure *= 1.0 - j + 2 * j * u01(rng_);
  down.noise_seed = mix_seed(cfg_.seed, 7004);
  RigConfig fwd = cfg_.stereo_rig;
  fwd.exposure = down.exposure / cfg_.down_camera.exposure * fwd.exposure;
  fwd.noise_seed = mix_seed(cfg_.seed, 7005);
  // The real camera the effects model keeps the configured rig's intrinsics (or its lens
  // calibration's); the ideal frames it starts from may be wider (ideal_rig).
  auto real_of = [&](const CameraEffectsConfig& fx, const RigConfig& rig) {
    return fx.any() ? real_camera(fx, StereoRenderer(world_, rig).intrinsics()) : camera::CameraModel{};
  };
  const camera::CameraModel down_real = real_of(cfg_.down_effects, down);
  const camera::CameraModel fwd_real = real_of(cfg_.stereo_effects, fwd);
  down = ideal_rig(down, cfg_.down_effects, down_real);
  fwd = ideal_rig(fwd, cfg_.stereo_effects, fwd_real);
  down_ = StereoRenderer(world_, down);
  forward_ = StereoRenderer(world_, fwd);
  auto stage = [&](CameraEffectsConfig fx, const camera::CameraModel& real, const Intrinsics& ideal, uint64_t stream,
                   const std::string& what) {
    fx.noise.seed = mix_seed(mix_seed(cfg_.seed, stream), fx.noise.seed);
    if (fx.lens.enabled) fx.lens.model = real;
    return Effects{CameraEffects(fx, pinhole_of(ideal), what), real};
  };
  if (cfg_.down_effects.any())
    down_fx_ = stage(cfg_.down_effects, down_real, down_.intrinsics(), 7008, "camera_effects.down");
  if (cfg_.stereo && cfg_.stereo_effects.any()) {
    left_fx_ = stage(cfg_.stereo_effects, fwd_real, forward_.intrinsics(), 7009, "camera_effects.stereo (left)");
    right_fx_ = stage(cfg_.stereo_effects, fwd_real, forward_.intrinsics(), 7010, "camera_effects.stereo (right)");
  }
  std::normal_distribution<double> n01(0.0, 1.0);
  down_calibration_ = down_.intrinsics();
  if (down_fx_) {  // the real camera's pinhole part (its distortion: down_fx_->real)
    down_calibration_.fx = down_real.fx;
    down_calibration_.fy = down_real.fy;
    down_calibration_.cx = down_real.cx;
    down_calibration_.cy = down_real.cy;
  }
  const double focal = 1.0 + cfg_.calibration_error.focal_rel * n01(rng_);
  down_calibration_.fx *= focal;
  down_calibration_.fy *= focal;
  down_calibration_.cx += cfg_.calibration_error.principal_px * n01(rng_);
  down_calibration_.cy += cfg_.calibration_error.principal_px * n01(rng_);
  T_body_down_ = body_to_left(down);
  T_body_left_ = body_to_left(fwd);

  MultirotorState start;
  start.position = *start_point;
  start.yaw = cfg_.placement.start_yaw_deg < 1e9 ? cfg_.placement.start_yaw_deg * kDeg : 2 * kPi * u01(rng_) - kPi;
  if (cfg_.placement.start_height_m > 0) {  // already flying: armed, holding its place
    start.position.z() += cfg_.placement.start_height_m;
    start.armed = true;
    start.on_ground = false;
    airborne_ = true;
  }
  vehicle_ = Multirotor(cfg_.vehicle, start, mix_seed(cfg_.seed, 7006));
  // The height fence over the ground it starts from; a room caps it so that the rotors stay
  // 0.2 m below the ceiling (a blind climb, HOLD's and ABORT's, must not end on it).
  double ceiling = cfg_.vehicle.max_height_m > 0 ? start_point->z() + cfg_.vehicle.max_height_m
                                                 : std::numeric_limits<double>::infinity();
  if (cfg_.world.kind == "room") ceiling = std::min(ceiling, world_.bounds().max.z() - 2 * cfg_.vehicle.radius_m - 0.2);
  vehicle_.set_ceiling(ceiling);
  q_prev_ = start.pose().rotation();

  // Wind: steady part from a drawn direction, gusts from their stationary distribution.
  const double theta = 2 * kPi * u01(rng_);
  wind_mean_ = cfg_.wind.mean_m_s * Eigen::Vector3d(std::cos(theta), std::sin(theta), 0.0);
  const double gust_y = n01(rng_), gust_x = n01(rng_);  // one draw per statement, as x86-64 GCC drew them
  gust_ = cfg_.wind.gust_std() * Eigen::Vector3d(gust_x, gust_y, 0.0);
  for (auto& axis : vib_phase_) axis = {2 * kPi * u01(rng_), 2 * kPi * u01(rng_), 0.85, 1.15};
  yaw_gust_rng_.seed(mix_seed(cfg_.seed, 7007));
  // Dryden turbulence and the platform's heading on streams of their own: every draw above
  // is the same whatever they are.
  wind_theta_ = theta;
  if (cfg_.wind.model == "dryden") {
    dryden_ = DrydenGusts(mix_seed(cfg_.seed, 7011));
    dryden_.start(dryden_scales(), (wind_mean_ - vehicle_.state().velocity).norm());
    gust_ = dryden_world(dryden_.value());
  }
  base_world_ = world_;
  if (cfg_.platform.moving()) {
    double heading = cfg_.platform.heading_deg * kDeg;
    if (std::isnan(heading)) {  // along the car's length, either way
      std::mt19937_64 g(mix_seed(cfg_.seed, 7012));
      const Eigen::Vector3d size = world_.landing_object()->box.size();
      heading = (size.x() >= size.y() ? 0.0 : kPi / 2) + (u01(g) < 0.5 ? 0.0 : kPi);
    }
    platform_ = PlatformMotion(cfg_.platform, heading);
  }
}

DrydenScales FlightSim::dryden_scales() const {
  const double w20 = cfg_.wind.w20_m_s < 0 ? cfg_.wind.mean_m_s : cfg_.wind.w20_m_s;
  return dryden_low_altitude(vehicle_.state().position.z() - world_.bounds().min.z(), w20);
}

// Dryden's (u, v, w): along the mean wind, across it (to its left), up.
Eigen::Vector3d FlightSim::dryden_world(const Eigen::Vector3d& uvw) const {
  const double c = std::cos(wind_theta_), s = std::sin(wind_theta_);
  return {c * uvw.x() - s * uvw.y(), s * uvw.x() + c * uvw.y(), uvw.z()};
}

Eigen::Vector2d FlightSim::platform_velocity() const {
  return platform_stopped_ ? Eigen::Vector2d::Zero() : platform_.velocity(t_);
}

void FlightSim::move_platform(double t) {
  if (!cfg_.platform.moving() || platform_stopped_) return;
  const Eigen::Vector2d d = platform_.offset(t);
  // The car stops at the field's edge (0.5 m inside it).
  const Aabb& b = base_world_.landing_object()->box;
  const Aabb& field = base_world_.bounds();
  if (b.min.x() + d.x() < field.min.x() + 0.5 || b.max.x() + d.x() > field.max.x() - 0.5 ||
      b.min.y() + d.y() < field.min.y() + 0.5 || b.max.y() + d.y() > field.max.y() - 0.5) {
    platform_stopped_ = true;
    return;
  }
  platform_offset_ = d;
  world_ = base_world_.with_landing_offset(d);
}

void FlightSim::set_start_utime(int64_t utime) {
  if (frame_ >= 0) throw std::logic_error("FlightSim::set_start_utime after the first step");
  cfg_.start_utime = utime;
}

int64_t FlightSim::utime_of(double t) const { return cfg_.start_utime + std::llround(t * 1e6); }

double FlightSim::support_height(const Eigen::Vector3d& p) const {
  double z = world_.bounds().min.z();
  for (const auto& o : world_.obstacles()) {
    const Aabb& b = o.box;
    if (p.x() >= b.min.x() && p.x() <= b.max.x() && p.y() >= b.min.y() && p.y() <= b.max.y() &&
        b.max.z() <= p.z() + 0.05)
      z = std::max(z, b.max.z());
  }
  return z;
}

Eigen::Vector3d FlightSim::wind_step(double dt) {
  if (cfg_.wind.model == "dryden") {
    // The airspeed the turbulence is advected past the vehicle with (Taylor's hypothesis).
    const double airspeed = (wind_mean_ - vehicle_.state().velocity).norm();
    gust_ = dryden_world(dryden_.step(dt, dryden_scales(), airspeed));
    return wind_mean_ + gust_;
  }
  // First-order Gauss-Markov gusts per horizontal axis, exact discretisation.
  const double a = std::exp(-dt / cfg_.wind.gust_time_constant_s), k = std::sqrt(1 - a * a) * cfg_.wind.gust_std();
  std::normal_distribution<double> n01(0.0, 1.0);
  gust_.x() = a * gust_.x() + k * n01(rng_);
  gust_.y() = a * gust_.y() + k * n01(rng_);
  return wind_mean_ + gust_;
}

double FlightSim::yaw_gust_step(double dt) {
  // First-order Gauss-Markov, exact discretisation; its std grows with the horizontal speed.
  if (cfg_.wind.yaw_gust_std_per_speed <= 0) return 0.0;
  const double std = cfg_.wind.yaw_gust_std_per_speed * vehicle_.state().velocity.head<2>().norm();
  const double a = std::exp(-dt / cfg_.wind.yaw_gust_time_constant_s);
  yaw_gust_deg_s_ = a * yaw_gust_deg_s_ + std::sqrt(1 - a * a) * std * std::normal_distribution<double>(0.0, 1.0)(yaw_gust_rng_);
  return yaw_gust_deg_s_;
}

geometry::SE3 FlightSim::vibration(double t) const {
  if (!cfg_.vibration.enabled || cfg_.vibration.amplitude_deg <= 0) return {};
  // Two tones per axis at +-15 % of the centre frequency; each tone's amplitude makes the
  // sum's RMS the configured one (RMS of a sine is A / sqrt(2)).
  const double a = cfg_.vibration.amplitude_deg * kDeg;
  Eigen::Vector3d w;
  for (int i = 0; i < 3; ++i) {
    const auto& p = vib_phase_[i];
    w[i] = a * (std::sin(2 * kPi * cfg_.vibration.frequency_hz * p[2] * t + p[0]) +
                std::sin(2 * kPi * cfg_.vibration.frequency_hz * p[3] * t + p[1]));
  }
  return geometry::SE3::from_rotation_vector(w, Eigen::Vector3d::Zero());
}

std::string FlightSim::command(const CommandInput& c) {
  const auto& p = cfg_.vehicle;
  std::string why;
  const bool finite = std::isfinite(c.velocity[0]) && std::isfinite(c.velocity[1]) && std::isfinite(c.velocity[2]) &&
                      std::isfinite(c.yaw_rate_deg_s);
  if (c.mode < 0 || c.mode > 4) {
    why = "unknown mode " + std::to_string(c.mode);
  } else if (!finite) {
    why = "velocity or yaw rate is not finite";
  } else if (std::hypot(c.velocity[0], c.velocity[1]) > 1.5 * p.max_horizontal_speed_m_s) {
    why = "horizontal speed " + std::to_string(std::hypot(c.velocity[0], c.velocity[1])) + " m/s exceeds 1.5 x the limit";
  } else if (std::abs(c.velocity[2]) > 1.5 * p.max_vertical_speed_m_s) {
    why = "vertical speed " + std::to_string(c.velocity[2]) + " m/s exceeds 1.5 x the limit";
  } else if (std::abs(c.yaw_rate_deg_s) > 1.5 * p.base.max_yaw_rate_deg_s) {
    why = "yaw rate " + std::to_string(c.yaw_rate_deg_s) + " deg/s exceeds 1.5 x the limit";
  }
  AutopilotCommand a;  // refused: hold (hover)
  if (why.empty()) {
    using Mode = AutopilotCommand::Mode;
    static constexpr Mode kModes[] = {Mode::Hover, Mode::Velocity, Mode::Hover, Mode::Takeoff, Mode::Land};
    a.mode = kModes[c.mode];
    a.velocity = {c.velocity[0], c.velocity[1], c.velocity[2]};
    a.yaw_rate_deg_s = c.yaw_rate_deg_s;
    ++applied_;
  } else {
    ++refused_;
    last_refusal_ = why;
  }
  vehicle_.command(t_, a);
  return why;
}

void FlightSim::physics_step(double dt) {
  // A disarmed vehicle standing on the car's roof rides with it.
  const Eigen::Vector2d platform_before = platform_offset_;
  const Obstacle* car = world_.landing_object();
  const Eigen::Vector3d& p = vehicle_.state().position;
  const bool on_car = car && !vehicle_.state().armed && vehicle_.state().on_ground &&
                      std::abs(p.z() - car->box.max.z()) < 1e-6 && p.x() >= car->box.min.x() &&
                      p.x() <= car->box.max.x() && p.y() >= car->box.min.y() && p.y() <= car->box.max.y();
  move_platform(t_ + dt);
  if (on_car && platform_offset_ != platform_before) {  // the roof carries what stands on it
    const Eigen::Vector2d d = platform_offset_ - platform_before;
    vehicle_.carry({d.x(), d.y(), 0.0});
  }
  if (outcome_.collided || outcome_.landed) return;
  const Eigen::Vector3d wind = wind_step(dt);
  const double vz_before = vehicle_.state().velocity.z();
  vehicle_.step(t_, dt, wind, yaw_gust_step(dt));
  const auto& s = vehicle_.state();
  const double z_support = support_height(s.position);
  if (s.position.z() <= z_support) {
    const double vz = std::min(vz_before, s.velocity.z());
    if (airborne_) {
      if (-vz > cfg_.vehicle.max_touchdown_speed_m_s) {
        outcome_.collided = true;
        outcome_.collision = "hard landing at " + std::to_string(-vz) + " m/s";
      }
      if (outcome_.touchdown_time_s < 0) {
        outcome_.touchdown_time_s = t_ + dt;
        outcome_.touchdown_position = {s.position.x(), s.position.y(), z_support};
        outcome_.touchdown_yaw = s.yaw;
        outcome_.touchdown_vertical_speed = -vz;
        outcome_.touchdown_pad_center = world_.helipad().center;
        outcome_.touchdown_pad_velocity = platform_stopped_ ? Eigen::Vector2d::Zero() : platform_.velocity(t_ + dt);
      }
    }
    vehicle_.set_contact(z_support);
    airborne_ = false;
    if (!vehicle_.state().armed && outcome_.touchdown_time_s >= 0 && !outcome_.collided) outcome_.landed = true;
  } else if (s.position.z() > z_support + 0.05) {
    airborne_ = true;
  }
  // Anything but the surface it stands on within the rotor radius is a collision.
  const double r = cfg_.vehicle.radius_m;
  const Eigen::Vector3d centre = vehicle_.state().position + Eigen::Vector3d(0, 0, r);
  const double d = world_.signed_distance(centre);
  if (!outcome_.collided && d < r - 0.02) {
    outcome_.collided = true;
    outcome_.collision = "rotor " + std::to_string(d) + " m from a surface at (" +
                         std::to_string(centre.x()) + ", " + std::to_string(centre.y()) + ", " +
                         std::to_string(centre.z()) + ")";
  }
}

FlightFrame FlightSim::step() {
  FlightFrame f;
  const int substeps = static_cast<int>(std::lround(cfg_.imu.rate_hz / cfg_.frame_rate_hz));
  const double dt = 1.0 / cfg_.imu.rate_hz;
  auto imu_sample = [&](double t) {
    const auto& s = vehicle_.state();
    const Eigen::Quaterniond q = s.pose().rotation();
    const Eigen::AngleAxisd turn(q_prev_.conjugate() * q);
    const Eigen::Vector3d omega = turn.angle() * turn.axis() / dt;
    omega_body_ = omega;
    q_prev_ = q;
    f.imu.push_back(imu_.sample(t, q, omega, s.armed ? s.acceleration : Eigen::Vector3d::Zero()));
  };
  if (frame_ < 0) {
    imu_sample(0.0);
  } else {
    for (int i = 1; i <= substeps; ++i) {
      physics_step(dt);
      t_ = (frame_ * substeps + i) * dt;
      imu_sample(t_);
    }
  }
  ++frame_;
  t_ = frame_ / cfg_.frame_rate_hz;
  if (t_ >= cfg_.max_time_s && !outcome_.ended()) outcome_.timed_out = true;

  f.seq = frame_;
  f.t = t_;
  f.utime = utime_of(t_);
  f.vehicle = vehicle_.state();
  f.wind = wind_mean_ + gust_;
  f.platform_velocity = platform_velocity();
  if (cfg_.platform.moving()) {  // the renderers draw the world as it is now
    down_ = StereoRenderer(world_, down_.rig());
    if (cfg_.stereo) forward_ = StereoRenderer(world_, forward_.rig());
  }
  const geometry::SE3 T_world_body = f.vehicle.pose();
  f.T_world_down = T_world_body * T_body_down_ * vibration(t_);
  f.down = down_.render_mono(f.T_world_down, f.utime, f.seq);
  if (down_fx_) {
    f.down.left = down_fx_->stage.apply(f.down.left, f.down.depth, camera_motion(f.T_world_down, T_body_down_),
                                        f.utime, f.seq);
    if (down_fx_->stage.config().lens.enabled) distort_truth(down_fx_->real, down_.intrinsics(), f.down);
  }
  f.T_world_left = T_world_body * T_body_left_ * vibration(t_ + 0.37);
  if (cfg_.stereo) f.stereo = forward_.render(f.T_world_left, f.utime, f.seq);
  if (f.stereo && left_fx_) {
    // The right view is shifted along the flow of the left's depth (parallax of the depth
    // lookup over the baseline neglected) and moves as the left camera does.
    const CameraMotion m = camera_motion(f.T_world_left, T_body_left_);
    f.stereo->left = left_fx_->stage.apply(f.stereo->left, f.stereo->depth, m, f.utime, f.seq);
    f.stereo->right = right_fx_->stage.apply(f.stereo->right, f.stereo->depth, m, f.utime, f.seq);
    if (left_fx_->stage.config().lens.enabled) distort_truth(left_fx_->real, forward_.intrinsics(), *f.stereo);
  }
  f.target = target_in(f.T_world_down);
  return f;
}

CameraMotion FlightSim::camera_motion(const geometry::SE3& T_world_cam, const geometry::SE3& T_body_cam) const {
  // The body's velocity and angular velocity in the camera frame (the mount's lever arm and
  // the vibration's own rate neglected).
  CameraMotion m;
  m.velocity = T_world_cam.rotation().conjugate() * vehicle_.state().velocity;
  m.angular_velocity = T_body_cam.rotation().conjugate() * omega_body_;
  return m;
}

TargetTruth FlightSim::target_in(const geometry::SE3& T_world_cam) const {
  const Helipad& pad = world_.helipad();
  const geometry::SE3 T_cam_world = T_world_cam.inverse();
  TargetTruth t;
  t.position = T_cam_world * pad.center;
  const Eigen::Vector3d axis = T_cam_world.rotation() * Eigen::Vector3d(std::cos(pad.yaw), std::sin(pad.yaw), 0.0);
  t.yaw = wrap_half_turn(std::atan2(axis.y(), axis.x()));
  return t;
}

LandingScore score_landing(const FlightSim& sim, double max_error_m, double max_yaw_deg) {
  const FlightOutcome& o = sim.outcome();
  LandingScore s;
  if (o.touchdown_time_s < 0) return s;
  const Helipad& pad = sim.world().helipad();
  s.touchdown_error_m = (o.touchdown_position - o.touchdown_pad_center).head<2>().norm();  // on the pad as it was then
  s.yaw_error_deg = wrap_half_turn(o.touchdown_yaw - pad.yaw) / kDeg;
  s.time_s = o.touchdown_time_s;
  s.success = o.landed && !o.collided && !o.timed_out && s.touchdown_error_m <= max_error_m &&
              std::abs(s.yaw_error_deg) < max_yaw_deg;
  return s;
}

}  // namespace aerie::sim
