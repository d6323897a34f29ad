#include "common/sim/flight/node/flightsim_node.hpp"

#include <aerie/gt_box_t.hpp>
#include <aerie/gt_pose_t.hpp>
#include <aerie/imu_t.hpp>
#include <aerie/sim_state_t.hpp>
#include <aerie/stereo_image_t.hpp>
#include <spdlog/spdlog.h>

#include <cmath>
#include <numbers>

#include "common/image/image_message.hpp"
#include "common/util/time.hpp"

namespace aerie::sim {

namespace {
constexpr double kRadToDeg = 180.0 / std::numbers::pi;
}  // namespace

aerie::image_t image_message(const cv::Mat& img, int64_t utime, int64_t seq, const std::string& camera,
                             const Intrinsics& K) {
  auto m = image::to_message(img, utime, seq);
  image::set_metadata(m, "camera", camera);
  image::set_metadata(m, "fx", std::to_string(K.fx));
  image::set_metadata(m, "fy", std::to_string(K.fy));
  image::set_metadata(m, "cx", std::to_string(K.cx));
  image::set_metadata(m, "cy", std::to_string(K.cy));
  return m;
}

aerie::gt_box_t gt_box_message(const StereoFrame& down, int64_t utime, int64_t seq, const std::string& camera) {
  return image::gt_box_message(utime, seq, "helipad", camera, down.target_visible, down.target_box, down.target_corners);
}

FlightSimNode::FlightSimNode(bus::Bus& bus, FlightSim& sim, FlightSimNodeOptions options)
    : bus_(bus), sim_(sim), opt_(std::move(options)) {
  if (!opt_.command_channel.empty())  // "" when the vehicle flies behind an autopilot (MAVLink)
    bus_.subscribe<aerie::control_cmd_t>(opt_.command_channel, [this](const aerie::control_cmd_t& c, const bus::ReceiveInfo&) {
      on_command(c);
    });
  for (const auto& ch : opt_.answer_channels)
    bus_.subscribe_raw(ch, [this, ch](const uint8_t* data, size_t size, const bus::ReceiveInfo&) {
      if (const auto u = bus::peek_utime(data, size)) answered_[ch] = std::max(answered_[ch], *u);
    });
}

void FlightSimNode::on_command(const aerie::control_cmd_t& c) {
  ++commands_;
  CommandInput in;
  in.mode = c.mode;
  in.velocity = {c.velocity_body[0], c.velocity_body[1], c.velocity_body[2]};
  in.yaw_rate_deg_s = c.yaw_rate_deg_s;
  const std::string why = sim_.command(in);
  if (!why.empty()) spdlog::warn("{}: command refused, holding: {}", opt_.command_channel, why);
}

const FlightFrame& FlightSimNode::publish_next() {
  frame_ = sim_.step();
  const FlightFrame& f = frame_;
  for (const auto& s : f.imu) {
    aerie::imu_t m{};
    m.utime = sim_.utime_of(s.t);
    m.seq = imu_seq_++;
    for (int i = 0; i < 3; ++i) {
      m.angular_velocity[i] = s.gyro[i];
      m.linear_acceleration[i] = s.accel[i];
    }
    m.orientation_valid = true;
    m.orientation[0] = s.attitude.w();
    m.orientation[1] = s.attitude.x();
    m.orientation[2] = s.attitude.y();
    m.orientation[3] = s.attitude.z();
    bus_.publish(opt_.imu_channel, m);
  }
  if (!opt_.gt_pose_channel.empty()) {
    const geometry::SE3& T = f.T_world_left;
    aerie::gt_pose_t p{};
    p.utime = f.utime;
    p.seq = f.seq;
    p.frame_id = "world";
    for (int i = 0; i < 3; ++i) p.position[i] = T.translation()[i];
    T.to_wxyz(p.orientation);
    bus_.publish(opt_.gt_pose_channel, p);
  }
  if (!opt_.gt_track_channel.empty())
    bus_.publish(opt_.gt_track_channel, gt_box_message(f.down, f.utime, f.seq, opt_.down_channel));
  if (!opt_.state_channel.empty()) {
    const auto& v = f.vehicle;
    const auto& o = sim_.outcome();
    const Helipad& pad = sim_.world().helipad();
    aerie::sim_state_t s{};
    s.utime = f.utime;
    s.seq = f.seq;
    s.world = sim_.config().world.kind;
    for (int i = 0; i < 3; ++i) {
      s.position[i] = v.position[i];
      s.velocity[i] = v.velocity[i];
      s.wind[i] = f.wind[i];
      s.touchdown_position[i] = o.touchdown_position[i];
      s.target_position[i] = pad.center[i];
    }
    s.yaw_deg = v.yaw * kRadToDeg;
    s.roll_deg = v.roll * kRadToDeg;
    s.pitch_deg = v.pitch * kRadToDeg;
    s.contact = o.collided ? aerie::sim_state_t::COLLIDED
                : o.landed ? aerie::sim_state_t::LANDED
                : v.on_ground ? aerie::sim_state_t::ON_GROUND
                              : aerie::sim_state_t::AIRBORNE;
    s.touchdown_yaw_deg = o.touchdown_yaw * kRadToDeg;
    s.touchdown_vertical_speed = o.touchdown_vertical_speed;
    s.target_yaw_deg = pad.yaw * kRadToDeg;
    s.commands_applied = sim_.commands_applied();
    s.commands_refused = sim_.commands_refused();
    s.last_refusal = sim_.last_refusal();
    s.lockstep_timeouts = timeouts_;
    bus_.publish(opt_.state_channel, s);
  }
  if (cameras_stalled_) {  // a stalled camera driver: the rest of the frame goes out
    ++stalled_frames_;
    return frame_;
  }
  if (f.stereo && !opt_.stereo_channel.empty()) {
    const Intrinsics K = sim_.stereo_intrinsics();
    aerie::stereo_image_t s{};
    s.utime = f.utime;
    s.seq = f.seq;
    s.left = image::to_message(f.stereo->left, f.utime, f.seq);
    s.right = image::to_message(f.stereo->right, f.utime, f.seq);
    s.fx = K.fx;
    s.fy = K.fy;
    s.cx = K.cx;
    s.cy = K.cy;
    s.baseline_m = K.baseline;
    bus_.publish(opt_.stereo_channel, s);
  }
  if (!opt_.down_channel.empty())
    bus_.publish(opt_.down_channel, image_message(f.down.left, f.utime, f.seq, "down", sim_.down_calibration()));
  return frame_;
}

bool FlightSimNode::wait_answers() {
  const int64_t deadline = util::wall_utime() + static_cast<int64_t>(opt_.answer_timeout_s * 1e6);
  auto answered = [&] {
    for (const auto& ch : opt_.answer_channels) {
      const auto it = answered_.find(ch);
      if (it == answered_.end() || it->second < frame_.utime) return false;
    }
    return true;
  };
  while (!answered()) {
    const int64_t left = deadline - util::wall_utime();
    if (left <= 0) {
      ++timeouts_;
      std::string channels;
      for (const auto& ch : opt_.answer_channels) channels += (channels.empty() ? "" : ", ") + ch;
      spdlog::warn("lock-step: no answer to frame {} on {} within {} s (counted; going on)", frame_.seq, channels,
                   opt_.answer_timeout_s);
      return false;
    }
    bus_.handle(static_cast<int>(std::min<int64_t>(left / 1000 + 1, 100)));
  }
  return true;
}

void FlightSimNode::report(bus::StatusReporter& status) const {
  status.set("frames", frame_.seq + 1);
  status.set("commands_received", commands_);
  status.set("commands_applied", sim_.commands_applied());
  status.set("commands_refused", sim_.commands_refused());
  status.set("lockstep_timeouts", timeouts_);
  const auto& o = sim_.outcome();
  if (o.collided)
    status.error("collision: " + o.collision);
  else if (!sim_.last_refusal().empty())
    status.warn("last command refused: " + sim_.last_refusal());
  else
    status.ok(o.landed ? "landed" : frame_.vehicle.on_ground ? "on the ground" : "flying");
}

}  // namespace aerie::sim
