#include "air/mavlink/autopilot_link.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/geometry/frames.hpp"
#include "common/util/section_reader.hpp"

namespace aerie::bridge {

namespace mav = aerie::mavlink;

namespace {
// pilot_state_t's constants (lcmtypes/aerie_pilot_state_t.lcm) the precision-landing path reads.
constexpr int kPilotDescend = 5, kPilotHold = 8, kPilotAbort = 9;
// control_cmd_t's modes.
constexpr int kHover = 0, kActive = 1, kFallbackHover = 2, kTakeoff = 3, kLand = 4;

std::string text_of(const mav::Statustext& st) {
  const auto end = std::find(st.text.begin(), st.text.end(), '\0');
  return std::string(st.text.begin(), end);
}

const char* severity_name(uint8_t s) {
  static const char* names[] = {"EMERGENCY", "ALERT", "CRITICAL", "ERROR", "WARNING", "NOTICE", "INFO", "DEBUG"};
  return s < 8 ? names[s] : "SEVERITY?";
}

void require(bool ok, const std::string& key, const std::string& expected) {
  if (!ok) throw std::invalid_argument("mavlink config: " + key + " must be " + expected);
}
}  // namespace

void BridgeConfig::validate() const {
  require(system_id >= 1 && system_id <= 255, "system_id", "in [1, 255]");
  require(component_id >= 1 && component_id <= 255, "component_id", "in [1, 255]");
  require(autopilot_system_id >= 0 && autopilot_system_id <= 255, "autopilot_system_id", "in [0, 255]");
  require(heartbeat_period_s > 0 && heartbeat_period_s <= 5, "heartbeat_period_s", "in (0, 5]");
  require(link_timeout_s > heartbeat_period_s && link_timeout_s <= 60, "link_timeout_s",
          "above heartbeat_period_s and at most 60");
  require(setpoint_rate_hz > 2 && setpoint_rate_hz <= 200, "setpoint_rate_hz", "in (2, 200] (PX4 needs > 2 Hz)");
  require(offboard_warmup_s >= 0 && offboard_warmup_s <= 10, "offboard_warmup_s", "in [0, 10]");
  require(control_timeout_s > 0 && control_timeout_s <= 5, "control_timeout_s", "in (0, 5]");
  require(odometry_rate_hz > 0 && odometry_rate_hz <= 200, "odometry_rate_hz", "in (0, 200]");
  require(command_timeout_s > 0 && command_timeout_s <= 30, "command_timeout_s", "in (0, 30]");
  require(command_attempts >= 1 && command_attempts <= 10, "command_attempts", "in [1, 10]");
  require(mode_retry_s >= 0 && mode_retry_s <= 30, "mode_retry_s", "in [0, 30]");
  require(takeoff_altitude_m > 0 && takeoff_altitude_m <= 50, "takeoff_altitude_m", "in (0, 50]");
  require(std::isfinite(camera_pitch_deg) && camera_pitch_deg >= 0 && camera_pitch_deg <= 90, "camera_pitch_deg",
          "in [0, 90]");
  for (double r : {imu_rate_hz, attitude_rate_hz, local_position_rate_hz, extended_state_rate_hz, battery_rate_hz})
    require(r >= 0 && r <= 1000, "the stream rates (*_rate_hz)", "in [0, 1000]");
}

BridgeConfig load_bridge(const util::Config& cfg) {
  BridgeConfig c;
  util::SectionReader<BridgeConfig>(cfg, c)("system_id", &BridgeConfig::system_id)(
      "component_id", &BridgeConfig::component_id)("autopilot_system_id", &BridgeConfig::autopilot_system_id)(
      "heartbeat_period_s", &BridgeConfig::heartbeat_period_s)("link_timeout_s", &BridgeConfig::link_timeout_s)(
      "setpoint_rate_hz", &BridgeConfig::setpoint_rate_hz)("offboard_warmup_s", &BridgeConfig::offboard_warmup_s)(
      "control_timeout_s", &BridgeConfig::control_timeout_s)("odometry_rate_hz", &BridgeConfig::odometry_rate_hz)(
      "command_timeout_s", &BridgeConfig::command_timeout_s)("command_attempts", &BridgeConfig::command_attempts)(
      "mode_retry_s", &BridgeConfig::mode_retry_s)("takeoff_altitude_m", &BridgeConfig::takeoff_altitude_m)(
      "camera_pitch_deg", &BridgeConfig::camera_pitch_deg)("send_odometry", &BridgeConfig::send_odometry)(
      "landing_target_fitted_only", &BridgeConfig::landing_target_fitted_only)(
      "imu_rate_hz", &BridgeConfig::imu_rate_hz)("attitude_rate_hz", &BridgeConfig::attitude_rate_hz)(
      "local_position_rate_hz", &BridgeConfig::local_position_rate_hz)(
      "extended_state_rate_hz", &BridgeConfig::extended_state_rate_hz)("battery_rate_hz", &BridgeConfig::battery_rate_hz)
      .known("landing_path")
      .finish();
  const std::string path = cfg.get<std::string>("landing_path", "aerie");
  if (path == "aerie")
    c.landing_path = LandingPath::Aerie;
  else if (path == "autopilot")
    c.landing_path = LandingPath::Autopilot;
  else
    throw std::invalid_argument(cfg.origin() + ": landing_path must be 'aerie' (Aerie's pilot flies the descent) or "
                                "'autopilot' (the autopilot's precision landing), not '" + path + "'");
  c.validate();
  return c;
}

AutopilotLink::AutopilotLink(BridgeConfig config)
    : cfg_((config.validate(), std::move(config))),
      commands_(static_cast<int64_t>(cfg_.command_timeout_s * 1e6), cfg_.command_attempts),
      setpoint_rate_(cfg_.setpoint_rate_hz),
      odometry_rate_(cfg_.odometry_rate_hz),
      body_from_camera_(geometry::body_from_camera(cfg_.camera_pitch_deg)) {
}

uint64_t signing_ticks(int64_t now_us) {
  const int64_t since_2015 = now_us - static_cast<int64_t>(mav::kSigningEpochUnixSeconds) * 1'000'000;
  return static_cast<uint64_t>(std::max<int64_t>(0, since_2015 >= 0 ? since_2015 : now_us) / 10);
}

void AutopilotLink::enable_signing(const mav::Key& key, uint8_t link_id, uint64_t persisted_timestamp) {
  const mav::SigningClock clock = [now = now_us_] { return signing_ticks(*now); };
  signer_.emplace(key, link_id, persisted_timestamp, clock);
  parser_.set_signing(key, /*require=*/true, clock);
}

void AutopilotLink::log(std::string line) {
  log_.push_back(std::move(line));
  changed_ = true;
}

std::vector<std::string> AutopilotLink::take_log() { return std::exchange(log_, {}); }
bool AutopilotLink::take_changed() { return std::exchange(changed_, false); }
std::optional<AutopilotImu> AutopilotLink::take_imu() { return std::exchange(imu_, std::nullopt); }

std::optional<uint64_t> AutopilotLink::timestamp_to_persist(int64_t now_us) {
  if (!signer_ || !signer_->should_persist(signing_ticks(now_us))) return std::nullopt;
  return signer_->mark_persisted(signing_ticks(now_us));
}

template <class Msg>
void AutopilotLink::emit(const Msg& msg) {
  const mav::Header h{static_cast<uint8_t>(cfg_.system_id), static_cast<uint8_t>(cfg_.component_id), seq_++};
  out_.push_back(signer_ ? mav::encode(msg, h, *signer_) : mav::encode(msg, h));
  ++counters_.frames_out;
}

void AutopilotLink::receive(std::span<const uint8_t> bytes, int64_t now_us) {
  advance(now_us);
  parser_.feed(bytes, [&](const mav::Frame& f) { on_frame(f, now_us); });
}

void AutopilotLink::on_frame(const mav::Frame& f, int64_t now_us) {
  if (f.msgid == mav::Heartbeat::kId) {
    const auto hb = mav::decode<mav::Heartbeat>(f);
    if (hb.autopilot == mav::mav_autopilot::kInvalid) return;  // a ground station or another companion
    on_heartbeat(hb, f, now_us);
    return;
  }
  if (view_.link == AutopilotView::Link::None || f.sysid != view_.system_id) {
    if (view_.link != AutopilotView::Link::None && f.compid == view_.component_id) ++counters_.foreign_autopilot;
    return;
  }
  ++counters_.frames_in;
  view_.last_heard_us = now_us;
  if (last_seq_ >= 0) seq_expected_ += static_cast<uint8_t>(f.seq - last_seq_);
  last_seq_ = f.seq;
  ++seq_received_;
  if (seq_expected_ >= 50) {
    view_.link_quality = static_cast<float>(std::min<int64_t>(seq_received_, seq_expected_)) / seq_expected_;
    seq_received_ = seq_expected_ = 0;
  }
  std::optional<mav::Message> msg;
  try {
    msg = mav::decode_message(f);
  } catch (const std::invalid_argument&) {
    return;  // the parser has checked lengths: unreachable for a catalogue message
  }
  if (!msg) return;
  std::visit(
      [&](const auto& m) {
        using M = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<M, mav::CommandAck>) {
          on_ack(m, now_us);
        } else if constexpr (std::is_same_v<M, mav::Statustext>) {
          on_statustext(m);
        } else if constexpr (std::is_same_v<M, mav::ExtendedSysState>) {
          if (m.landed_state != view_.landed_state) changed_ = true;
          view_.landed_state = m.landed_state;
        } else if constexpr (std::is_same_v<M, mav::SysStatus>) {
          if (m.voltage_battery != UINT16_MAX) view_.battery_voltage_v = m.voltage_battery * 1e-3f;
          if (m.battery_remaining >= 0) view_.battery_remaining_pct = m.battery_remaining;
        } else if constexpr (std::is_same_v<M, mav::BatteryStatus>) {
          if (m.battery_remaining >= 0) view_.battery_remaining_pct = m.battery_remaining;
        } else if constexpr (std::is_same_v<M, mav::Timesync>) {
          if (m.tc1 != 0) {  // the answer to our request: ts1 is our time (ns), tc1 the autopilot's
            const int64_t rtt_mid_ns = (m.ts1 + now_us * 1000) / 2;
            view_.clock_offset_us = (m.tc1 - rtt_mid_ns) / 1000;
          }
        } else if constexpr (std::is_same_v<M, mav::AttitudeQuaternion>) {
          const Eigen::Quaterniond q(m.q1, m.q2, m.q3, m.q4);  // body FRD -> NED
          if (q.coeffs().allFinite() && std::abs(q.norm() - 1) < 1e-3) attitude_ned_ = q.normalized();
        } else if constexpr (std::is_same_v<M, mav::LocalPositionNed>) {
          if (attitude_ned_ && std::isfinite(m.x) && std::isfinite(m.y) && std::isfinite(m.z)) {
            view_.pose = VehicleNed{Eigen::Vector3d(m.x, m.y, m.z), *attitude_ned_};
            view_.velocity_ned = Eigen::Vector3d(m.vx, m.vy, m.vz);
          }
        } else if constexpr (std::is_same_v<M, mav::EstimatorStatus>) {
          if (m.flags != view_.estimator_flags) changed_ = true;
          view_.estimator_flags = m.flags;
        } else if constexpr (std::is_same_v<M, mav::HighresImu>) {
          AutopilotImu s;
          s.utime = now_us;
          s.angular_velocity = geometry::flip_yz(Eigen::Vector3d(m.xgyro, m.ygyro, m.zgyro));
          s.linear_acceleration = geometry::flip_yz(Eigen::Vector3d(m.xacc, m.yacc, m.zacc));
          // FRD -> NED becomes FLU -> (north, west, up): z-up, as Aerie's world.
          if (attitude_ned_) s.orientation = geometry::flip_yz(*attitude_ned_);
          if (s.angular_velocity.allFinite() && s.linear_acceleration.allFinite()) imu_ = s;
        }
      },
      *msg);
}

