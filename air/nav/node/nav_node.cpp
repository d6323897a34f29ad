#include "air/nav/node/nav_node.hpp"

#include <aerie/imu_t.hpp>
#include <aerie/nav_state_t.hpp>
#include <aerie/pose_t.hpp>
#include <spdlog/spdlog.h>

#include <cmath>
#include <utility>

#include "air/nav/state_file.hpp"

namespace aerie::nav {
namespace {

int8_t to_message(NavStatus s) {
  switch (s) {
    case NavStatus::Initialising: return aerie::nav_state_t::INITIALISING;
    case NavStatus::Ok: return aerie::nav_state_t::OK;
    case NavStatus::ImuOnly: return aerie::nav_state_t::IMU_ONLY;
    case NavStatus::Lost: return aerie::nav_state_t::LOST;
  }
  return aerie::nav_state_t::INITIALISING;
}

}  // namespace

void fill_nav_state(aerie::nav_state_t& m, const NominalState& x, const Mat15& P, double time_since_vo_s) {
  for (int i = 0; i < 3; ++i) {
    m.position[i] = x.p[i];
    m.velocity[i] = x.v[i];
    m.gyro_bias[i] = x.bg[i];
    m.accel_bias[i] = x.ba[i];
    for (int j = 0; j < 3; ++j) {
      m.position_covariance[3 * i + j] = P(kP + i, kP + j);
      m.attitude_covariance[3 * i + j] = P(kTheta + i, kTheta + j);
    }
  }
  for (int i = 0; i < kErrorDim; ++i) m.covariance_diagonal[i] = P(i, i);
  m.orientation[0] = x.q.w();
  m.orientation[1] = x.q.x();
  m.orientation[2] = x.q.y();
  m.orientation[3] = x.q.z();
  m.time_since_vo_s = time_since_vo_s;
}

int8_t nav_status_to_message(NavStatus s) { return to_message(s); }

NavNode::NavNode(bus::Bus& bus, NavConfig config, NavNodeOptions options)
    : bus_(bus),
      cfg_(std::move(config)),
      opt_(std::move(options)),
      eskf_(cfg_.eskf),
      imu_time_(opt_.imu_channel, util::MessageClockConfig{cfg_.imu_max_jump_us, cfg_.message_time.resync_messages,
                                                           cfg_.message_time.stale_timeout_us}),
      vo_time_(opt_.vo_channel, cfg_.message_time) {
  if (!cfg_.resume.state_file.empty()) {
    std::string why;
    resume_from_ = read_snapshot(cfg_.resume.state_file, why);
    if (!resume_from_) spdlog::info("no state to resume from: {}; a static alignment starts the filter", why);
  }
  bus_.subscribe<aerie::imu_t>(opt_.imu_channel, [this](const aerie::imu_t& m, const bus::ReceiveInfo&) {
    if (!admit(imu_time_, opt_.imu_channel, m.utime)) return;
    ImuSample s;
    s.utime = m.utime;
    s.gyro = Vec3(m.angular_velocity[0], m.angular_velocity[1], m.angular_velocity[2]);
    s.accel = Vec3(m.linear_acceleration[0], m.linear_acceleration[1], m.linear_acceleration[2]);
    const Outcome o = resume_at(s) ? Outcome{true, ""} : eskf_.add_imu(s);
    if (!o.accepted) {
      ++counters_["imu_refused"];
      refused(opt_.imu_channel, o.reason);
      return;
    }
    if (!o.reason.empty()) {  // a gap, bridged
      log_.last_error = opt_.imu_channel + ": " + o.reason;
      spdlog::warn("{}", log_.last_error);
    }
    ++counters_["imu"];
    const int64_t period_us =
        cfg_.publish_rate_hz > 0.0 ? static_cast<int64_t>(std::llround(1e6 / cfg_.publish_rate_hz)) : 0;
    if (last_publish_utime_ == INT64_MIN || m.utime - last_publish_utime_ >= period_us) publish();
    keep_snapshot();
  }, 1000);  // 200 Hz: a deep queue so that a burst is not dropped
  bus_.subscribe<aerie::pose_t>(opt_.vo_channel, [this](const aerie::pose_t& m, const bus::ReceiveInfo&) {
    if (m.status == aerie::pose_t::LOST) {  // the pose is the last good one, not a measurement
      ++counters_["vo_not_tracking"];
      return;
    }
    if (m.status != aerie::pose_t::OK && m.status != aerie::pose_t::INITIALISING && m.status != aerie::pose_t::RESET) {
      ++counters_["vo_refused"];
      refused(opt_.vo_channel, "unknown pose status " + std::to_string(m.status));
      return;
    }
    const auto vo_time = admit(vo_time_, opt_.vo_channel, m.utime);
    if (!vo_time) return;
    const double qn = std::sqrt(m.orientation[0] * m.orientation[0] + m.orientation[1] * m.orientation[1] +
                                m.orientation[2] * m.orientation[2] + m.orientation[3] * m.orientation[3]);
    if (!std::isfinite(qn) || std::abs(qn - 1.0) > 1e-3) {
      ++counters_["vo_refused"];
      refused(opt_.vo_channel, "orientation is not a unit quaternion (norm " + std::to_string(qn) + ")");
      return;
    }
    VoMeasurement v;
    v.utime = m.utime;
    v.T_vo_cam = geometry::SE3(Eigen::Quaterniond(m.orientation[0], m.orientation[1], m.orientation[2], m.orientation[3]),
                               Vec3(m.position[0], m.position[1], m.position[2]));
    Mat6 C;
    for (int i = 0; i < 36; ++i) C(i / 6, i % 6) = m.covariance[i];
    if (!C.isZero(0.0)) v.covariance = C;  // all zero (the VO's first frame): the configured noise
    // INITIALISING (first frame) and RESET: the VO (re)started its frame.
    // A VO that came back at a new time (restarted: its INITIALISING pose may have been held
    // as a jump) is a new frame too.
    v.restart = m.status != aerie::pose_t::OK || *vo_time == util::MessageClock::Verdict::kResynced;
    const Outcome o = eskf_.add_vo(v);
    if (!o.accepted) {
      ++counters_["vo_refused"];
      refused(opt_.vo_channel, o.reason);
      return;
    }
    ++counters_["vo"];
  });
}

bool NavNode::resume_at(const ImuSample& first) {
  if (!resume_from_ || eskf_.initialised()) return false;
  const Snapshot snap = *std::exchange(resume_from_, std::nullopt);
  const double age_s = static_cast<double>(first.utime - snap.x.utime) * 1e-6;
  if (!(age_s >= 0.0 && age_s <= cfg_.resume.max_age_s)) {
    spdlog::info("not resuming from {}: its state is {:.3f} s from the first IMU sample (resume.max_age_s {}; "
                 "another flight or clock); a static alignment starts the filter",
                 cfg_.resume.state_file, age_s, cfg_.resume.max_age_s);
    return false;
  }
  eskf_.resume(snap, first, cfg_.resume.gap);
  spdlog::info("resumed from {} ({:.3f} s old, VO frame {}): p = ({:.2f}, {:.2f}, {:.2f})", cfg_.resume.state_file,
               age_s, snap.T_world_vo ? "anchored" : "not anchored yet", eskf_.state().p.x(), eskf_.state().p.y(),
               eskf_.state().p.z());
  last_status_ = eskf_.status();  // no INITIALISING -> OK to log: the filter did not initialise
  return true;
}

void NavNode::keep_snapshot() {
  if (cfg_.resume.state_file.empty() || !eskf_.initialised()) return;
  const int64_t utime = eskf_.state().utime;
  if (last_snapshot_utime_ != INT64_MIN &&
      utime - last_snapshot_utime_ < static_cast<int64_t>(std::llround(cfg_.resume.write_period_s * 1e6)))
    return;
  last_snapshot_utime_ = utime;
  try {
    write_snapshot(cfg_.resume.state_file, eskf_.snapshot());
    ++counters_["snapshots"];
  } catch (const std::exception& e) {
    ++counters_["snapshot_errors"];
    refused("resume.state_file", e.what());
  }
}

std::optional<util::MessageClock::Verdict> admit_message_time(util::MessageClock& clock, const std::string& channel,
                                                              int64_t utime, std::map<std::string, int64_t>& counters,
                                                              const std::string& held, RefusalLog& log) {
  // Staleness is the filter's own (outage.*, on message time): the node clock is not used.
  const util::MessageClock::Result r = clock.observe(utime, 0);
  if (r.verdict == util::MessageClock::Verdict::kResynced) spdlog::info("{}: {}", channel, r.reason);
  if (r.accepted()) return r.verdict;
  ++counters[held];
  log.refused(channel, r.reason);
  return std::nullopt;
}

std::optional<util::MessageClock::Verdict> NavNode::admit(util::MessageClock& clock, const std::string& channel,
                                                          int64_t utime) {
  return admit_message_time(clock, channel, utime, counters_, channel == opt_.imu_channel ? "imu_time_held" : "vo_time_held",
                            log_);
}

void RefusalLog::refused(const std::string& what, const std::string& why) {
  last_error = what + ": " + why;
  const int64_t n = ++per_channel[what];
  int64_t p = 1;
  while (p < n) p *= 10;
  if (p == n) spdlog::warn("{} ({} refused on {} so far)", last_error, n, what);
}

void NavNode::refused(const std::string& what, const std::string& why) { log_.refused(what, why); }

void NavNode::publish() {
  const NavStatus s = eskf_.status();
  if (s != last_status_) {
    spdlog::info("{} -> {}: {}", to_string(last_status_), to_string(s), eskf_.status_reason());
    last_status_ = s;
    ++counters_["status_changes"];
  }
  const NominalState& x = eskf_.state();
  aerie::nav_state_t m{};
  m.utime = eskf_.initialised() ? x.utime : 0;
  m.seq = seq_++;
  m.status = to_message(s);
  m.reason = eskf_.status_reason();
  m.orientation[0] = 1.0;
  if (eskf_.initialised()) fill_nav_state(m, x, eskf_.covariance_world_attitude(), eskf_.time_since_update_s());
  m.vo_applied = static_cast<int32_t>(eskf_.counters().vo_applied);
  m.vo_gated = static_cast<int32_t>(eskf_.counters().vo_gated);
  bus_.publish(opt_.state_channel, m);
  last_publish_utime_ = eskf_.initialised() ? x.utime : last_publish_utime_;
  ++counters_["states"];
}

int64_t NavNode::counter(const std::string& name) const {
  const auto it = counters_.find(name);
  return it == counters_.end() ? 0 : it->second;
}

void NavNode::report(bus::StatusReporter& status) const {
  for (const auto& [k, v] : counters_) status.set(k, v);
  const EskfCounters& c = eskf_.counters();
  status.set("imu_accepted", c.imu_accepted);
  status.set("imu_non_finite", c.imu_non_finite);
  status.set("imu_negative_time", c.imu_negative_time);
  status.set("imu_out_of_range", c.imu_out_of_range);
  status.set("imu_time_not_increasing", c.imu_time_not_increasing);
  status.set("imu_gaps", c.imu_gaps);
  status.set("static_windows_rejected", c.static_windows_rejected);
  status.set("vo_applied", c.vo_applied);
  status.set("vo_gated", c.vo_gated);
  status.set("vo_anchors", c.vo_anchors);
  status.set("vo_invalid", c.vo_invalid);
  status.set("vo_too_old", c.vo_too_old);
  status.set("vo_duplicate", c.vo_duplicate);
  status.set("vo_before_alignment", c.vo_before_alignment);
  status.set("vo_pending_dropped", c.vo_pending_dropped);
  status.set("vo_delayed", c.vo_delayed);
  status.set("vo_out_of_order", c.vo_out_of_order);
  status.set("resumed", c.resumed);
  const NavStatus s = eskf_.status();
  const std::string msg = std::string(to_string(s)) + ": " + eskf_.status_reason();
  if (s == NavStatus::Lost)
    status.error(msg);
  else if (s == NavStatus::ImuOnly)
    status.warn(msg);
  else if (!log_.last_error.empty())
    status.warn(msg + " (last refused input: " + log_.last_error + ")");
  else
    status.ok(msg);
}

}  // namespace aerie::nav
