#include "air/control/control_node.hpp"

#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>

#include "air/control/anchor_file.hpp"
#include "common/bus/channels.hpp"
#include "common/flc/flc_io.hpp"
#include "common/util/time.hpp"

namespace aerie::control {

namespace {
std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}
}  // namespace

void check_incoming_controller(const flc::FlcSpec& spec, const std::string& origin) {
  struct Factor {
    const flc::Variable& v;
    const char* role;
    const char* gain;
    double lo;
    bool lo_open, sign_free;
  };
  const Factor factors[] = {{spec.inputs[0], "input", "Kp", kMinGain, false, false},
                            {spec.inputs[1], "input", "Kd", 0.0, true, false},
                            {spec.inputs[2], "input", "Ki", 0.0, true, true},
                            {spec.output, "output", "Ku", kMinGain, false, false}};
  for (const auto& f : factors) {
    const double k = f.sign_free ? std::abs(f.v.scaling) : f.v.scaling;
    const bool ok = std::isfinite(k) && (f.lo_open ? k > f.lo : k >= f.lo) && k <= kMaxScaling;
    if (ok) continue;
    const std::string range = f.sign_free ? "|" + std::string(f.gain) + "| in (0, " + number(kMaxScaling) + "]"
                                          : std::string(f.lo_open ? "(" : "[") + number(f.lo) + ", " + number(kMaxScaling) + "]";
    throw std::invalid_argument(origin + ": " + f.gain + " (scaling of " + f.role + " '" + f.v.name + "') = " +
                                number(f.v.scaling) + " is outside " + range +
                                (f.v.scaling < 0 && !f.sign_free ? ": a negative factor reverses the command" : ""));
  }
  const flc::Variable& out = spec.output;
  if (!(out.min < 0 && out.max > 0) || out.min < -kMaxOutputRange || out.max > kMaxOutputRange)
    throw std::invalid_argument(origin + ": output '" + out.name + "' range [" + number(out.min) + ", " + number(out.max) +
                                "] must hold 0 inside and lie within [-" + number(kMaxOutputRange) + ", " +
                                number(kMaxOutputRange) + "] deg/s");
  const flc::Flc flc(spec);
  for (const double e : {10.0, 45.0, 90.0}) {
    const double right = flc.evaluate(e, 0, 0), left = flc.evaluate(-e, 0, 0);
    const bool strict = e == 90.0;
    if (!(strict ? right > 0 : right >= 0) || !(strict ? left < 0 : left <= 0))
      throw std::invalid_argument(origin + ": rules: a heading error of +/-" + number(e) + " deg alone gives " +
                                  number(right) + " / " + number(left) + " deg/s: the controller does not turn " +
                                  "toward the reference (positive error, positive yaw rate)");
  }
}

flc::FlcSpec controller_from_message(const aerie::flc_params_t& m, const flc::FlcSpec& current) {
  const std::string origin = "FLC_PARAMS '" + m.controller_id + "'";
  flc::FlcSpec spec;
  try {
    spec = m.fll.empty() ? current : flc::parse_fll(m.fll, origin + " fll");
  } catch (const std::runtime_error& e) {
    throw std::invalid_argument(e.what());
  }
  if (m.names.size() != m.values.size()) throw std::invalid_argument(origin + ": names and values differ in length");
  if (m.fll.empty() && m.names.empty()) throw std::invalid_argument(origin + ": neither an FLL nor parameters");
  for (size_t i = 0; i < m.names.size(); ++i) {
    if (!std::isfinite(m.values[i])) throw std::invalid_argument(origin + ": parameter '" + m.names[i] + "' is not finite");
    try {
      spec.set_parameter(m.names[i], m.values[i]);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(origin + ": " + e.what());
    }
  }
  if (!m.controller_id.empty()) spec.id = m.controller_id;
  try {
    spec.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(origin + ": " + e.what());
  }
  check_incoming_controller(spec, origin);
  return spec;
}

