#include "air/pilot/pilot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

#include "common/geometry/frames.hpp"

namespace aerie::pilot {

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;

// Wraps degrees to (-90, 90]: the pad's H looks the same after half a turn.
double wrap_half_turn_deg(double a) {
  a = std::remainder(a, 180.0);
  return a <= -90.0 ? a + 180.0 : a;
}

bool airborne(State s) {
  return s != State::Idle && s != State::Landed && s != State::Touchdown;
}
}  // namespace

const char* state_name(State s) {
  static constexpr const char* kNames[] = {"IDLE",    "TAKEOFF",   "SURVEY", "ACQUIRE", "APPROACH", "DESCEND",
                                           "TOUCHDOWN", "LANDED", "HOLD",    "ABORT",    "ABORTED"};
  return kNames[static_cast<int>(s)];
}

void PilotConfig::validate() const {
  auto need = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("pilot config: ") + what);
  };
  need(controller == "fuzzy" || controller == "pid", "controller must be fuzzy or pid");
  need(takeoff_time_s > 0 && takeoff_min_s >= 0 && acquire_timeout_s > 0 && hold_timeout_s > 0 && touchdown_time_s > 0,
       "takeoff_time_s, acquire_timeout_s, hold.timeout_s and descent.touchdown_time_s must be > 0");
  need(survey_speed_m_s > 0 && descent_speed_m_s > 0 && abort_climb_m_s > 0 && hold_climb_m_s >= 0,
       "survey, descent and abort speeds must be > 0, the hold climb >= 0");
  need(approach_height_m > touchdown_height_m && touchdown_height_m > 0,
       "approach.height_m must exceed descent.touchdown_height_m > 0");
  need(approach_tolerance_m > 0 && yaw_tolerance_deg > 0 && height_tolerance_m > 0 && descent_gate_m > 0 &&
           handover_tolerance_m > 0,
       "tolerances, descent.gate_m and descent.handover_tolerance_m must be > 0");
  need(settle_frames >= 1 && loss_frames >= 1 && handover_frames >= 1,
       "settle_frames, loss_frames and descent.handover_frames must be >= 1");
  need(max_input_age_s >= 0 && max_input_age_s <= 60, "max_input_age_s must be in [0, 60] s (0 = off)");
  need(stale_timeout_s > 0 && control_period_s > 0 && abort_climb_s >= 0 && hold_climb_max_s >= 0,
       "stale_timeout_s and control_period_s must be > 0");
  for (const auto& leg : survey_legs) need(leg.allFinite(), "survey legs must be finite");
  feedforward.estimator.validate();
  need(feedforward.min_speed_m_s >= 0 && feedforward.max_speed_m_s > 0 && feedforward.touchdown_speed_m_s > 0 &&
           feedforward.touchdown_margin_s >= 0,
       "feedforward: min_speed_m_s >= 0, max_speed_m_s > 0, touchdown_speed_m_s > 0, touchdown_margin_s >= 0");
  const std::pair<const char*, const AxisGains*> axes[] = {{"forward", &forward}, {"left", &left}, {"up", &up}, {"yaw", &yaw}};
  for (const auto& [axis, g] : axes)
    if (!g->valid())
      throw std::invalid_argument("pilot config: gains." + controller + "." + axis +
                                  ": finite; kp, ki, kd >= 0; ku, integral_limit, output_limit > 0");
}

Pilot::Pilot(PilotConfig config) : cfg_(std::move(config)), pad_velocity_(cfg_.feedforward.estimator) {
  cfg_.validate();
  forward_ = make_axis(cfg_.controller, cfg_.fuzzy_base, cfg_.forward);
  left_ = make_axis(cfg_.controller, cfg_.fuzzy_base, cfg_.left);
  up_ = make_axis(cfg_.controller, cfg_.fuzzy_base, cfg_.up);
  yaw_ = make_axis(cfg_.controller, cfg_.fuzzy_base, cfg_.yaw);
  R_body_cam_ = geometry::body_from_camera(cfg_.camera_pitch_deg);
  status_.state = State::Idle;
}

void Pilot::on_attitude(int64_t, const Eigen::Quaterniond& q) {
  if (!q.coeffs().allFinite() || std::abs(q.norm() - 1.0) > 1e-3)
    throw std::invalid_argument("attitude is not a finite unit quaternion");
  attitude_ = q;
}

void Pilot::on_target(const TargetObservation& t) {
  if (!t.position_cam.allFinite() || !std::isfinite(t.yaw_cam) || !(t.position_cam.z() > 0))
    throw std::invalid_argument("target pose is not finite or not in front of the camera");
  target_ = t;
}

