#include "air/mavlink/node/mavlink_node.hpp"

#include <aerie/control_cmd_t.hpp>
#include <aerie/imu_t.hpp>
#include <aerie/nav_state_t.hpp>
#include <aerie/pilot_state_t.hpp>
#include <aerie/target_pose_t.hpp>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

#include "common/mavlink/signing.hpp"

namespace aerie::bridge {

namespace {
Eigen::Matrix3d matrix3(const double* m) {
  Eigen::Matrix3d out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out(r, c) = m[3 * r + c];
  return out;
}

NavSample nav_sample(const aerie::nav_state_t& m) {
  NavSample s;
  s.utime = m.utime;
  s.valid = m.status == aerie::nav_state_t::OK;
  s.position = {m.position[0], m.position[1], m.position[2]};
  s.velocity = {m.velocity[0], m.velocity[1], m.velocity[2]};
  s.orientation = Eigen::Quaterniond(m.orientation[0], m.orientation[1], m.orientation[2], m.orientation[3]);
  s.position_covariance = matrix3(m.position_covariance);
  s.attitude_covariance = matrix3(m.attitude_covariance);
  s.velocity_covariance = Eigen::Vector3d(m.covariance_diagonal[3], m.covariance_diagonal[4], m.covariance_diagonal[5])
                              .asDiagonal();
  return s;
}

int8_t autopilot_code(mavlink::Autopilot a) {
  switch (a) {
    case mavlink::Autopilot::Px4: return aerie::autopilot_state_t::AUTOPILOT_PX4;
    case mavlink::Autopilot::ArduPilot: return aerie::autopilot_state_t::AUTOPILOT_ARDUPILOT;
    default: return aerie::autopilot_state_t::AUTOPILOT_OTHER;
  }
}
}  // namespace

MavlinkNode::MavlinkNode(bus::Bus& bus, AutopilotLink link, std::unique_ptr<mavlink::Endpoint> autopilot,
                         std::vector<std::unique_ptr<mavlink::Endpoint>> ground, MavlinkNodeOptions options,
                         util::NodeClock now)
    : Node(bus, "mavlink"),
      link_(std::move(link)),
      autopilot_(std::move(autopilot)),
      ground_(std::move(ground)),
      ground_parsers_(ground_.size()),
      opt_(std::move(options)),
      now_(std::move(now)) {
  if (!autopilot_) throw std::invalid_argument("aerie-mavlink: no autopilot endpoint");
  subscribe<aerie::control_cmd_t>(opt_.control_channel, [this](const aerie::control_cmd_t& m, const bus::ReceiveInfo&) {
    ControlInput c;
    c.utime = m.utime;
    c.mode = m.mode;
    c.velocity = {m.velocity_body[0], m.velocity_body[1], m.velocity_body[2]};
    c.yaw_rate_cw_deg_s = m.yaw_rate_deg_s;
    const int64_t t = now_();
    link_.on_control(c, t);
    pending_control_utime_ = m.utime;
    flush(t);  // the setpoint leaves with the command that made it
  });
  subscribe<aerie::nav_state_t>(opt_.nav_channel, [this](const aerie::nav_state_t& m, const bus::ReceiveInfo&) {
    const int64_t t = now_();
    link_.on_nav(nav_sample(m), t);
    flush(t);
  });
  subscribe<aerie::target_pose_t>(opt_.target_channel, [this](const aerie::target_pose_t& m, const bus::ReceiveInfo&) {
    const int64_t t = now_();
    link_.on_target({m.utime, {m.position[0], m.position[1], m.position[2]}, m.source != aerie::target_pose_t::SOURCE_BOX},
                    t);
    flush(t);
  });
  subscribe<aerie::pilot_state_t>(opt_.pilot_state_channel, [this](const aerie::pilot_state_t& m, const bus::ReceiveInfo&) {
    link_.on_pilot_state(m.state, now_());
  });
}

int64_t MavlinkNode::frame_to_wire_us(double p) const {
  if (frame_to_wire_us_.empty()) return -1;
  std::vector<int64_t> v = frame_to_wire_us_;
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(p * static_cast<double>(v.size())));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

MavlinkNode::~MavlinkNode() {
  if (!frame_to_wire_us_.empty())
    spdlog::info("camera frame to setpoint on the wire: p50 {:.2f} ms, p99 {:.2f} ms over {} setpoints",
                 frame_to_wire_us(0.5) / 1e3, frame_to_wire_us(0.99) / 1e3, frame_to_wire_us_.size());
  const auto ts = link_.last_signing_timestamp();
  if (opt_.timestamp_file.empty() || !ts) return;
  try {
    mavlink::save_timestamp(opt_.timestamp_file, *ts);  // a restart continues above it
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
  }
}

void MavlinkNode::flush(int64_t now_us) {
  const int64_t setpoints_before = link_.counters().setpoints;
  for (const auto& frame : link_.poll(now_us))
    if (!autopilot_->write(frame)) ++write_failures_;
  if (link_.counters().setpoints > setpoints_before && pending_control_utime_ >= 0) {
    if (frame_to_wire_us_.size() >= 20000)  // the last ten thousand or more (at 20 Hz: over 8 minutes)
      frame_to_wire_us_.erase(frame_to_wire_us_.begin(), frame_to_wire_us_.begin() + 10000);
    frame_to_wire_us_.push_back(now_() - pending_control_utime_);
    pending_control_utime_ = -1;
  }
  for (const std::string& line : link_.take_log()) spdlog::info("{}", line);
}

void MavlinkNode::tick(int64_t) {
  const int64_t now_us = now_();  // the node's clock, also in lock-step
  try {
    buf_.clear();
    if (autopilot_->read(buf_) > 0) {
      link_.receive(buf_, now_us);
      for (auto& g : ground_)
        if (g->write(buf_)) ++routed_down_;
    }
    for (size_t i = 0; i < ground_.size(); ++i) {
      buf_.clear();
      if (ground_[i]->read(buf_) == 0) continue;
      ground_parsers_[i].feed(buf_, [&](const mavlink::Frame& f) {
        if (autopilot_->write(mavlink::serialize(f))) ++routed_up_;
      });
    }
  } catch (const std::runtime_error& e) {  // an endpoint failed for good (serial port gone)
    ++endpoint_errors_;
    status().error(e.what());
    spdlog::error("{}", e.what());
  }
  flush(now_us);
  if (auto imu = link_.take_imu(); imu && opt_.publish_imu) {
    aerie::imu_t m{};
    m.utime = imu->utime;
    m.seq = imu_seq_++;
    for (int k = 0; k < 3; ++k) {
      m.angular_velocity[k] = imu->angular_velocity[k];
      m.linear_acceleration[k] = imu->linear_acceleration[k];
    }
    m.orientation_valid = imu->orientation.has_value();
    const Eigen::Quaterniond q = imu->orientation.value_or(Eigen::Quaterniond::Identity());
    m.orientation[0] = q.w();
    m.orientation[1] = q.x();
    m.orientation[2] = q.y();
    m.orientation[3] = q.z();
    bus().publish(opt_.imu_channel, m);
  }
  if (link_.take_changed() || now_us - last_state_us_ >= 1'000'000) {
    bus().publish(opt_.state_channel, state_message(now_us));
    last_state_us_ = now_us;
  }
  persist_timestamp(now_us);
  report();
}

void MavlinkNode::persist_timestamp(int64_t now_us) {
  if (opt_.timestamp_file.empty()) return;
  if (const auto ts = link_.timestamp_to_persist(now_us)) {
    try {
      mavlink::save_timestamp(opt_.timestamp_file, *ts);
    } catch (const std::exception& e) {
      status().warn(e.what());
    }
  }
}

aerie::autopilot_state_t MavlinkNode::state_message(int64_t now_us) const {
  const AutopilotView& v = link_.view();
  aerie::autopilot_state_t m{};
  m.utime = v.last_heard_us ? v.last_heard_us : now_us;
  m.seq = state_seq_++;
  m.link = v.link == AutopilotView::Link::Ok     ? aerie::autopilot_state_t::LINK_OK
           : v.link == AutopilotView::Link::Lost ? aerie::autopilot_state_t::LINK_LOST
                                                 : aerie::autopilot_state_t::LINK_NONE;
  m.autopilot = autopilot_code(v.autopilot);
  m.system_id = static_cast<int16_t>(v.system_id);
  m.component_id = static_cast<int16_t>(v.component_id);
  m.armed = v.armed;
  m.mode = v.mode;
  m.custom_mode = v.custom_mode;
  m.system_status = static_cast<int8_t>(v.system_status);
  m.landed_state = static_cast<int8_t>(v.landed_state);
  m.aerie_in_control = v.in_companion_mode;
  m.signing = link_.signing();
  m.battery_voltage_v = v.battery_voltage_v;
  m.battery_remaining_pct = v.battery_remaining_pct;
  m.link_quality = v.link_quality;
  m.clock_offset_us = v.clock_offset_us;
  m.estimator_flags = v.estimator_flags;
  m.local_position_valid = v.pose.has_value();
  if (v.pose) {
    for (int k = 0; k < 3; ++k) {
      m.position_ned[k] = static_cast<float>(v.pose->position[k]);
      m.velocity_ned[k] = static_cast<float>(v.velocity_ned[k]);
    }
    const Eigen::Quaterniond& q = v.pose->attitude;
    m.attitude[0] = static_cast<float>(q.w());
    m.attitude[1] = static_cast<float>(q.x());
    m.attitude[2] = static_cast<float>(q.y());
    m.attitude[3] = static_cast<float>(q.z());
  } else {
    m.attitude[0] = 1;
  }
  m.last_statustext = v.last_statustext;
  m.last_command = v.last_command;
  m.last_result = v.last_result;
  return m;
}

void MavlinkNode::report() {
  const auto& c = link_.counters();
  const auto& p = link_.parser_counters();
  auto& s = status();
  s.set("frames_in", c.frames_in);
  s.set("frames_out", c.frames_out);
  s.set("setpoints", c.setpoints);
  s.set("odometry", c.odometry);
  s.set("landing_targets", c.landing_targets);
  s.set("control_stale", c.control_stale);
  s.set("commands_accepted", c.commands_accepted);
  s.set("commands_refused", c.commands_refused);
  s.set("commands_timed_out", c.commands_timed_out);
  s.set("link_losses", c.link_losses);
  s.set("foreign_autopilot", c.foreign_autopilot);
  s.set("bad_inputs", c.bad_inputs);
  s.set("refused.bad_crc", static_cast<int64_t>(p.bad_crc));
  s.set("refused.unknown_message", static_cast<int64_t>(p.unknown_message));
  s.set("refused.payload_too_long", static_cast<int64_t>(p.payload_too_long));
  s.set("refused.bad_incompat_flags", static_cast<int64_t>(p.bad_incompat_flags));
  s.set("refused.mavlink1", static_cast<int64_t>(p.mavlink1_refused));
  s.set("refused.unsigned", static_cast<int64_t>(p.unsigned_refused));
  s.set("refused.bad_signature", static_cast<int64_t>(p.bad_signature));
  s.set("refused.replayed", static_cast<int64_t>(p.replayed_timestamp));
  s.set("refused.stale", static_cast<int64_t>(p.stale_timestamp));
  s.set("garbage_bytes", static_cast<int64_t>(p.garbage_bytes));
  s.set("routed_up", routed_up_);
  s.set("routed_down", routed_down_);
  s.set("write_failures", write_failures_);
  s.set("endpoint_errors", endpoint_errors_);
  if (!frame_to_wire_us_.empty() && now_() - last_stats_us_ >= 1'000'000) {  // once a second
    last_stats_us_ = now_();
    s.set("frame_to_wire_p50_us", frame_to_wire_us(0.5));
    s.set("frame_to_wire_p99_us", frame_to_wire_us(0.99));
  }
  const AutopilotView& v = link_.view();
  const std::string who = std::string(mavlink::to_string(v.autopilot)) + " " + v.mode + (v.armed ? " ARMED" : " disarmed") +
                          (link_.signing() ? ", signed" : ", UNSIGNED");
  if (endpoint_errors_ > 0) return;  // the endpoint's error stays in status
  if (v.link == AutopilotView::Link::Lost)
    s.error("autopilot link LOST (no heartbeat for " + std::to_string(static_cast<int>(link_.config().link_timeout_s)) +
            " s)");
  else if (v.link == AutopilotView::Link::None)
    s.warn("waiting for the autopilot's heartbeat on " + autopilot_->name());
  else if (!link_.signing())
    s.warn(who);
  else
    s.ok(who);
}

}  // namespace aerie::bridge