std::string default_pose_channel(NodeOptions::Input input) {
  switch (input) {
    case NodeOptions::Input::kVoPose: return channels::kVoPose;
    case NodeOptions::Input::kNavState: return channels::kNavState;
    case NodeOptions::Input::kGtPose: return channels::kGtPose;
  }
  return channels::kVoPose;
}

HeadingFrame default_heading_frame(NodeOptions::Input input) {
  HeadingFrame f;  // VO: its world is its first camera frame (y down), the camera's optical axis
  if (input == NodeOptions::Input::kGtPose) {  // simulators publish a z-up world, y toward the wall
    f.up = {0, 0, 1};
    f.forward = {0, 1, 0};
  } else if (input == NodeOptions::Input::kNavState) {  // gravity-aligned z-up world, the body's x forward
    f.up = {0, 0, 1};
    f.forward = {1, 0, 0};
    f.axis = {1, 0, 0};
  }
  return f;
}

namespace {

NodeOptions checked(NodeOptions o) {
  if (!(o.rate_hz >= 0.0 && o.rate_hz <= 1000.0))
    throw std::invalid_argument("control: rate_hz must be in [0, 1000] (0 = one command per input)");
  o.frame.validate();
  o.control.validate();
  if (o.pose_channel.empty()) o.pose_channel = default_pose_channel(o.input);
  o.message_time.stale_timeout_us = static_cast<int64_t>(std::llround(o.control.stale_timeout_s * 1e6));
  return o;
}

}  // namespace

ControlNode::ControlNode(bus::Bus& bus, bus::StatusReporter& status, flc::FlcSpec controller, NodeOptions options,
                         util::NodeClock now)
    : bus_(bus),
      status_(status),
      opt_(checked(std::move(options))),
      loop_(std::move(controller), opt_.control),
      now_(std::move(now)),
      pose_clock_(status, opt_.pose_channel, opt_.message_time),
      input_clock_(opt_.pose_channel + " (input clock)", opt_.message_time) {
  if (opt_.message_clock) now_ = [this] { return input_now_; };
  period_us_ = opt_.rate_hz > 0 ? static_cast<int64_t>(1e6 / opt_.rate_hz) : 0;
  switch (opt_.input) {
    case NodeOptions::Input::kVoPose:
      bus_.subscribe<aerie::pose_t>(opt_.pose_channel, [this](const aerie::pose_t& m, const bus::ReceiveInfo&) {
        on_input_time(m.utime);
        if (m.status == aerie::pose_t::OK) {
          source_was_ok_ = true;
          on_pose(m.utime, m.orientation, m.position);
        } else {
          status_.count("pose_not_ok");  // initialising/lost: no heading, the fallback takes over when stale
          if (source_was_ok_ && m.status != aerie::pose_t::LOST)
            refuse_mission(opt_.pose_channel + " restarted its frame (aerie-vo restarted or reset)");
        }
        answer();
      });
      break;
    case NodeOptions::Input::kNavState:
      bus_.subscribe<aerie::nav_state_t>(opt_.pose_channel, [this](const aerie::nav_state_t& m, const bus::ReceiveInfo&) {
        on_input_time(m.utime);
        // IMU_ONLY is the filter bridging a VO outage within its configured time: still flown on.
        // A restarted aerie-nav initialises for its whole alignment window (200 messages at 1 s
        // and 200 Hz); one message saying so is a corrupt one, not a restart.
        initialising_run_ = m.status == aerie::nav_state_t::INITIALISING ? initialising_run_ + 1 : 0;
        if (m.status == aerie::nav_state_t::OK || m.status == aerie::nav_state_t::IMU_ONLY) {
          source_was_ok_ = true;
          on_pose(m.utime, m.orientation, m.position);
        } else {
          status_.count("nav_not_ok");  // initialising/lost
          if (source_was_ok_ && initialising_run_ >= kNavRestartMessages)
            refuse_mission(opt_.pose_channel + " is initialising again: aerie-nav restarted, its frame is new");
        }
        answer();
      });
      break;
    case NodeOptions::Input::kGtPose:
      bus_.subscribe<aerie::gt_pose_t>(opt_.pose_channel, [this](const aerie::gt_pose_t& m, const bus::ReceiveInfo&) {
        on_input_time(m.utime);
        on_pose(m.utime, m.orientation, m.position);
        answer();
      });
      break;
  }
  bus_.subscribe<aerie::flc_params_t>(opt_.params_channel,
                                      [this](const aerie::flc_params_t& m, const bus::ReceiveInfo&) { on_params(m); });
  status_.ok("controller " + loop_.controller().id);
}