void Pilot::enter(State s, int64_t utime, const std::string& reason) {
  if (s == State::Approach && status_.state != State::Hold) reset_controllers();
  if (s == State::Hold) hold_ff_level_ = estimated_feedforward();  // follow the pad's last motion
  if (s == State::Touchdown) {  // the handover onto a moving pad sets them
    touchdown_ff_level_.setZero();
    blind_s_ = 0;
  }
  status_.state = s;
  status_.reason = reason;
  state_since_ = utime;
  settled_run_ = 0;
}

void Pilot::reset_controllers() {
  forward_->reset();
  left_->reset();
  up_->reset();
  yaw_->reset();
}

Command Pilot::hover(int64_t utime) const {
  Command c;
  c.utime = utime;
  c.mode = Command::Mode::Velocity;  // zero velocity: the autopilot holds position and height
  return c;
}

Command Pilot::steer(int64_t utime, double t, const Eigen::Vector3d& target, double yaw_error_deg, double vz) {
  Command c = hover(utime);
  c.velocity = {forward_->update(t, target.x()), left_->update(t, target.y()), vz};
  if (ff_on_) c.velocity.head<2>() += ff_;  // only when on: -0.0 + 0.0 would change a still pad's bytes
  c.yaw_rate_deg_s = yaw_->update(t, yaw_error_deg);
  return c;
}

Eigen::Vector2d Pilot::to_heading(const Eigen::Vector2d& level) const {
  return Eigen::Rotation2Dd(-ahrs_yaw_) * level;
}

Eigen::Vector2d Pilot::estimated_feedforward() const {
  const auto& f = cfg_.feedforward;
  const Eigen::Vector2d v = pad_velocity_.velocity();
  if (!f.enabled || v.norm() < f.min_speed_m_s) return Eigen::Vector2d::Zero();
  return v.norm() > f.max_speed_m_s ? Eigen::Vector2d(v.normalized() * f.max_speed_m_s) : v;
}

void Pilot::on_autopilot_link(bool ok, int64_t utime) {
  autopilot_link_ok_ = ok;
  if (!ok && (status_.state == State::Approach || status_.state == State::Descend)) {
    resume_state_ = status_.state;
    ++status_.link_holds;
    enter(State::Hold, utime, "autopilot link lost (no heartbeat)");
  }
}

Command Pilot::on_track(int64_t utime, TrackStatus status, std::optional<double> age_s) {
  last_track_ = utime;
  if (!autopilot_link_ok_) return tick(utime, false, TrackStatus::Idle);  // as stale: HOLD cannot resume
  if (cfg_.max_input_age_s > 0 && age_s && *age_s > cfg_.max_input_age_s) {
    ++status_.aged_results;
    if (status_.state == State::Approach || status_.state == State::Descend) {
      resume_state_ = status_.state;
      ++status_.age_holds;
      char why[96];
      std::snprintf(why, sizeof why, "tracker result %.2f s old (limit %.2f s)", *age_s, cfg_.max_input_age_s);
      enter(State::Hold, utime, why);
    }
    return tick(utime, false, TrackStatus::Idle);  // no target from it: HOLD cannot re-acquire on it
  }
  return tick(utime, true, status);
}

std::optional<Command> Pilot::on_clock(int64_t utime) {
  if (last_track_ < 0) last_track_ = utime;  // the silence starts with the first message
  if (utime - last_track_ < static_cast<int64_t>(cfg_.stale_timeout_s * 1e6)) return std::nullopt;
  if (last_tick_ >= 0 && utime - last_tick_ < static_cast<int64_t>(cfg_.control_period_s * 1e6)) return std::nullopt;
  if (status_.state == State::Approach || status_.state == State::Descend) {
    resume_state_ = status_.state;
    ++status_.stale_holds;
    enter(State::Hold, utime, "no tracker result for " + std::to_string((utime - last_track_) * 1e-6) + " s (stale)");
  }
  return tick(utime, false, TrackStatus::Idle);
}

bool Pilot::on_operator(Operator cmd, int64_t utime, std::string* why) {
  auto refuse = [&](const std::string& w) {
    if (why) *why = w + " in state " + state_name(status_.state);
    return false;
  };
  switch (cmd) {
    case Operator::Start:
      if (status_.state != State::Idle) return refuse("START");
      started_ = true;
      return true;
    case Operator::Abort:
      if (!airborne(status_.state) || status_.state == State::Aborted) return refuse("ABORT");
      enter(State::Abort, utime, "operator ABORT");
      return true;
    case Operator::Land:
      if (!airborne(status_.state)) return refuse("LAND");
      enter(State::Touchdown, utime, "operator LAND");
      return true;
    case Operator::Resume:
      if (status_.state != State::Hold && status_.state != State::Aborted) return refuse("RESUME");
      enter(State::Acquire, utime, "operator RESUME");
      return true;
  }
  return refuse("unknown command");
}

