#include "loop/avoidance.hpp"

#include <aerie/control_cmd_t.hpp>
#include <aerie/pose_t.hpp>

#include <unistd.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <stdexcept>

#include "air/nav/node/nav_node.hpp"
#include "common/bus/status.hpp"
#include "common/flc/flc_io.hpp"
#include "common/sim/flight/flight_config.hpp"
#include "common/sim/vehicle/scenario_config.hpp"

namespace aerie::loop::avoidance {

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;
double wrap180(double a) { return std::remainder(a, 360.0); }

// A file the vehicle keeps on its disk for one flight (aerie-control's anchor, aerie-nav's
// snapshot), so that a respawned node resumes from it; one per flight and node (flights run in
// parallel), removed with the flight.
struct FlightFile {
  std::string path;
  explicit FlightFile(const std::string& suffix) {
    static std::atomic<int64_t> next{0};
    path = (std::filesystem::temp_directory_path() /
            ("aerie-avoidance-" + std::to_string(::getpid()) + "-" + std::to_string(next++) + "." + suffix))
               .string();
  }
  ~FlightFile() {
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
  }
};
}  // namespace

Source source_from_name(const std::string& name) {
  if (name == "gt") return Source::kGt;
  if (name == "vo") return Source::kVo;
  if (name == "vio") return Source::kVio;
  throw std::invalid_argument("heading source must be gt, vo or vio, not '" + name + "'");
}

const char* source_name(Source source) {
  switch (source) {
    case Source::kGt: return "gt";
    case Source::kVo: return "vo";
    case Source::kVio: return "vio";
  }
  return "?";
}

RunConfig load_avoidance_run(const util::Config& cfg, const std::string& base_dir) {
  const auto file = [&](const char* key) {
    const std::string f = cfg.get<std::string>(key, std::string("config/") + key + ".yaml");
    return util::Config::load(f.starts_with('/') ? f : base_dir + "/" + f);
  };
  sim::require_known_keys(cfg, {"sim", "scene", "settle_band_deg", "control", "vo", "nav"});
  RunConfig rc;
  rc.sim = sim::load_flight_config(cfg.section("sim"));
  rc.scene = sim::scene_from(cfg.section("scene"));
  rc.settle_band_deg = cfg.get_in("settle_band_deg", rc.settle_band_deg, 0.1, 45.0);
  const auto c = cfg.section("control");
  sim::require_known_keys(c, {"stale_timeout_s", "limits"});
  rc.control.control.stale_timeout_s = c.get("stale_timeout_s", rc.control.control.stale_timeout_s);
  const auto lim = c.section("limits");
  sim::require_known_keys(lim, {"max_yaw_rate_deg_s", "max_yaw_accel_deg_s2"});
  rc.control.control.limits.max_yaw_rate_deg_s = lim.get("max_yaw_rate_deg_s", rc.control.control.limits.max_yaw_rate_deg_s);
  rc.control.control.limits.max_yaw_accel_deg_s2 =
      lim.get("max_yaw_accel_deg_s2", rc.control.control.limits.max_yaw_accel_deg_s2);
  rc.vo = stereo::load_vo_node_config(file("vo"));
  rc.nav = nav::load_nav_config(file("nav"));
  if (!rc.sim.placement.given_start() || rc.sim.placement.start_yaw_deg >= 1e9 || rc.sim.placement.start_height_m <= 0)
    throw std::runtime_error(cfg.origin() + ": sim.placement needs start_x_m, start_y_m, start_yaw_deg and "
                             "start_height_m > 0 (the vehicle starts hovering, facing the wall)");
  rc.controller = flc::thesis_initial();
  return rc;
}

flc::FlcSpec controller_named(const std::string& name, const std::string& base_dir) {
  if (name == "initial") return flc::thesis_initial();
  const bool bare = name.find('/') == std::string::npos && name.find('.') == std::string::npos;
  return flc::load_controller(bare ? base_dir + "/config/flc/" + name + ".yaml" : name);
}

