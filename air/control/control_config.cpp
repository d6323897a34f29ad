#include "air/control/control_config.hpp"

#include "common/bus/channels.hpp"
#include "common/flc/flc_io.hpp"
#include "common/sim/vehicle/scenario_config.hpp"

namespace aerie::control {
namespace {

Eigen::Vector3d vec3(const util::Config& cfg, const std::string& key, const Eigen::Vector3d& fallback) {
  if (!cfg.has(key)) return fallback;
  const auto v = cfg.get<std::vector<double>>(key, {});
  if (v.size() != 3) throw std::runtime_error(cfg.origin() + ": '" + key + "' must be [x, y, z]");
  return {v[0], v[1], v[2]};
}

}  // namespace

NodeSetup node_setup(const util::Config& cfg, const CliOverrides& cli) {
  sim::require_known_keys(cfg, {"controller", "input", "channels", "rate_hz", "reference_deg", "reference_relative",
                                "forward_speed_m_s", "activation_distance_m", "stale_timeout_s", "max_input_age_s", "anchor_file", "limits", "heading_frame",
                                "message_time"});
  NodeSetup s;
  const std::string file = !cli.controller.empty() ? cli.controller : cfg.get<std::string>("controller", "");
  s.controller = file.empty() ? flc::thesis_initial() : flc::load_controller(file);

  NodeOptions& o = s.options;
  const std::string input = !cli.input.empty() ? cli.input : cfg.get<std::string>("input", "vo");
  if (input != "vo" && input != "nav" && input != "gt")
    throw std::runtime_error(cfg.origin() + ": 'input' must be vo, nav or gt, not '" + input + "'");
  o.input = input == "vo" ? NodeOptions::Input::kVoPose : input == "nav" ? NodeOptions::Input::kNavState : NodeOptions::Input::kGtPose;
  const auto ch = cfg.section("channels");
  sim::require_known_keys(ch, {"pose", "params", "command"});
  o.pose_channel = !cli.pose_channel.empty() ? cli.pose_channel : ch.get<std::string>("pose", "");
  if (o.pose_channel.empty()) o.pose_channel = default_pose_channel(o.input);
  o.params_channel = ch.get<std::string>("params", o.params_channel);
  o.command_channel = ch.get<std::string>("command", o.command_channel);
  o.rate_hz = cli.rate_hz.value_or(cfg.get("rate_hz", o.rate_hz));
  o.anchor_file = cfg.get<std::string>("anchor_file", o.anchor_file);

  ControlConfig& c = o.control;
  c.reference_deg = cli.reference_deg.value_or(cfg.get("reference_deg", c.reference_deg));
  c.reference_relative = cfg.get("reference_relative", c.reference_relative);
  c.forward_speed_m_s = cli.forward_speed.value_or(cfg.get("forward_speed_m_s", c.forward_speed_m_s));
  c.activation_distance_m = cfg.get("activation_distance_m", c.activation_distance_m);
  c.stale_timeout_s = cli.stale_timeout_s.value_or(cfg.get("stale_timeout_s", c.stale_timeout_s));
  c.max_input_age_s = cfg.get("max_input_age_s", c.max_input_age_s);
  const auto lim = cfg.section("limits");
  sim::require_known_keys(lim, {"max_yaw_rate_deg_s", "max_yaw_accel_deg_s2"});
  c.limits.max_yaw_rate_deg_s = lim.get("max_yaw_rate_deg_s", c.limits.max_yaw_rate_deg_s);
  c.limits.max_yaw_accel_deg_s2 = lim.get("max_yaw_accel_deg_s2", c.limits.max_yaw_accel_deg_s2);

  // The message-time policy of the pose source; its stale timeout is stale_timeout_s above.
  const auto mt = cfg.section("message_time");
  if (mt.has("stale_timeout_s"))
    throw std::runtime_error(cfg.origin() + ": 'message_time.stale_timeout_s' is not a key of aerie-control: "
                             "staleness is the top-level 'stale_timeout_s'");
  o.message_time = util::MessageClockConfig::from_config(mt, o.message_time);

  const auto fr = cfg.section("heading_frame");
  sim::require_known_keys(fr, {"up", "forward", "axis"});
  o.frame = default_heading_frame(o.input);
  o.frame.up = vec3(fr, "up", o.frame.up);
  o.frame.forward = vec3(fr, "forward", o.frame.forward);
  o.frame.axis = vec3(fr, "axis", o.frame.axis);
  try {
    c.validate();
    o.frame.validate();
    if (!(o.rate_hz >= 0.0 && o.rate_hz <= 1000.0)) throw std::invalid_argument("rate_hz must be in [0, 1000] (0 = one command per input)");
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(cfg.origin() + ": " + e.what());
  }
  return s;
}

}  // namespace aerie::control
