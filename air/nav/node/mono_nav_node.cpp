#include "air/nav/node/mono_nav_node.hpp"

#include <aerie/imu_t.hpp>
#include <aerie/nav_state_t.hpp>
#include <aerie/pose_t.hpp>
#include <spdlog/spdlog.h>

#include <cmath>
#include <utility>

namespace aerie::nav {

MonoNavNode::MonoNavNode(bus::Bus& bus, NavConfig config, NavNodeOptions options)
    : bus_(bus),
      cfg_(std::move(config)),
      opt_(std::move(options)),
      filter_(cfg_.eskf, cfg_.mono),
      imu_time_(opt_.imu_channel, util::MessageClockConfig{cfg_.imu_max_jump_us, cfg_.message_time.resync_messages,
                                                           cfg_.message_time.stale_timeout_us}),
      vo_time_(cfg_.mono_channel, cfg_.message_time) {
  bus_.subscribe<aerie::imu_t>(opt_.imu_channel, [this](const aerie::imu_t& m, const bus::ReceiveInfo&) {
    if (!admit_message_time(imu_time_, opt_.imu_channel, m.utime, counters_, "imu_time_held", log_)) return;
    ImuSample s;
    s.utime = m.utime;
    s.gyro = Vec3(m.angular_velocity[0], m.angular_velocity[1], m.angular_velocity[2]);
    s.accel = Vec3(m.linear_acceleration[0], m.linear_acceleration[1], m.linear_acceleration[2]);
    const Outcome o = filter_.add_imu(s);
    if (!o.accepted) {
      ++counters_["imu_refused"];
      log_.refused(opt_.imu_channel, o.reason);
      return;
    }
    if (!o.reason.empty()) log_.last_error = opt_.imu_channel + ": " + o.reason;
    ++counters_["imu"];
    const int64_t period_us =
        cfg_.publish_rate_hz > 0.0 ? static_cast<int64_t>(std::llround(1e6 / cfg_.publish_rate_hz)) : 0;
    if (last_publish_utime_ == INT64_MIN || m.utime - last_publish_utime_ >= period_us) publish();
  }, 1000);
  bus_.subscribe<aerie::pose_t>(cfg_.mono_channel, [this](const aerie::pose_t& m, const bus::ReceiveInfo&) {
    const int state = m.status & aerie::pose_t::STATE_MASK;
    if (state == aerie::pose_t::LOST) {  // the last good pose repeated, not a measurement
      ++counters_["vo_not_tracking"];
      return;
    }
    if (state == aerie::pose_t::INITIALISING) {  // no map yet: the pose means nothing; the next one starts a map
      ++counters_["mono_initialising"];
      new_map_ = true;
      return;
    }
    if (state != aerie::pose_t::OK && state != aerie::pose_t::RESET) {
      ++counters_["vo_refused"];
      log_.refused(cfg_.mono_channel, "unknown pose status " + std::to_string(m.status));
      return;
    }
    if (!(m.status & aerie::pose_t::SCALE_ARBITRARY)) ++counters_["mono_without_scale_flag"];  // taken as arbitrary
    const auto verdict = admit_message_time(vo_time_, cfg_.mono_channel, m.utime, counters_, "vo_time_held", log_);
    if (!verdict) return;
    MonoMeasurement v;
    v.utime = m.utime;
    v.q_vis_cam = Eigen::Quaterniond(m.orientation[0], m.orientation[1], m.orientation[2], m.orientation[3]);
    v.p_vis_cam = Vec3(m.position[0], m.position[1], m.position[2]);
    Mat6 C;
    for (int i = 0; i < 36; ++i) C(i / 6, i % 6) = m.covariance[i];
    if (!C.isZero(0.0)) v.covariance = C;
    v.reset = state == aerie::pose_t::RESET || new_map_ || *verdict == util::MessageClock::Verdict::kResynced;
    const Outcome o = filter_.add_vo(v);  // refuses NaN, a non-unit quaternion, negative time, ...
    if (!o.accepted) {
      ++counters_["vo_refused"];
      log_.refused(cfg_.mono_channel, o.reason);
      return;
    }
    new_map_ = false;
    ++counters_["vo"];
  });
}

void MonoNavNode::publish() {
  int8_t status = nav_status_to_message(filter_.status());
  if (filter_.status() == NavStatus::Ok && filter_.scale_status() == ScaleStatus::Unknown)
    status = aerie::nav_state_t::SCALE_UNKNOWN;
  if (status != last_status_) {
    spdlog::info("NAV_STATE status {} -> {}: {}", last_status_, status, filter_.status_reason());
    last_status_ = status;
    ++counters_["status_changes"];
  }
  aerie::nav_state_t m{};
  m.utime = filter_.initialised() ? filter_.state().utime : 0;
  m.seq = seq_++;
  m.status = status;
  m.reason = filter_.status_reason();
  m.orientation[0] = 1.0;
  if (filter_.initialised())
    fill_nav_state(m, filter_.state(), filter_.covariance_world_attitude(), filter_.time_since_update_s());
  m.vo_applied = static_cast<int32_t>(filter_.counters().vo_applied);
  m.vo_gated = static_cast<int32_t>(filter_.counters().vo_gated);
  bus_.publish(opt_.state_channel, m);
  if (filter_.initialised()) last_publish_utime_ = filter_.state().utime;
  ++counters_["states"];
}

int64_t MonoNavNode::counter(const std::string& name) const {
  const auto it = counters_.find(name);
  return it == counters_.end() ? 0 : it->second;
}

void MonoNavNode::report(bus::StatusReporter& status) const {
  for (const auto& [k, v] : counters_) status.set(k, v);
  const MonoCounters& c = filter_.counters();
  for (const auto& [k, v] : std::initializer_list<std::pair<const char*, int64_t>>{
           {"imu_accepted", c.imu_accepted}, {"imu_non_finite", c.imu_non_finite},
           {"imu_negative_time", c.imu_negative_time}, {"imu_out_of_range", c.imu_out_of_range},
           {"imu_time_not_increasing", c.imu_time_not_increasing}, {"imu_gaps", c.imu_gaps},
           {"static_windows_rejected", c.static_windows_rejected}, {"vo_applied", c.vo_applied},
           {"vo_gated", c.vo_gated}, {"vo_anchors", c.vo_anchors}, {"vo_invalid", c.vo_invalid},
           {"vo_not_unit", c.vo_not_unit}, {"vo_negative_time", c.vo_negative_time}, {"vo_too_old", c.vo_too_old},
           {"vo_duplicate", c.vo_duplicate}, {"vo_before_alignment", c.vo_before_alignment},
           {"vo_pending_dropped", c.vo_pending_dropped}, {"vo_delayed", c.vo_delayed},
           {"vo_out_of_order", c.vo_out_of_order}, {"vision_resets", c.vision_resets}, {"jump_resets", c.jump_resets}})
    status.set(k, v);
  // The scale in status: integer counters, so lambda and its sigma in parts per million.
  status.set("scale_ppm", static_cast<int64_t>(std::llround(filter_.scale() * 1e6)));
  status.set("scale_sigma_ppm", static_cast<int64_t>(std::llround(filter_.log_scale_sigma() * 1e6)));
  status.set("scale_ok", filter_.scale_status() == ScaleStatus::Ok ? 1 : 0);
  const NavStatus s = filter_.status();
  const std::string msg = std::string(to_string(s)) + ": " + filter_.status_reason();
  if (s == NavStatus::Lost)
    status.error(msg);
  else if (s == NavStatus::ImuOnly || filter_.scale_status() == ScaleStatus::Unknown)
    status.warn(msg);
  else if (!log_.last_error.empty())
    status.warn(msg + " (last refused input: " + log_.last_error + ")");
  else
    status.ok(msg);
}

}  // namespace aerie::nav