void AutopilotLink::on_statustext(const mav::Statustext& m) {
  // A long text comes in chunks of one id (MAVLink STATUSTEXT: id 0 = a single chunk; a chunk
  // shorter than 50 characters is the last one).
  const std::string chunk = text_of(m);
  if (m.id == 0 || m.id != statustext_id_ || m.chunk_seq == 0) statustext_.clear();
  statustext_id_ = m.id;
  if (statustext_.size() < 8 * m.text.size()) statustext_ += chunk;  // at most 8 chunks kept
  if (m.id != 0 && chunk.size() == m.text.size()) return;  // more to come
  view_.last_statustext = std::string(severity_name(m.severity)) + ": " + statustext_;
  commands_.on_statustext(statustext_);
  log("autopilot " + view_.last_statustext);
  statustext_.clear();
}

void AutopilotLink::on_heartbeat(const mav::Heartbeat& hb, const mav::Frame& f, int64_t now_us) {
  if (view_.link == AutopilotView::Link::None) {
    if (cfg_.autopilot_system_id != 0 && f.sysid != cfg_.autopilot_system_id) {
      ++counters_.foreign_autopilot;
      return;
    }
    view_.system_id = f.sysid;
    view_.component_id = f.compid;
  } else if (f.sysid != view_.system_id || f.compid != view_.component_id) {
    ++counters_.foreign_autopilot;  // a second autopilot on the link: never ours
    return;
  }
  ++counters_.frames_in;
  view_.last_heard_us = now_us;
  const bool was_up = view_.link == AutopilotView::Link::Ok;
  view_.autopilot = mav::autopilot_of(hb.autopilot);
  const bool armed = (hb.base_mode & mav::mav_mode_flag::kSafetyArmed) != 0;
  if (armed != view_.armed || hb.custom_mode != view_.custom_mode || !was_up) changed_ = true;
  if (armed != view_.armed) log(std::string("autopilot ") + (armed ? "ARMED" : "DISARMED"));
  if (!armed && view_.armed)  // landed and disarmed (or disarmed by the pilot's RC): a new flight starts afresh
    takeoff_requested_ = takeoff_sent_ = land_requested_ = precland_ = false;
  if (hb.custom_mode != view_.custom_mode || !was_up)
    log("autopilot mode " + mav::mode_name(view_.autopilot, hb.custom_mode));
  view_.armed = armed;
  view_.custom_mode = hb.custom_mode;
  view_.mode = mav::mode_name(view_.autopilot, hb.custom_mode);
  view_.system_status = hb.system_status;
  view_.in_companion_mode = mav::in_companion_mode(view_.autopilot, hb.custom_mode);
  if (!was_up) link_up();
}