RunResult fly(const RunConfig& config) {
  RunResult r;
  sim::FlightSimConfig sc = config.sim;
  sc.stereo = config.source != Source::kGt;  // the truth needs no images
  // Every node below answers on this thread: the buses settled = the frame answered.
  Harness harness(config, sc);
  sim::FlightSim& simulator = harness.sim();
  const util::NodeClock now = harness.clock();

  // The scene, measured from the start along its heading; the wall must be where it says.
  const sim::MultirotorState start = simulator.vehicle().state();
  const Eigen::Vector2d ahead(std::cos(start.yaw), std::sin(start.yaw)), right(std::sin(start.yaw), -std::cos(start.yaw));
  const auto hit = simulator.world().raycast(start.position, {ahead.x(), ahead.y(), 0.0});
  if (!hit || std::abs(hit->t - config.scene.wall_y_m) > 0.1)
    throw std::invalid_argument("avoidance: the surface ahead of the start is " + (hit ? std::to_string(hit->t) : "none") +
                                " m away; scene.wall_m is " + std::to_string(config.scene.wall_y_m));

  bus::Bus &vo_bus = harness.bus_of("vo"), &nav_bus = harness.bus_of("nav"), &control_bus = harness.bus_of("control");
  bus::StatusReporter vo_status(vo_bus, "vo"), control_status(control_bus, "control");
  std::optional<faults::Respawnable<stereo::VoNode>> vo_node;
  std::optional<faults::Respawnable<nav::NavNode>> nav_node;
  control::NodeOptions co = config.control;
  co.rate_hz = 0;  // one command per input: the frame's answer
  co.control.forward_speed_m_s = config.speed_m_s;
  co.control.activation_distance_m = config.scene.normal_area_m;
  co.control.reference_deg = 90;  // parallel to the wall, turning right
  co.control.reference_relative = true;
  switch (config.source) {
    case Source::kGt: co.input = control::NodeOptions::Input::kGtPose; break;
    case Source::kVo: co.input = control::NodeOptions::Input::kVoPose; break;
    case Source::kVio: co.input = control::NodeOptions::Input::kNavState; break;
  }
  co.pose_channel = control::default_pose_channel(co.input);
  const FlightFile anchor_file("anchor"), nav_state_file("nav-state");
  co.anchor_file = anchor_file.path;
  co.frame = control::default_heading_frame(co.input);
  if (config.source != Source::kGt) {
    stereo::VoNodeConfig vc = config.vo;
    vc.vo.ba_synchronous = true;
    vc.depth = "";
    vo_node.emplace(vo_bus, [&, vc] { return std::make_unique<stereo::VoNode>(vo_bus, vo_status, vc, now); });
  }
  if (config.source == Source::kVo) {
    // VO's world is its first left camera frame: the rig's up and forward, seen from the camera
    // (the vehicle starts level, hovering).
    const Eigen::Matrix3d R_body_cam = sim::body_to_left(sc.stereo_rig).rotation().toRotationMatrix();
    co.frame.up = R_body_cam.transpose() * Eigen::Vector3d::UnitZ();
    co.frame.forward = R_body_cam.transpose() * Eigen::Vector3d::UnitX();
  }
  nav::NavConfig nc = config.nav;
  nc.resume.state_file = nav_state_file.path;
  if (config.source == Source::kVio)
    nav_node.emplace(nav_bus, [&] { return std::make_unique<nav::NavNode>(nav_bus, nc); });
  faults::Respawnable<control::ControlNode> control_node(
      control_bus, [&] { return std::make_unique<control::ControlNode>(control_bus, control_status, config.controller, co, now); });
  harness.add("control", control_node);
  if (vo_node) harness.add("vo", *vo_node);
  if (nav_node) harness.add("nav", *nav_node);

  vo_bus.subscribe<aerie::pose_t>(config.vo.pose, [&](const aerie::pose_t& m, const bus::ReceiveInfo&) {
    ++r.vo_poses;
    r.vo_not_ok += m.status != aerie::pose_t::OK;
  });
  aerie::control_cmd_t last_cmd{};
  control_bus.subscribe<aerie::control_cmd_t>(co.command_channel, [&](const aerie::control_cmd_t& m, const bus::ReceiveInfo&) {
    last_cmd = m;
    r.commands_fallback += m.mode == aerie::control_cmd_t::FALLBACK_HOVER;
  });

  const double dt = 1.0 / sc.frame_rate_hz;
  sim::SettlingStats settling(config.settle_band_deg);
  double activation_t = 0, max_travel = 0, est_sq = 0;
  std::optional<double> estimate_offset;  // estimate - truth at aerie-control's first input
  int64_t est_n = 0;
  while (true) {
    const sim::FlightFrame& f = harness.step();
    Sample s;
    s.t = f.t;
    const Eigen::Vector2d d = f.vehicle.position.head<2>() - start.position.head<2>();
    s.travel_m = d.dot(ahead);
    s.lateral_m = d.dot(right);
    s.heading_deg = wrap180(-(f.vehicle.yaw - start.yaw) / kDeg);  // clockwise positive
    s.turning = control_node.get() && control_node.get()->loop().turning();
    if (last_cmd.mode == aerie::control_cmd_t::ACTIVE) {
      if (!estimate_offset) estimate_offset = wrap180(last_cmd.heading_deg - s.heading_deg);
      s.estimate_deg = wrap180(last_cmd.heading_deg - *estimate_offset);
      s.command_deg_s = last_cmd.yaw_rate_deg_s;
      const double e = wrap180(s.estimate_deg - s.heading_deg);
      est_sq += e * e;
      ++est_n;
    }
    if (s.turning && !r.activated) {
      r.activated = true;
      activation_t = f.t;
      r.activation_travel_m = s.travel_m;
    }
    if (r.activated) settling.add(f.t - activation_t, wrap180(90.0 - s.heading_deg), dt);
    max_travel = std::max(max_travel, s.travel_m);
    r.entered_danger = r.entered_danger || s.travel_m >= config.scene.dangerous_from();
    r.completed = s.lateral_m >= config.scene.lateral_limit_m;
    r.trajectory.push_back(s);
    if (r.completed || simulator.outcome().ended()) break;
  }
  const sim::FlightOutcome& o = simulator.outcome();
  r.collided = o.collided;
  r.collision = o.collision;
  r.timed_out = o.timed_out && !r.completed;
  r.itse = settling.itse();
  r.settle_time_s = settling.settle_time_s();
  r.heading_rmse_deg = settling.steady_rmse_deg();
  r.min_wall_distance_m = config.scene.wall_y_m - max_travel;
  if (est_n) r.estimate_rmse_deg = std::sqrt(est_sq / static_cast<double>(est_n));
  if (nav_node && nav_node->get()) r.nav_gated = nav_node->get()->filter().counters().vo_gated;
  static_cast<RunStats&>(r) = harness.finish();
  return r;
}

}  // namespace aerie::loop::avoidance