Command Pilot::tick(int64_t utime, bool fresh_track, TrackStatus track) {
  last_tick_ = utime;
  const double t = utime * 1e-6;
  // The target of this frame, in the levelled heading frame.
  const bool tracked = track == TrackStatus::Tracking || track == TrackStatus::Redetected;
  const bool have = fresh_track && tracked && target_ && target_->utime == utime;
  if (fresh_track) lost_run_ = have ? 0 : lost_run_ + 1;
  status_.target_valid = have;
  Eigen::Vector3d p = Eigen::Vector3d::Constant(std::nan(""));
  double yaw_err = std::nan(""), height = std::nan("");
  if (have) {
    // R = Rz(yaw) * tilt (ZYX): remove the yaw to keep roll and pitch.
    const Eigen::Matrix3d R = attitude_.toRotationMatrix();
    const Eigen::Matrix3d tilt = Eigen::AngleAxisd(-std::atan2(R(1, 0), R(0, 0)), Eigen::Vector3d::UnitZ()) * R;
    p = tilt * (R_body_cam_ * target_->position_cam);
    height = -p.z();
  }
  if (cfg_.feedforward.enabled) {
    const Eigen::Matrix3d R = attitude_.toRotationMatrix();
    ahrs_yaw_ = std::atan2(R(1, 0), R(0, 0));
    if (have) pad_velocity_.observe(t, Eigen::Rotation2Dd(ahrs_yaw_) * p.head<2>());
    ff_ = to_heading(estimated_feedforward());
    ff_on_ = !ff_.isZero();
    status_.pad_velocity = pad_velocity_.velocity();
  }
  if (have) {
    // Body forward is image "up" (-y) for a camera pitched down: the pad's axis should sit
    // at -90 deg in the image; the rest is the turn still needed (clockwise positive).
    yaw_err = wrap_half_turn_deg(target_->yaw_cam / kDeg + 90.0);
  }
  status_.target_level = p;
  status_.yaw_error_deg = yaw_err;
  status_.height_m = height;

  auto time_in_state = [&] { return (utime - state_since_) * 1e-6; };
  auto lost = [&](State resume) {
    if (lost_run_ < cfg_.loss_frames) return false;
    resume_state_ = resume;
    ++status_.losses;
    enter(State::Hold, utime, "target lost for " + std::to_string(lost_run_) + " frames");
    return true;
  };

  Command c = hover(utime);
  switch (status_.state) {
    case State::Idle:
      if (!cfg_.wait_for_start || started_) {
        enter(State::Takeoff, utime, cfg_.wait_for_start ? "operator START" : "mission start");
        c.mode = Command::Mode::Takeoff;
      }
      break;
    case State::Takeoff:
      c.mode = Command::Mode::Takeoff;
      if (have && time_in_state() >= cfg_.takeoff_min_s)
        enter(State::Approach, utime, "target acquired during the take-off");
      else if (time_in_state() >= cfg_.takeoff_time_s)
        enter(cfg_.survey_legs.empty() ? State::Acquire : State::Survey, utime, "take-off done");
      break;
    case State::Survey: {
      if (have) {
        enter(State::Approach, utime, "target acquired during the survey");
        break;
      }
      // The legs are dead-reckoned: each is flown at the survey speed for its length.
      double elapsed = time_in_state();
      bool on_leg = false;
      for (const auto& leg : cfg_.survey_legs) {
        const double duration = leg.norm() / cfg_.survey_speed_m_s;
        if (elapsed < duration) {
          c.velocity.head<2>() = leg.normalized() * cfg_.survey_speed_m_s;
          on_leg = true;
          break;
        }
        elapsed -= duration;
      }
      if (!on_leg) enter(State::Acquire, utime, "survey done without the target");
      break;
    }
    case State::Acquire:
      if (have)
        enter(State::Approach, utime, "target acquired");
      else if (time_in_state() >= cfg_.acquire_timeout_s)
        enter(State::Abort, utime, "no target within " + std::to_string(cfg_.acquire_timeout_s) + " s");
      break;
    case State::Approach:
      if (!have) {
        lost(State::Approach);
        break;
      }
      c = steer(utime, t, p, yaw_err, up_->update(t, cfg_.approach_height_m - height));
      settled_run_ = p.head<2>().norm() < cfg_.approach_tolerance_m && std::abs(yaw_err) < cfg_.yaw_tolerance_deg &&
                             std::abs(height - cfg_.approach_height_m) < cfg_.height_tolerance_m
                         ? settled_run_ + 1
                         : 0;
      if (settled_run_ >= cfg_.settle_frames) enter(State::Descend, utime, "centred and aligned over the target");
      break;
    case State::Descend: {
      if (!have) {
        lost(State::Descend);
        break;
      }
      if (!target_->fitted) {
        // A box-only pose is too coarse this low: a box cut by the image border, chased,
        // leads the vehicle off the pad. Hover (moving with a moving pad), and climb slowly
        // (a wider view) until the pad's geometry is fitted again.
        settled_run_ = 0;
        if (ff_on_) c.velocity.head<2>() = ff_;
        if (height < cfg_.approach_height_m) c.velocity.z() = cfg_.hold_climb_m_s;
        break;
      }
      const double off = p.head<2>().norm();
      if (height < cfg_.touchdown_height_m) {
        // The autopilot's LAND below is blind and keeps the point where it begins: hand over
        // only when centred and aligned, else hold this height and keep centring on vision.
        settled_run_ = off < cfg_.handover_tolerance_m && std::abs(yaw_err) < cfg_.yaw_tolerance_deg ? settled_run_ + 1 : 0;
        if (settled_run_ >= cfg_.handover_frames) {
          enter(State::Touchdown, utime, "centred below the touchdown height");
          c.mode = Command::Mode::Land;
          if (ff_on_) {  // a moving pad: descend with it (LAND would stop over the ground)
            touchdown_ff_level_ = estimated_feedforward();
            blind_s_ = height / cfg_.feedforward.touchdown_speed_m_s + cfg_.feedforward.touchdown_margin_s;
            c.mode = Command::Mode::Velocity;
            c.velocity = {ff_.x(), ff_.y(), -cfg_.feedforward.touchdown_speed_m_s};
          }
        } else {
          c = steer(utime, t, p, yaw_err, 0.0);
        }
        break;
      }
      // Slower with the horizontal error (the gate) and near the handover height (1/s on the
      // height left, crossing it at 5 cm/s), so that the pad stays in view.
      const double gate = std::clamp(1.0 - off / cfg_.descent_gate_m, 0.0, 1.0);
      const double vz = std::min(cfg_.descent_speed_m_s * gate, height - cfg_.touchdown_height_m + 0.05);
      c = steer(utime, t, p, yaw_err, -vz);
      break;
    }
    case State::Touchdown:
      c.mode = Command::Mode::Land;
      if (time_in_state() < blind_s_) {  // onto a moving pad: with it, blind, then LAND
        const Eigen::Vector2d v = to_heading(touchdown_ff_level_);
        c.mode = Command::Mode::Velocity;
        c.velocity = {v.x(), v.y(), -cfg_.feedforward.touchdown_speed_m_s};
      }
      if (time_in_state() >= cfg_.touchdown_time_s + blind_s_) enter(State::Landed, utime, "touchdown");
      break;
    case State::Landed:
      c.mode = Command::Mode::Land;
      break;
    case State::Hold:
      if (have) {
        ++status_.reacquisitions;
        enter(resume_state_, utime, "target re-acquired");
        break;
      }
      if (time_in_state() >= cfg_.hold_timeout_s) {
        enter(State::Abort, utime, "target not re-acquired within " + std::to_string(cfg_.hold_timeout_s) + " s");
        break;
      }
      if (time_in_state() < cfg_.hold_climb_max_s) c.velocity.z() = cfg_.hold_climb_m_s;
      if (!hold_ff_level_.isZero()) c.velocity.head<2>() = to_heading(hold_ff_level_);  // with the pad's last motion
      break;
    case State::Abort:
      c.velocity.z() = cfg_.abort_climb_m_s;
      if (time_in_state() >= cfg_.abort_climb_s) enter(State::Aborted, utime, status_.reason);
      break;
    case State::Aborted:
      break;
  }
  status_.time_in_state_s = time_in_state();
  if (cfg_.feedforward.enabled) {
    // What the vehicle is asked to fly from now on (HOVER, TAKEOFF and LAND hold still).
    const bool flies = c.mode == Command::Mode::Velocity;
    pad_velocity_.command(t, flies ? Eigen::Vector2d(Eigen::Rotation2Dd(ahrs_yaw_) * c.velocity.head<2>()) : Eigen::Vector2d::Zero());
    status_.feedforward = flies ? ff_ : Eigen::Vector2d::Zero();
  }
  return last_ = c;
}

}  // namespace aerie::pilot