void AutopilotLink::link_up() {
  view_.link = AutopilotView::Link::Ok;
  log(std::string("link up: ") + mav::to_string(view_.autopilot) + " autopilot, system " +
      std::to_string(view_.system_id) + " component " + std::to_string(view_.component_id) +
      (signer_ ? ", signed" : ", unsigned"));
  const std::pair<uint32_t, double> streams[] = {
      {mav::HighresImu::kId, cfg_.imu_rate_hz},           {mav::AttitudeQuaternion::kId, cfg_.attitude_rate_hz},
      {mav::LocalPositionNed::kId, cfg_.local_position_rate_hz}, {mav::ExtendedSysState::kId, cfg_.extended_state_rate_hz},
      {mav::BatteryStatus::kId, cfg_.battery_rate_hz}};
  // One SET_MESSAGE_INTERVAL per stream: each is acknowledged on its own, so they go out in turn
  // (the command client keeps one command of an id in flight): the first now, the rest on later polls.
  for (const auto& [id, hz] : streams)
    if (hz > 0) pending_intervals_.push_back({id, hz});
}

void AutopilotLink::send_command(uint16_t command, std::array<float, 7> p, int64_t now_us) {
  mav::CommandLong c;
  c.target_system = static_cast<uint8_t>(view_.system_id);
  c.target_component = static_cast<uint8_t>(view_.component_id);
  c.command = command;
  c.param1 = p[0];
  c.param2 = p[1];
  c.param3 = p[2];
  c.param4 = p[3];
  c.param5 = p[4];
  c.param6 = p[5];
  c.param7 = p[6];
  commands_.send(c, now_us);
  view_.last_command = command_name(command);
  view_.last_result = "sent";
  changed_ = true;
}