void ControlNode::on_input_time(int64_t utime) {
  if (!opt_.message_clock) return;
  // The pose clock counts and reports jumps; this one only keeps them from moving the time.
  if (input_clock_.observe(utime, input_now_).accepted()) input_now_ = input_clock_.newest();
}

void ControlNode::answer() {
  if (period_us_ == 0) publish_command(now_());
}

void ControlNode::on_pose(int64_t utime, const double orientation[4], const double position[3]) {
  double heading = 0.0;
  try {
    heading = heading_from_quaternion(orientation, opt_.frame);
    if (!std::isfinite(position[0]) || !std::isfinite(position[1]) || !std::isfinite(position[2]))
      throw std::invalid_argument("position is not finite");
  } catch (const std::invalid_argument& e) {
    // Counted, shown in the status, logged once per 100 so that a wrong frame does not flood the log.
    status_.count("bad_pose");
    status_.warn(std::string("pose on ") + opt_.pose_channel + ": " + e.what());
    if (bad_poses_++ % 100 == 0)
      spdlog::warn("pose on {}: {} ({} so far; check heading_frame)", opt_.pose_channel, e.what(), bad_poses_);
    return;
  }
  on_heading(utime, heading, {position[0], position[1], position[2]}, now_());
}

void ControlNode::on_heading(int64_t utime, double heading_deg, const Eigen::Vector3d& position, int64_t receive_us) {
  // A pose whose time jumps (utime = INT64_MAX, a restarted VO) is held and counted
  // ("<channel>.time_jumps") without touching the loop; after resync_messages consistent
  // ones the loop follows the new time base.
  const auto time = pose_clock_.observe(utime, receive_us);
  if (!time.accepted()) return;
  if (time.verdict == util::MessageClock::Verdict::kResynced) loop_.resync();
  const double from_origin = position.head<2>().norm();
  if (!had_pose_ && opt_.input != NodeOptions::Input::kGtPose && loop_.config().activation_distance_m > 0 &&
      from_origin > 0.5 * loop_.config().activation_distance_m) {
    const std::string not_resumed = resume_anchor(utime);
    if (!not_resumed.empty())
      refuse_mission("the first pose is " + std::to_string(from_origin) + " m from " + opt_.pose_channel +
                     "'s origin: not the start of the manoeuvre (aerie-control restarted in flight?), and " + not_resumed);
  }
  had_pose_ = true;
  const bool anchored = loop_.anchor().has_value();
  const std::optional<double> age_s = util::message_age_s(utime, receive_us);
  if (!loop_.on_heading(utime, heading_deg, receive_us, position, age_s)) {
    status_.count("pose_out_of_order");
    return;
  }
  if (!anchored && loop_.anchor() && !opt_.anchor_file.empty()) {
    try {
      write_anchor(opt_.anchor_file, opt_.pose_channel, *loop_.anchor());
    } catch (const std::exception& e) {
      status_.count("anchor_write_errors");
      status_.warn(std::string("cannot keep the manoeuvre's anchor: ") + e.what());
      spdlog::warn("cannot keep the manoeuvre's anchor: {}", e.what());
    }
  }
  status_.count("poses");
  // The newest pose's age on this node's clock; -1 when the clocks are not comparable.
  status_.set("input_age_ms", age_s ? std::llround(*age_s * 1e3) : -1);
  if (loop_.aged()) {
    status_.count("aged_poses");
    if (aged_poses_++ % 100 == 0)
      spdlog::warn("pose on {} is {:.0f} ms old (limit {:.0f} ms): hovering until a fresh one ({} so far)",
                   opt_.pose_channel, *age_s * 1e3, loop_.config().max_input_age_s * 1e3, aged_poses_);
  }
  last_receive_ = opt_.message_clock ? util::wall_utime() : receive_us;  // for the status' latency hop
}