void AutopilotLink::on_ack(const mav::CommandAck& ack, int64_t now_us) {
  const auto r = commands_.on_ack(ack, now_us);
  if (!r) return;
  view_.last_command = command_name(r->command);
  view_.last_result = r->describe().substr(view_.last_command.size() + 2);
  // An answered mode change is not asked for again within mode_retry_s: a refusal waits, and an
  // acceptance shows in the next heartbeat (up to a second later).
  if (r->command == mav::mav_cmd::kDoSetMode) mode_answered_at_us_ = now_us;
  if (r->accepted) {
    ++counters_.commands_accepted;
  } else {
    ++counters_.commands_refused;
    if (r->command == mav::mav_cmd::kNavTakeoff || r->command == mav::mav_cmd::kComponentArmDisarm)
      takeoff_refused_at_us_ = now_us;  // the pilot's TAKEOFF asks again after mode_retry_s
  }
  log("command " + r->describe());
}

void AutopilotLink::request_arm(bool arm, int64_t now_us) {
  send_command(mav::mav_cmd::kComponentArmDisarm, {arm ? 1.0f : 0.0f, 0, 0, 0, 0, 0, 0}, now_us);
}

void AutopilotLink::request_mode(const std::string& name, int64_t now_us) {
  const auto mode = mav::custom_mode_of(view_.autopilot, name);
  if (!mode)
    throw std::invalid_argument("mode '" + name + "' is not a mode of a " + mav::to_string(view_.autopilot) +
                                " autopilot");
  const auto p = mav::set_mode_params(view_.autopilot, *mode);
  send_command(mav::mav_cmd::kDoSetMode, {p.param1, p.param2, p.param3, 0, 0, 0, 0}, now_us);
}

void AutopilotLink::on_control(const ControlInput& c, int64_t now_us) {
  advance(now_us);
  if (!c.velocity.allFinite() || !std::isfinite(c.yaw_rate_cw_deg_s) || c.mode < kHover || c.mode > kLand) {
    ++counters_.bad_inputs;
    return;
  }
  control_ = c;
  control_at_us_ = now_us;
}

void AutopilotLink::on_nav(const NavSample& s, int64_t now_us) {
  advance(now_us);
  if (!cfg_.send_odometry || view_.link != AutopilotView::Link::Ok) return;
  std::optional<mav::Odometry> o;
  try {
    o = odometry_.on_sample(s);
  } catch (const std::invalid_argument&) {
    ++counters_.bad_inputs;
    return;
  }
  if (!o || !odometry_rate_.due(now_us)) return;
  emit(*o);
  ++counters_.odometry;
}

void AutopilotLink::on_target(const CameraTarget& t, int64_t now_us) {
  advance(now_us);
  if (view_.link != AutopilotView::Link::Ok || (cfg_.landing_target_fitted_only && !t.fitted)) return;
  try {
    if (view_.autopilot == mav::Autopilot::ArduPilot) {
      emit(landing_target_ardupilot(t, body_from_camera_));
    } else {
      if (!view_.pose) return;  // PX4 wants the target in its local frame: needs its position first
      emit(landing_target_px4(t, body_from_camera_, *view_.pose));
    }
    ++counters_.landing_targets;
  } catch (const std::invalid_argument&) {
    ++counters_.bad_inputs;
  }
}