void ControlNode::on_params(const aerie::flc_params_t& m) {
  std::string reason;
  try {
    const auto refused = loop_.set_controller(controller_from_message(m, loop_.controller()));
    if (refused) reason = *refused;
  } catch (const std::exception& e) {
    reason = e.what();
  }
  if (!reason.empty()) {
    status_.count("params_refused");
    status_.warn("refused controller '" + m.controller_id + "': " + reason + " (keeping '" + loop_.controller().id + "')");
    spdlog::warn("refused controller '{}': {} (keeping '{}')", m.controller_id, reason, loop_.controller().id);
    return;
  }
  status_.count("params_accepted");
  if (mission_refused_.empty()) status_.ok("controller " + loop_.controller().id);
  spdlog::info("controller '{}' in use ({} rules)", loop_.controller().id, loop_.controller().rules.size());
}

void ControlNode::tick(int64_t now_us) {
  if (period_us_ == 0 || now_us < next_publish_) return;
  publish_command(now_us);
  // Keep the fixed rate; after a long pause start again from now.
  next_publish_ = now_us - next_publish_ > period_us_ ? now_us + period_us_ : next_publish_ + period_us_;
}

std::string ControlNode::resume_anchor(int64_t utime) {
  if (opt_.anchor_file.empty()) return "no anchor_file is configured to resume from";
  std::string why;
  std::optional<Anchor> a = read_anchor(opt_.anchor_file, opt_.pose_channel, why);
  if (a && !(a->utime < utime && static_cast<double>(utime) - static_cast<double>(a->utime) <= kMaxAnchorAgeUs)) {
    why = opt_.anchor_file + ": its anchor (utime " + std::to_string(a->utime) + ") is not from the " +
          std::to_string(kMaxAnchorAgeUs / 60'000'000) + " minutes before this pose (another mission or another clock)";
    a.reset();
  }
  if (!a) return why;
  loop_.resume(*a);
  status_.count("anchor_resumed");
  spdlog::info("resumed the manoeuvre anchored at ({:.2f}, {:.2f}, {:.2f}) m, reference {:.1f} deg, utime {} ({})",
               a->start.x(), a->start.y(), a->start.z(), a->reference_deg, a->utime, opt_.anchor_file);
  return "";
}

void ControlNode::refuse_mission(const std::string& why) {
  if (!mission_refused_.empty()) return;
  mission_refused_ = why;
  status_.count("mission_refused");
  status_.error("manoeuvre refused, hovering until the mission is restarted: " + why);
  spdlog::error("manoeuvre refused, hovering until the mission is restarted: {}", why);
}

void ControlNode::publish_command(int64_t now_us) {
  Command c = loop_.command(now_us);
  if (!mission_refused_.empty()) {
    c.mode = Mode::kFallbackHover;
    c.yaw_rate_deg_s = c.forward_speed_m_s = 0.0;
  }
  aerie::control_cmd_t m;
  m.utime = c.source_utime;
  m.seq = seq_++;
  m.mode = static_cast<int8_t>(c.mode);
  m.controller_id = c.controller_id;
  m.yaw_rate_deg_s = static_cast<float>(c.yaw_rate_deg_s);
  m.velocity_body[0] = static_cast<float>(c.forward_speed_m_s);
  m.velocity_body[1] = 0.0f;
  m.velocity_body[2] = 0.0f;
  m.heading_deg = static_cast<float>(c.heading_deg);
  m.heading_ref_deg = static_cast<float>(c.reference_deg);
  m.heading_error_deg = static_cast<float>(c.error_deg);
  bus_.publish(opt_.command_channel, m);
  status_.count(c.mode == Mode::kActive ? "commands_active" : c.mode == Mode::kHover ? "commands_hover" : "commands_fallback");
  // Stale (FALLBACK_HOVER) after stale_timeout_s, and live again, in the status: "<channel>.stale".
  pose_clock_.check(now_us);
  status_.mark_hop(c.source_utime, last_receive_, util::wall_utime());
}

}  // namespace aerie::control