void AutopilotLink::on_pilot_state(int state, int64_t now_us) {
  advance(now_us);
  pilot_state_ = state;
}

void AutopilotLink::fly(int64_t now_us) {
  const bool fresh = control_ && now_us - control_at_us_ <= static_cast<int64_t>(cfg_.control_timeout_s * 1e6);
  const bool up = view_.link == AutopilotView::Link::Ok;
  if (!fresh || !up) {
    if (stream_since_us_ >= 0) {
      ++counters_.control_stale;
      log(up ? "control_cmd_t stale: setpoint stream stopped (the autopilot's offboard-loss failsafe takes over)"
             : "link lost: setpoint stream stopped");
    }
    stream_since_us_ = -1;
    return;
  }
  const int mode = control_->mode;
  const bool autopilot_lands =
      cfg_.landing_path == LandingPath::Autopilot && (pilot_state_ == kPilotDescend || precland_);

  if (mode == kTakeoff) {  // arm and take off once; the autopilot climbs on its own
    stream_since_us_ = -1;
    if (takeoff_refused_at_us_ >= 0 && now_us - takeoff_refused_at_us_ >= static_cast<int64_t>(cfg_.mode_retry_s * 1e6))
      takeoff_requested_ = takeoff_sent_ = false, takeoff_refused_at_us_ = -1;
    if (!takeoff_requested_ && !view_.armed) {
      takeoff_requested_ = true;
      land_requested_ = precland_ = false;
      if (view_.autopilot == mav::Autopilot::ArduPilot) request_mode("GUIDED", now_us);  // Copter arms and takes off in GUIDED
      request_arm(true, now_us);
    }
    if (takeoff_requested_ && view_.armed && !commands_.pending(mav::mav_cmd::kNavTakeoff) &&
        view_.landed_state != mav::mav_landed_state::kInAir && view_.landed_state != mav::mav_landed_state::kTakeoff &&
        !takeoff_sent_) {
      takeoff_sent_ = true;
      send_command(mav::mav_cmd::kNavTakeoff, {0, 0, 0, NAN, NAN, NAN, static_cast<float>(cfg_.takeoff_altitude_m)}, now_us);
    }
    return;
  }
  if (mode == kLand || autopilot_lands) {
    stream_since_us_ = -1;
    if (mode == kLand && !land_requested_ && view_.armed && !precland_) {  // the precision landing goes on
      land_requested_ = true;
      send_command(mav::mav_cmd::kNavLand, {0, 0, 0, NAN, NAN, NAN, NAN}, now_us);
    } else if (mode != kLand && autopilot_lands && !precland_ && view_.armed) {
      precland_ = true;
      log("the autopilot flies the descent: precision landing on LANDING_TARGET");
      if (view_.autopilot == mav::Autopilot::ArduPilot)
        request_mode("LAND", now_us);  // with PLND_ENABLED, LAND follows LANDING_TARGET
      else
        send_command(mav::mav_cmd::kNavLand, {0, 2, 0, NAN, NAN, NAN, NAN}, now_us);  // param2 2: precision land required
    }
    if (precland_ && (pilot_state_ == kPilotHold || pilot_state_ == kPilotAbort)) {
      precland_ = false;  // the pilot lost the target: its commands fly again (below, next poll)
      log("pilot left the descent: the precision landing is stopped, the companion mode asked for");
    }
    return;
  }
  // ACTIVE, HOVER, FALLBACK_HOVER: stream velocity setpoints, then ask for the companion mode.
  if (!view_.armed || land_requested_) return;
  if (stream_since_us_ < 0) stream_since_us_ = now_us;
  if (setpoint_rate_.due(now_us)) {
    const bool hold = mode == kHover || mode == kFallbackHover;
    const Eigen::Vector3d v = hold ? Eigen::Vector3d::Zero() : control_->velocity;
    const double rate = hold ? 0.0 : control_->yaw_rate_cw_deg_s;
    emit(velocity_setpoint(v, rate, static_cast<uint32_t>((now_us - boot_us_) / 1000),
                           {static_cast<uint8_t>(view_.system_id), static_cast<uint8_t>(view_.component_id)}));
    ++counters_.setpoints;
  }
  if (!view_.in_companion_mode && now_us - stream_since_us_ >= static_cast<int64_t>(cfg_.offboard_warmup_s * 1e6) &&
      !commands_.pending(mav::mav_cmd::kDoSetMode) &&
      now_us - mode_answered_at_us_ >= static_cast<int64_t>(cfg_.mode_retry_s * 1e6))
    request_mode(mav::mode_name(view_.autopilot, mav::companion_mode(view_.autopilot)), now_us);
}

std::vector<std::vector<uint8_t>> AutopilotLink::poll(int64_t now_us) {
  advance(now_us);
  if (boot_us_ < 0) boot_us_ = now_us;
  if (view_.link == AutopilotView::Link::Ok &&
      now_us - view_.last_heard_us > static_cast<int64_t>(cfg_.link_timeout_s * 1e6)) {
    view_.link = AutopilotView::Link::Lost;
    ++counters_.link_losses;
    log("link LOST: no heartbeat from the autopilot for " + std::to_string(cfg_.link_timeout_s) + " s");
  } else if (view_.link == AutopilotView::Link::Lost && now_us - view_.last_heard_us <= 1'000'000) {
    link_up();
  }
  if (now_us - last_heartbeat_sent_ >= static_cast<int64_t>(cfg_.heartbeat_period_s * 1e6)) {
    mav::Heartbeat hb;
    hb.type = mav::mav_type::kOnboardController;
    hb.autopilot = mav::mav_autopilot::kInvalid;
    hb.system_status = mav::mav_state::kActive;
    hb.mavlink_version = 3;
    emit(hb);
    if (view_.link == AutopilotView::Link::Ok) {
      mav::Timesync ts;
      ts.ts1 = now_us * 1000;
      ts.target_system = static_cast<uint8_t>(view_.system_id);
      ts.target_component = static_cast<uint8_t>(view_.component_id);
      emit(ts);
    }
    last_heartbeat_sent_ = now_us;
  }
  if (view_.link == AutopilotView::Link::Ok && !pending_intervals_.empty() &&
      !commands_.pending(mav::mav_cmd::kSetMessageInterval)) {
    const auto [id, hz] = pending_intervals_.front();
    pending_intervals_.erase(pending_intervals_.begin());
    send_command(mav::mav_cmd::kSetMessageInterval, {static_cast<float>(id), static_cast<float>(1e6 / hz), 0, 0, 0, 0, 0},
                 now_us);
  }
  fly(now_us);
  for (const mav::CommandLong& c : commands_.due(now_us)) emit(c);
  for (const auto& r : commands_.expired(now_us)) {
    ++counters_.commands_timed_out;
    view_.last_command = command_name(r.command);
    view_.last_result = "no COMMAND_ACK (timed out)";
    if (r.command == mav::mav_cmd::kDoSetMode) mode_answered_at_us_ = now_us;
    log("command " + r.describe() + " after " + std::to_string(cfg_.command_attempts) + " attempts");
  }
  return std::exchange(out_, {});
}

}  // namespace aerie::bridge
