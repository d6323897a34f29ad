#include "common/sim/autopilot/sim_autopilot.hpp"

#include "common/mavlink/modes.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace aerie::sim::autopilot {

Params airframe_params(const MultirotorParams& vehicle, uint64_t seed) {
  Params p;
  p.EKF2_OF_CTRL = 1;
  p.EKF2_EV_CTRL = 0;
  p.EKF2_HGT_REF = 2;  // range finder
  p.VISO_TYPE = 0;
  p.EK3_SRC1_POSXY = 0;
  p.EK3_SRC1_VELXY = 5;  // OpticalFlow
  p.EK3_SRC1_POSZ = 2;   // range finder
  p.flow_drift_m_per_sqrt_s = vehicle.hold_drift_m_per_sqrt_s;
  p.MPC_TKO_SPEED = std::min(p.MPC_TKO_SPEED, vehicle.max_vertical_speed_m_s);
  p.WPNAV_SPEED_UP = std::min(p.WPNAV_SPEED_UP, 100 * vehicle.max_vertical_speed_m_s);
  p.MPC_LAND_SPEED = vehicle.land_speed_m_s;
  p.LAND_SPEED = static_cast<int>(std::lround(100 * vehicle.land_speed_m_s));
  p.noise_seed = seed;
  return p;
}

const char* to_string(PrecLandState s) {
  switch (s) {
    case PrecLandState::Idle: return "idle";
    case PrecLandState::Start: return "start";
    case PrecLandState::HorizontalApproach: return "horizontal_approach";
    case PrecLandState::DescendAboveTarget: return "descend_above_target";
    case PrecLandState::FinalApproach: return "final_approach";
    case PrecLandState::Search: return "search";
    case PrecLandState::Fallback: return "fallback";
    case PrecLandState::Done: return "done";
  }
  return "?";
}


namespace mv = aerie::mavlink;
// PX4 main/sub modes and ArduCopter mode numbers (common/mavlink/modes.hpp).
namespace px4 = aerie::mavlink::px4;
namespace copter = aerie::mavlink::copter;

namespace {

constexpr double kG = 9.81;
constexpr double kPi = std::numbers::pi;
// Setpoints must arrive at > 2 Hz (PX4 "Offboard Mode": "a stream of setpoints at more than
// 2 Hz"): a gap longer than this breaks the run ...
constexpr double kSetpointGap_s = 0.5;
// ... and the run must have lasted this long before OFFBOARD is accepted ("about 1 s").
constexpr double kOffboardWarmup_s = 1.0;
// Vision not heard from for this long: the estimator stops using it and the local position is
// invalid (a fixed stand-in for EKF2's aiding-source timeout plus commander's position checks).
constexpr double kVisionTimeout_s = 1.0;
// Complementary filter weight of one vision innovation (estimate error state += w * innovation).
constexpr double kVisionWeight = 0.3;
// ArduPilot AC_PrecLand.cpp LANDING_TARGET_TIMEOUT_MS: the target is dropped after 2 s.
constexpr double kArduTargetTimeout_s = 2.0;
// PX4 precland.cpp STATE_TIMEOUT: horizontal approach taking longer falls back to a normal land.
constexpr double kPrecLandStateTimeout_s = 10.0;
// Land detector: ground contact without vertical motion for this long (ArduCopter
// LAND_DETECTOR_TRIGGER_SEC 1 s; PX4's multicopter land detector needs a similar time).
constexpr double kLandDetect_s = 1.0;
// Take-off complete within this of the take-off altitude (PX4 NAV_MC_ALT_RAD-like).
constexpr double kTakeoffAcceptance_m = 0.3;
// RTL: close enough to home to land.
constexpr double kReturnAcceptance_m = 0.3;
// MAV_CMD_COMPONENT_ARM_DISARM param2 magic: arm/disarm without checks.
constexpr float kForceMagic = 21196.0f;
// Streamed message ids.
constexpr uint32_t kStreamIds[] = {mv::Heartbeat::kId,        mv::SysStatus::kId,    mv::AttitudeQuaternion::kId,
                                   mv::LocalPositionNed::kId, mv::HighresImu::kId,   mv::DistanceSensor::kId,
                                   mv::BatteryStatus::kId,    mv::ExtendedSysState::kId};

template <class T>
void set_text(std::array<char, 50>& dst, const T& s) {
  dst.fill(0);
  std::memcpy(dst.data(), s.data(), std::min<size_t>(s.size(), dst.size()));
}

std::string id_string(const std::array<char, 16>& id) {
  size_t n = 0;
  while (n < id.size() && id[n] != '\0') ++n;
  return std::string(id.data(), n);
}

bool finite3(float a, float b, float c) { return std::isfinite(a) && std::isfinite(b) && std::isfinite(c); }

// A float command parameter as an integer in [lo, hi]; -1 when it is not (NaN, out of range).
int64_t int_param(float f, int64_t lo, int64_t hi) {
  if (!std::isfinite(f) || f < static_cast<float>(lo) || f > static_cast<float>(hi)) return -1;
  return static_cast<int64_t>(f);
}


struct ParamDef {
  const char* name;
  Personality who;
  double Params::*d;
  int Params::*i;
};

const std::vector<ParamDef>& param_defs() {
  using P = Params;
  constexpr auto X = Personality::Px4;
  constexpr auto A = Personality::ArduCopter;
  static const std::vector<ParamDef> defs = {
      {"COM_OF_LOSS_T", X, &P::COM_OF_LOSS_T, nullptr},   {"COM_OBL_RC_ACT", X, nullptr, &P::COM_OBL_RC_ACT},
      {"COM_RC_IN_MODE", X, nullptr, &P::COM_RC_IN_MODE}, {"COM_DISARM_LAND", X, &P::COM_DISARM_LAND, nullptr},
      {"COM_OBC_LOSS_T", X, &P::COM_OBC_LOSS_T, nullptr}, {"MIS_TAKEOFF_ALT", X, &P::MIS_TAKEOFF_ALT, nullptr},
      {"MPC_TKO_SPEED", X, &P::MPC_TKO_SPEED, nullptr},   {"MPC_LAND_SPEED", X, &P::MPC_LAND_SPEED, nullptr},
      {"MPC_XY_P", X, &P::MPC_XY_P, nullptr},             {"MPC_Z_P", X, &P::MPC_Z_P, nullptr},
      {"EKF2_EV_CTRL", X, nullptr, &P::EKF2_EV_CTRL},     {"EKF2_EV_DELAY", X, &P::EKF2_EV_DELAY, nullptr},
      {"EKF2_HGT_REF", X, nullptr, &P::EKF2_HGT_REF},     {"PLD_HACC_RAD", X, &P::PLD_HACC_RAD, nullptr},
      {"EKF2_OF_CTRL", X, nullptr, &P::EKF2_OF_CTRL},
      {"PLD_BTOUT", X, &P::PLD_BTOUT, nullptr},           {"PLD_FAPPR_ALT", X, &P::PLD_FAPPR_ALT, nullptr},
      {"PLD_SRCH_ALT", X, &P::PLD_SRCH_ALT, nullptr},     {"PLD_SRCH_TOUT", X, &P::PLD_SRCH_TOUT, nullptr},
      {"PLD_MAX_SRCH", X, nullptr, &P::PLD_MAX_SRCH},
      {"GUID_TIMEOUT", A, &P::GUID_TIMEOUT, nullptr},     {"VISO_TYPE", A, nullptr, &P::VISO_TYPE},
      {"VISO_DELAY_MS", A, nullptr, &P::VISO_DELAY_MS},   {"EK3_SRC1_POSXY", A, nullptr, &P::EK3_SRC1_POSXY},
      {"EK3_SRC1_VELXY", A, nullptr, &P::EK3_SRC1_VELXY}, {"EK3_SRC1_POSZ", A, nullptr, &P::EK3_SRC1_POSZ},
      {"EK3_SRC1_YAW", A, nullptr, &P::EK3_SRC1_YAW},     {"FS_EKF_ACTION", A, nullptr, &P::FS_EKF_ACTION},
      {"PLND_ENABLED", A, nullptr, &P::PLND_ENABLED},     {"PLND_TYPE", A, nullptr, &P::PLND_TYPE},
      {"LAND_SPEED", A, nullptr, &P::LAND_SPEED},         {"PILOT_TKOFF_ALT", A, &P::PILOT_TKOFF_ALT, nullptr},
      {"WPNAV_SPEED_UP", A, &P::WPNAV_SPEED_UP, nullptr}, {"PSC_POSXY_P", A, &P::PSC_POSXY_P, nullptr},
      {"PSC_POSZ_P", A, &P::PSC_POSZ_P, nullptr},
  };
  return defs;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Frames

Eigen::Vector3d enu_to_ned(const Eigen::Vector3d& v) { return {v.y(), v.x(), -v.z()}; }
Eigen::Vector3d ned_to_enu(const Eigen::Vector3d& v) { return {v.y(), v.x(), -v.z()}; }

Eigen::Vector3d ned_to_heading(const Eigen::Vector3d& v_ned, double yaw_enu) {
  const Eigen::Vector3d e = ned_to_enu(v_ned);
  const double c = std::cos(yaw_enu), s = std::sin(yaw_enu);
  return {c * e.x() + s * e.y(), -s * e.x() + c * e.y(), e.z()};
}

Eigen::Vector3d heading_to_ned(const Eigen::Vector3d& v_h, double yaw_enu) {
  const double c = std::cos(yaw_enu), s = std::sin(yaw_enu);
  return enu_to_ned({c * v_h.x() - s * v_h.y(), s * v_h.x() + c * v_h.y(), v_h.z()});
}

Eigen::Vector3d body_ned_to_heading(const Eigen::Vector3d& v) { return {v.x(), -v.y(), -v.z()}; }

Eigen::Matrix3d ned_from_frd(double roll, double pitch, double yaw_enu) {
  const Eigen::Matrix3d R_enu_flu = (Eigen::AngleAxisd(yaw_enu, Eigen::Vector3d::UnitZ()) *
                                     Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                                     Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                                        .toRotationMatrix();
  Eigen::Matrix3d T;
  T << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  const Eigen::Matrix3d F = Eigen::Vector3d(1, -1, -1).asDiagonal();
  return T * R_enu_flu * F;
}

// ---------------------------------------------------------------------------------------------
// Params

void Params::validate() const {
  auto need = [](bool ok, const char* field, const std::string& expected, double got) {
    if (!ok) {
      std::ostringstream o;
      o << "autopilot Params: " << field << " must be " << expected << " (got " << got << ")";
      throw std::invalid_argument(o.str());
    }
  };
  auto pos = [&](double v, const char* f) { need(std::isfinite(v) && v > 0, f, "> 0", v); };
  auto in = [&](double v, double lo, double hi, const char* f) {
    std::ostringstream e;
    e << "in [" << lo << ", " << hi << "]";
    need(std::isfinite(v) && v >= lo && v <= hi, f, e.str(), v);
  };
  in(COM_OF_LOSS_T, 0.01, 60, "COM_OF_LOSS_T");
  in(COM_OBL_RC_ACT, 0, 5, "COM_OBL_RC_ACT");
  in(COM_RC_IN_MODE, 0, 4, "COM_RC_IN_MODE");
  in(COM_DISARM_LAND, -1, 20, "COM_DISARM_LAND");
  pos(COM_OBC_LOSS_T, "COM_OBC_LOSS_T");
  pos(MIS_TAKEOFF_ALT, "MIS_TAKEOFF_ALT");
  pos(MPC_TKO_SPEED, "MPC_TKO_SPEED");
  pos(MPC_LAND_SPEED, "MPC_LAND_SPEED");
  pos(MPC_XY_P, "MPC_XY_P");
  pos(MPC_Z_P, "MPC_Z_P");
  in(EKF2_EV_CTRL, 0, 15, "EKF2_EV_CTRL");
  in(EKF2_EV_DELAY, 0, 300, "EKF2_EV_DELAY");
  in(EKF2_HGT_REF, 0, 3, "EKF2_HGT_REF");
  in(EKF2_OF_CTRL, 0, 1, "EKF2_OF_CTRL");
  in(flow_drift_m_per_sqrt_s, 0, 1, "flow_drift_m_per_sqrt_s");
  pos(PLD_HACC_RAD, "PLD_HACC_RAD");
  pos(PLD_BTOUT, "PLD_BTOUT");
  in(PLD_FAPPR_ALT, 0, 10, "PLD_FAPPR_ALT");
  pos(PLD_SRCH_ALT, "PLD_SRCH_ALT");
  pos(PLD_SRCH_TOUT, "PLD_SRCH_TOUT");
  in(PLD_MAX_SRCH, 0, 100, "PLD_MAX_SRCH");
  pos(GUID_TIMEOUT, "GUID_TIMEOUT");
  in(VISO_TYPE, 0, 3, "VISO_TYPE");
  in(VISO_DELAY_MS, 0, 250, "VISO_DELAY_MS");
  in(EK3_SRC1_POSXY, 0, 7, "EK3_SRC1_POSXY");
  in(EK3_SRC1_VELXY, 0, 7, "EK3_SRC1_VELXY");
  in(EK3_SRC1_POSZ, 0, 7, "EK3_SRC1_POSZ");
  in(EK3_SRC1_YAW, 0, 8, "EK3_SRC1_YAW");
  in(FS_EKF_ACTION, 0, 3, "FS_EKF_ACTION");
  in(PLND_ENABLED, 0, 1, "PLND_ENABLED");
  in(PLND_TYPE, 0, 4, "PLND_TYPE");
  in(LAND_SPEED, 30, 200, "LAND_SPEED");
  in(PILOT_TKOFF_ALT, 0, 1000, "PILOT_TKOFF_ALT");
  pos(WPNAV_SPEED_UP, "WPNAV_SPEED_UP");
  pos(PSC_POSXY_P, "PSC_POSXY_P");
  pos(PSC_POSZ_P, "PSC_POSZ_P");
  pos(battery_capacity_mah, "battery_capacity_mah");
  in(battery_cells, 1, 14, "battery_cells");
  in(battery_idle_current_a, 0, 1000, "battery_idle_current_a");
  in(battery_flight_current_a, 0, 1000, "battery_flight_current_a");
  in(imu_accel_noise_m_s2, 0, 10, "imu_accel_noise_m_s2");
  in(imu_gyro_noise_rad_s, 0, 1, "imu_gyro_noise_rad_s");
}

// ---------------------------------------------------------------------------------------------
// Construction, parameters

SimAutopilot::SimAutopilot(Personality personality, const Params& params)
    : personality_(personality), p_(params), mode_(personality == Personality::Px4 ? FlightMode::Position
                                                                                  : FlightMode::Manual),
      rng_(params.noise_seed),
      flow_rng_(params.noise_seed * 2654435761u + 1) {
  p_.validate();
  // Default rates: PX4's MAVLink "Onboard" mode (mavlink_main.cpp configure_streams_to_default);
  // ArduCopter's SRn_* stream groups at 2 Hz (companions set rates with SET_MESSAGE_INTERVAL).
  const bool px = personality_ == Personality::Px4;
  auto hz = [](double f) { return f > 0 ? 1.0 / f : 0.0; };
  const std::map<uint32_t, double> rates = {
      {mv::Heartbeat::kId, 1.0},
      {mv::SysStatus::kId, px ? 5.0 : 2.0},
      {mv::AttitudeQuaternion::kId, px ? 50.0 : 0.0},
      {mv::LocalPositionNed::kId, px ? 30.0 : 2.0},
      {mv::HighresImu::kId, px ? 50.0 : 0.0},
      {mv::DistanceSensor::kId, px ? 10.0 : 2.0},
      {mv::BatteryStatus::kId, px ? 0.5 : 2.0},
      {mv::ExtendedSysState::kId, px ? 5.0 : 2.0},
  };
  for (uint32_t id : kStreamIds) {
    Stream s;
    s.interval = s.default_interval = hz(rates.at(id));
    streams_[id] = s;
  }
}

uint16_t SimAutopilot::param_count() const {
  return static_cast<uint16_t>(
      std::count_if(param_defs().begin(), param_defs().end(), [&](const ParamDef& d) { return d.who == personality_; }));
}

std::optional<ParamEntry> SimAutopilot::param(uint16_t index) const {
  uint16_t i = 0;
  for (const ParamDef& d : param_defs()) {
    if (d.who != personality_) continue;
    if (i == index) {
      ParamEntry e;
      e.name = d.name;
      e.is_int = d.i != nullptr;
      e.value = d.i ? static_cast<double>(p_.*(d.i)) : p_.*(d.d);
      e.index = i;
      e.count = param_count();
      return e;
    }
    ++i;
  }
  return std::nullopt;
}

std::optional<ParamEntry> SimAutopilot::param(const std::string& name) const {
  uint16_t i = 0;
  for (const ParamDef& d : param_defs()) {
    if (d.who != personality_) continue;
    if (name == d.name) return param(i);
    ++i;
  }
  return std::nullopt;
}

double SimAutopilot::stream_interval(uint32_t msg_id) const {
  auto it = streams_.find(msg_id);
  return it == streams_.end() ? 0.0 : it->second.interval;
}

// ---------------------------------------------------------------------------------------------
// Modes

std::string SimAutopilot::mode_name() const { return name_of(mode_); }

std::string SimAutopilot::name_of(FlightMode m) const {
  const bool px = personality_ == Personality::Px4;
  switch (m) {
    case FlightMode::Manual: return px ? "MANUAL" : "STABILIZE";
    case FlightMode::Altitude: return px ? "ALTCTL" : "ALT_HOLD";
    case FlightMode::Position: return px ? "POSCTL" : "LOITER";
    case FlightMode::Offboard: return px ? "OFFBOARD" : "GUIDED";
    case FlightMode::Takeoff: return px ? "AUTO.TAKEOFF" : "GUIDED";
    case FlightMode::Hold: return px ? "AUTO.LOITER" : "LOITER";
    case FlightMode::Land: return px ? "AUTO.LAND" : "LAND";
    case FlightMode::PrecLand: return px ? "AUTO.PRECLAND" : "LAND";
    case FlightMode::Return: return px ? "AUTO.RTL" : "RTL";
    case FlightMode::Guided: return px ? "OFFBOARD" : "GUIDED";
    case FlightMode::Brake: return px ? "AUTO.LOITER" : "BRAKE";
  }
  return "?";
}

uint32_t SimAutopilot::custom_mode() const {
  if (personality_ == Personality::Px4) {
    switch (mode_) {
      case FlightMode::Manual: return px4::custom_mode(px4::kManual, 0);
      case FlightMode::Altitude: return px4::custom_mode(px4::kAltctl, 0);
      case FlightMode::Position: return px4::custom_mode(px4::kPosctl, 0);
      case FlightMode::Offboard:
      case FlightMode::Guided: return px4::custom_mode(px4::kOffboard, 0);
      case FlightMode::Takeoff: return px4::custom_mode(px4::kAuto, px4::kAutoTakeoff);
      case FlightMode::Hold:
      case FlightMode::Brake: return px4::custom_mode(px4::kAuto, px4::kAutoLoiter);
      case FlightMode::Land: return px4::custom_mode(px4::kAuto, px4::kAutoLand);
      case FlightMode::PrecLand: return px4::custom_mode(px4::kAuto, px4::kAutoPrecland);
      case FlightMode::Return: return px4::custom_mode(px4::kAuto, px4::kAutoRtl);
    }
  } else {
    switch (mode_) {
      case FlightMode::Manual: return copter::kStabilize;
      case FlightMode::Altitude: return copter::kAltHold;
      case FlightMode::Position:
      case FlightMode::Hold: return copter::kLoiter;
      case FlightMode::Offboard:
      case FlightMode::Takeoff:
      case FlightMode::Guided: return copter::kGuided;
      case FlightMode::Land:
      case FlightMode::PrecLand: return copter::kLand;
      case FlightMode::Return: return copter::kRtl;
      case FlightMode::Brake: return copter::kBrake;
    }
  }
  return 0;
}

bool SimAutopilot::mode_needs_position(FlightMode m) const {
  switch (m) {
    case FlightMode::Position:
    case FlightMode::Offboard:
    case FlightMode::Takeoff:
    case FlightMode::Hold:
    case FlightMode::PrecLand:
    case FlightMode::Return:
    case FlightMode::Guided:
    case FlightMode::Brake: return true;
    case FlightMode::Manual:
    case FlightMode::Altitude:
    case FlightMode::Land: return false;  // LAND descends without a horizontal position
  }
  return false;
}

bool SimAutopilot::offboard_stream_ok(double t) const {
  return t - sp_last_ <= kSetpointGap_s + 1e-9 && sp_last_ - sp_run_start_ >= kOffboardWarmup_s - 1e-9;
}

std::string SimAutopilot::mode_refusal(FlightMode m, double t) const {
  const bool px = personality_ == Personality::Px4;
  const std::string name = name_of(m);
  if (px && m == FlightMode::Offboard && !offboard_stream_ok(t)) return "Switching to OFFBOARD rejected: no setpoints";
  if (mode_needs_position(m) && !xy_valid_)
    return px ? "Switching to " + name + " rejected: no valid local position"
              : "Mode change to " + name + " failed: requires position";
  return "";
}

void SimAutopilot::enter_mode(FlightMode m, double t) {
  const FlightMode before = mode_;
  mode_ = m;
  mode_since_ = t;
  descend_ = false;
  guided_stopped_ = false;
  hold_sp_ = est_;
  if (m != FlightMode::PrecLand) {
    pl_state_ = PrecLandState::Idle;
    pl_mode_ = PrecLandMode::None;
  }
  if (m == FlightMode::Guided && before != FlightMode::Guided && before != FlightMode::Takeoff) have_sp_ = false;
}

void SimAutopilot::failsafe(FlightMode fallback, double t, const std::string& text) {
  if (mode_needs_position(fallback) && !xy_valid_) fallback = FlightMode::Land;
  enter_mode(fallback, t);
  if (!xy_valid_) descend_ = true;
  statustext(mv::mav_severity::kCritical, text);
}

void SimAutopilot::disarm(double t, const std::string& why) {
  armed_ = false;
  was_airborne_ = false;
  landed_since_ = t;
  if (!why.empty()) statustext(mv::mav_severity::kInfo, why);
  if (mode_ == FlightMode::PrecLand && pl_state_ != PrecLandState::Idle) pl_state_ = PrecLandState::Done;
}

// ---------------------------------------------------------------------------------------------
// receive()

void SimAutopilot::receive(const mv::Message& msg, uint8_t sysid, uint8_t compid, double t_s) {
  if (sysid == kSystemId && compid == kComponentId) {  // our own echo
    ++ignored_;
    return;
  }
  auto for_us = [](uint8_t ts, uint8_t tc) {
    return (ts == 0 || ts == kSystemId) && (tc == 0 || tc == kComponentId);
  };
  std::visit(
      [&](const auto& m) {
        using M = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<M, mv::Heartbeat>) {
          // The companion: MAV_COMP_ID_ONBOARD_COMPUTER or MAV_TYPE_ONBOARD_CONTROLLER.
          if (compid == mv::mav_component::kOnboardComputer || m.type == mv::mav_type::kOnboardController) {
            companion_last_ = t_s;
            if (!companion_alive_) {
              companion_alive_ = true;
              statustext(mv::mav_severity::kInfo, "Onboard computer connected");
            }
          }
        } else if constexpr (std::is_same_v<M, mv::CommandLong>) {
          if (!for_us(m.target_system, m.target_component)) return void(++ignored_);
          on_command(m, sysid, compid, t_s);
        } else if constexpr (std::is_same_v<M, mv::SetPositionTargetLocalNed>) {
          if (!for_us(m.target_system, m.target_component)) return void(++ignored_);
          on_setpoint(m, t_s);
        } else if constexpr (std::is_same_v<M, mv::Odometry>) {
          // PX4 and ArduPilot take ODOMETRY in MAV_FRAME_LOCAL_FRD (20) or LOCAL_NED (1); the
          // vision frame is taken as aligned with the autopilot's local NED frame.
          if ((m.frame_id != mv::mav_frame::kLocalFrd && m.frame_id != mv::mav_frame::kLocalNed) ||
              !finite3(m.x, m.y, m.z))
            return void(++ignored_);
          on_vision({m.x, m.y, m.z}, m.reset_counter, t_s);
        } else if constexpr (std::is_same_v<M, mv::VisionPositionEstimate>) {
          if (!finite3(m.x, m.y, m.z)) return void(++ignored_);
          on_vision({m.x, m.y, m.z}, m.reset_counter, t_s);
        } else if constexpr (std::is_same_v<M, mv::LandingTarget>) {
          on_landing_target(m, t_s);
        } else if constexpr (std::is_same_v<M, mv::Timesync>) {
          // A request (tc1 == 0) is answered with tc1 = our time (ns) and its ts1.
          if (m.tc1 != 0) return;
          mv::Timesync r;
          r.tc1 = static_cast<int64_t>(std::llround(t_s * 1e9));
          r.ts1 = m.ts1;
          r.target_system = sysid;
          r.target_component = compid;
          send(r, sysid, compid);
        } else if constexpr (std::is_same_v<M, mv::ParamRequestRead>) {
          if (!for_us(m.target_system, m.target_component)) return void(++ignored_);
          on_param_request(m, sysid, compid);
        } else if constexpr (std::is_same_v<M, mv::SetGpsGlobalOrigin>) {
          if (m.target_system != 0 && m.target_system != kSystemId) return void(++ignored_);
          origin_set_ = true;
          mv::GpsGlobalOrigin o;
          o.latitude = m.latitude;
          o.longitude = m.longitude;
          o.altitude = m.altitude;
          o.time_usec = static_cast<uint64_t>(std::llround(t_s * 1e6));
          send(o);
        } else {
          ++ignored_;
        }
      },
      msg);
}

void SimAutopilot::on_param_request(const mv::ParamRequestRead& m, uint8_t sysid, uint8_t compid) {
  // param_index -1: by name (PARAM_REQUEST_READ). Unknown parameters get no answer (as both
  // firmwares do: the requester times out).
  const auto e = m.param_index >= 0 ? param(static_cast<uint16_t>(m.param_index)) : param(id_string(m.param_id));
  if (!e) return void(++ignored_);
  mv::ParamValue v;
  std::memcpy(v.param_id.data(), e->name.data(), std::min<size_t>(e->name.size(), v.param_id.size()));
  if (e->is_int) {
    v.param_type = 6;  // MAV_PARAM_TYPE_INT32
    const int32_t iv = static_cast<int32_t>(std::lround(e->value));
    if (personality_ == Personality::Px4) {
      std::memcpy(&v.param_value, &iv, sizeof iv);  // PX4: bytewise encoding
    } else {
      v.param_value = static_cast<float>(iv);  // ArduPilot: C cast
    }
  } else {
    v.param_type = 9;  // MAV_PARAM_TYPE_REAL32
    v.param_value = static_cast<float>(e->value);
  }
  v.param_count = e->count;
  v.param_index = e->index;
  send(v, sysid, compid);
}

void SimAutopilot::on_command(const mv::CommandLong& c, uint8_t sysid, uint8_t compid, double t) {
  const std::array<float, 7> params{c.param1, c.param2, c.param3, c.param4, c.param5, c.param6, c.param7};
  LastCommand& last = last_cmd_[{sysid, compid}];
  mv::CommandAck ack;
  ack.command = c.command;
  ack.target_system = sysid;
  ack.target_component = compid;
  // A retransmission (confirmation > 0) of the command just executed is acknowledged again
  // without executing it twice (MAVLink command protocol).
  if (c.confirmation > 0 && last.valid && last.command == c.command &&
      std::memcmp(last.params.data(), params.data(), sizeof params) == 0) {
    ack.result = last.result;
    send(ack, sysid, compid);
    return;
  }
  const size_t mark = outbox_.size();
  uint8_t result = mv::mav_result::kUnsupported;
  switch (c.command) {
    case mv::mav_cmd::kComponentArmDisarm: result = cmd_arm(c, t); break;
    case mv::mav_cmd::kDoSetMode: result = cmd_set_mode(c, t); break;
    case mv::mav_cmd::kNavTakeoff: result = cmd_takeoff(c, t); break;
    case mv::mav_cmd::kNavLand: result = cmd_land(c, t); break;
    case mv::mav_cmd::kSetMessageInterval: result = cmd_message_interval(c); break;
    case mv::mav_cmd::kRequestMessage:
    case mv::mav_cmd::kRequestAutopilotCapabilities: result = cmd_request_message(c, sysid, compid, t); break;
    default: result = mv::mav_result::kUnsupported; break;
  }
  if (result != mv::mav_result::kUnsupported) ++commands_executed_;
  last.valid = true;
  last.command = c.command;
  last.params = params;
  last.result = result;
  ack.result = result;
  // The ACK goes before what the command produced (the requested message), after its STATUSTEXT.
  size_t at = mark;
  while (at < outbox_.size() && std::holds_alternative<mv::Statustext>(outbox_[at].msg)) ++at;
  outbox_.insert(outbox_.begin() + static_cast<std::ptrdiff_t>(at), Outbound{ack, sysid, compid});
}

uint8_t SimAutopilot::cmd_arm(const mv::CommandLong& c, double t) {
  const bool px = personality_ == Personality::Px4;
  const bool forced = c.param2 == kForceMagic;
  const uint8_t refused = px ? mv::mav_result::kTemporarilyRejected : mv::mav_result::kFailed;
  if (c.param1 == 1.0f) {
    if (armed_) return mv::mav_result::kAccepted;
    if (!forced) {
      std::string why;
      if (px && p_.COM_RC_IN_MODE <= 3) {
        why = "Arming denied: no manual control input (COM_RC_IN_MODE " + std::to_string(p_.COM_RC_IN_MODE) + ")";
      } else if (mode_ == FlightMode::Land || mode_ == FlightMode::PrecLand || mode_ == FlightMode::Return) {
        why = px ? "Arming denied: not possible in " + mode_name() : std::string("Arm: Mode not armable");
      } else if (mode_needs_position(mode_) && !xy_valid_) {
        why = px ? "Arming denied: no valid local position, required by " + mode_name()
                 : std::string("PreArm: Need Position Estimate");
      } else if (px && mode_ == FlightMode::Offboard && !offboard_stream_ok(t)) {
        why = "Arming denied: no offboard setpoints";
      }
      if (!why.empty()) {
        statustext(mv::mav_severity::kCritical, why);
        return refused;
      }
    }
    armed_ = true;
    was_airborne_ = false;
    landed_since_ = t;
    home_ = est_;
    hold_sp_ = est_;
    statustext(mv::mav_severity::kInfo, px ? "Armed by external command" : "Arming motors");
    return mv::mav_result::kAccepted;
  }
  if (c.param1 == 0.0f) {
    if (!armed_) return mv::mav_result::kAccepted;
    if (!landed_ && !forced) {
      statustext(mv::mav_severity::kCritical,
                 px ? "Disarming denied: not landed" : "Disarm: vehicle flying (force with 21196)");
      return px ? mv::mav_result::kDenied : mv::mav_result::kFailed;
    }
    disarm(t, px ? "Disarmed by external command" : "Disarming motors");
    return mv::mav_result::kAccepted;
  }
  return mv::mav_result::kDenied;
}

uint8_t SimAutopilot::cmd_set_mode(const mv::CommandLong& c, double t) {
  const bool px = personality_ == Personality::Px4;
  const uint8_t refused = px ? mv::mav_result::kTemporarilyRejected : mv::mav_result::kFailed;
  const int64_t base_mode = int_param(c.param1, 0, 255);
  if (base_mode < 0 || (base_mode & mv::mav_mode_flag::kCustomModeEnabled) == 0) {
    statustext(mv::mav_severity::kWarning, "Mode change refused: only custom modes (param1 bit 1) are supported");
    return mv::mav_result::kDenied;
  }
  std::optional<FlightMode> m;
  PrecLandMode pl = PrecLandMode::None;
  const int a = static_cast<int>(int_param(c.param2, 0, 255));
  const int b = px ? static_cast<int>(int_param(c.param3, 0, 255)) : 0;
  if (px) {
    if (a == px4::kManual || a == px4::kStabilized) m = FlightMode::Manual;
    else if (a == px4::kAltctl) m = FlightMode::Altitude;
    else if (a == px4::kPosctl) m = FlightMode::Position;
    else if (a == px4::kOffboard) m = FlightMode::Offboard;
    else if (a == px4::kAuto) {
      if (b == px4::kAutoTakeoff) m = FlightMode::Takeoff;
      else if (b == px4::kAutoLoiter) m = FlightMode::Hold;
      else if (b == px4::kAutoRtl) m = FlightMode::Return;
      else if (b == px4::kAutoLand) m = FlightMode::Land;
      else if (b == px4::kAutoPrecland) m = FlightMode::PrecLand, pl = PrecLandMode::Required;
    }
  } else {
    if (a == copter::kStabilize) m = FlightMode::Manual;
    else if (a == copter::kAltHold) m = FlightMode::Altitude;
    else if (a == copter::kGuided) m = FlightMode::Guided;
    else if (a == copter::kLoiter) m = FlightMode::Hold;
    else if (a == copter::kRtl) m = FlightMode::Return;
    else if (a == copter::kLand) m = FlightMode::Land;
    else if (a == copter::kBrake) m = FlightMode::Brake;
  }
  if (!m) {
    std::ostringstream o;
    o << "Unsupported mode " << a;
    if (px) o << "/" << b;
    statustext(mv::mav_severity::kWarning, o.str());
    return px ? mv::mav_result::kDenied : mv::mav_result::kFailed;
  }
  if (*m == mode_) return mv::mav_result::kAccepted;
  const std::string why = mode_refusal(*m, t);
  if (!why.empty()) {
    statustext(mv::mav_severity::kCritical, why);
    return refused;
  }
  if (*m == FlightMode::PrecLand) {
    start_precland(pl, t);
  } else {
    enter_mode(*m, t);
    if (*m == FlightMode::Takeoff) takeoff_z_ = home_.z() + p_.MIS_TAKEOFF_ALT;
  }
  return mv::mav_result::kAccepted;
}

uint8_t SimAutopilot::cmd_takeoff(const mv::CommandLong& c, double t) {
  const bool px = personality_ == Personality::Px4;
  const uint8_t refused = px ? mv::mav_result::kTemporarilyRejected : mv::mav_result::kFailed;
  if (!armed_) {
    statustext(mv::mav_severity::kCritical, px ? "Takeoff denied: disarmed" : "Takeoff: not armed");
    return refused;
  }
  if (!px && mode_ != FlightMode::Guided) {
    statustext(mv::mav_severity::kCritical, "Takeoff: mode is not GUIDED");
    return refused;
  }
  const std::string why = mode_refusal(FlightMode::Takeoff, t);
  if (!why.empty()) {
    statustext(mv::mav_severity::kCritical, why);
    return refused;
  }
  double alt = 0;
  if (px) {
    // param7 is AMSL in PX4; home is at 0 m AMSL here. NaN: MIS_TAKEOFF_ALT above home.
    alt = std::isfinite(c.param7) && c.param7 > 0 ? c.param7 : p_.MIS_TAKEOFF_ALT;
  } else {
    // ArduCopter: param7 = altitude above home (m); 0: PILOT_TKOFF_ALT (this model's default).
    alt = std::isfinite(c.param7) && c.param7 > 0 ? c.param7 : p_.PILOT_TKOFF_ALT / 100.0;
    if (alt <= 0) {
      statustext(mv::mav_severity::kCritical, "Takeoff: altitude must be > 0");
      return mv::mav_result::kDenied;
    }
  }
  enter_mode(FlightMode::Takeoff, t);
  takeoff_z_ = home_.z() + alt;
  return mv::mav_result::kAccepted;
}

uint8_t SimAutopilot::cmd_land(const mv::CommandLong& c, double t) {
  if (personality_ == Personality::Px4) {
    const int pl = std::isnan(c.param2) ? 0 : static_cast<int>(int_param(c.param2, 0, 255));
    if (pl == 1 || pl == 2) {
      const std::string why = mode_refusal(FlightMode::PrecLand, t);
      if (!why.empty()) {
        statustext(mv::mav_severity::kCritical, why);
        return mv::mav_result::kTemporarilyRejected;
      }
      start_precland(static_cast<PrecLandMode>(pl), t);
      return mv::mav_result::kAccepted;
    }
    if (pl != 0) {
      statustext(mv::mav_severity::kWarning, "Land: precision land mode must be 0, 1 or 2");
      return mv::mav_result::kDenied;
    }
  }
  if (mode_ != FlightMode::Land) enter_mode(FlightMode::Land, t);
  if (!xy_valid_) descend_ = true;
  return mv::mav_result::kAccepted;
}

uint8_t SimAutopilot::cmd_message_interval(const mv::CommandLong& c) {
  if (int_param(c.param1, 0, 0xFFFFFF) < 0 || !std::isfinite(c.param2)) return mv::mav_result::kDenied;
  const auto id = static_cast<uint32_t>(int_param(c.param1, 0, 0xFFFFFF));
  auto it = streams_.find(id);
  if (it == streams_.end()) {
    statustext(mv::mav_severity::kWarning, "SET_MESSAGE_INTERVAL: message " + std::to_string(id) + " not streamed");
    return mv::mav_result::kDenied;
  }
  Stream& s = it->second;
  // param2: interval in us; -1 = off; 0 = default.
  if (c.param2 < 0) s.interval = 0;
  else if (c.param2 == 0) s.interval = s.default_interval;
  else s.interval = c.param2 * 1e-6;
  s.next = t_;
  return mv::mav_result::kAccepted;
}

uint8_t SimAutopilot::cmd_request_message(const mv::CommandLong& c, uint8_t sysid, uint8_t compid, double t) {
  const uint32_t id = c.command == mv::mav_cmd::kRequestAutopilotCapabilities
                          ? mv::AutopilotVersion::kId
                          : static_cast<uint32_t>(int_param(c.param1, 0, 0xFFFFFF));  // -1 -> no such id
  if (id == mv::AutopilotVersion::kId) {
    send(autopilot_version(), sysid, compid);
    return mv::mav_result::kAccepted;
  }
  if (streams_.count(id)) {
    send(make(id, t, truth_), sysid, compid);
    return mv::mav_result::kAccepted;
  }
  statustext(mv::mav_severity::kWarning, "REQUEST_MESSAGE: message " + std::to_string(id) + " not available");
  return mv::mav_result::kDenied;
}

void SimAutopilot::on_setpoint(const mv::SetPositionTargetLocalNed& m, double t) {
  namespace tm = mv::type_mask;
  const bool px = personality_ == Personality::Px4;
  const uint16_t mask = m.type_mask;
  // Velocity control only: position and acceleration ignored, velocity used (PX4 also accepts
  // position/acceleration setpoints, which this model does not fly: they are refused). ArduCopter
  // documents 0x0DC7 (velocity) and 0x05C7 (velocity + yaw rate).
  const bool velocity_only = (mask & tm::kPositionIgnore) == tm::kPositionIgnore &&
                             (mask & tm::kAccelerationIgnore) == tm::kAccelerationIgnore &&
                             (mask & (tm::kVxIgnore | tm::kVyIgnore | tm::kVzIgnore)) == 0;
  const bool frame_ok = m.coordinate_frame == mv::mav_frame::kLocalNed || m.coordinate_frame == mv::mav_frame::kBodyNed;
  bool ok = velocity_only && frame_ok && finite3(m.vx, m.vy, m.vz);
  if (!px) ok = ok && (mask == 0x0DC7 || mask == 0x05C7) && (mode_ == FlightMode::Guided);
  if (!ok) return void(++setpoints_refused_);
  Setpoint sp;
  const Eigen::Vector3d v(m.vx, m.vy, m.vz);
  // Frame 8 is rotated by the current heading when received (as both firmwares do).
  const Eigen::Vector3d v_h = m.coordinate_frame == mv::mav_frame::kBodyNed ? body_ned_to_heading(v)
                                                                           : ned_to_heading(v, truth_.yaw);
  const double c = std::cos(truth_.yaw), s = std::sin(truth_.yaw);
  sp.v_world = {c * v_h.x() - s * v_h.y(), s * v_h.x() + c * v_h.y(), v_h.z()};
  if ((mask & tm::kYawRateIgnore) == 0 && std::isfinite(m.yaw_rate)) {
    sp.yaw_rate_cw = m.yaw_rate;  // NED yaw rate: positive = clockwise seen from above
  } else if (px && (mask & tm::kYawIgnore) == 0 && std::isfinite(m.yaw)) {
    sp.has_yaw = true;
    sp.yaw_ned = m.yaw;
  }
  if (t - sp_last_ > kSetpointGap_s) sp_run_start_ = t;
  sp_last_ = t;
  sp_ = sp;
  have_sp_ = true;
  guided_stopped_ = false;
}

bool SimAutopilot::fusion_configured() const {
  if (personality_ == Personality::Px4) return (p_.EKF2_EV_CTRL & 1) != 0;
  return p_.VISO_TYPE > 0 && p_.EK3_SRC1_POSXY == 6;
}

bool SimAutopilot::flow_configured() const {
  if (personality_ == Personality::Px4) return p_.EKF2_OF_CTRL == 1;
  return p_.EK3_SRC1_VELXY == 5;
}

bool SimAutopilot::on_flow(double t) const {
  const bool vision_fresh = have_vision_ && t - vision_last_ <= kVisionTimeout_s + 1e-9;
  return flow_configured() && !(fusion_configured() && vision_fresh);
}

bool SimAutopilot::vertical_from_vision() const {
  if (personality_ == Personality::Px4) return (p_.EKF2_EV_CTRL & 2) != 0 && p_.EKF2_HGT_REF == 3;
  return p_.VISO_TYPE > 0 && p_.EK3_SRC1_POSZ == 6;
}

void SimAutopilot::on_vision(const Eigen::Vector3d& p_ned, uint8_t reset_counter, double t) {
  const bool px = personality_ == Personality::Px4;
  if (!fusion_configured() && !vertical_from_vision()) return void(++ignored_);
  // ArduPilot's EKF3 does not use ExternalNav before it has an origin (SET_GPS_GLOBAL_ORIGIN).
  if (!px && !origin_set_) return void(++ignored_);
  const double delay_s = px ? p_.EKF2_EV_DELAY * 1e-3 : p_.VISO_DELAY_MS * 1e-3;
  // A new reset_counter = the vision re-anchored: the estimator resets to it (EKF2 ev reset).
  const bool reset = have_reset_counter_ && reset_counter != reset_counter_;
  have_reset_counter_ = true;
  reset_counter_ = reset_counter;
  vision_pending_.push_back({t - delay_s, ned_to_enu(p_ned), reset});
  if (vision_pending_.size() > 1000) vision_pending_.pop_front();
  vision_last_ = t;
}

void SimAutopilot::on_landing_target(const mv::LandingTarget& m, double t) {
  if (personality_ == Personality::Px4) {
    // PX4 mavlink_receiver: position_valid and MAV_FRAME_LOCAL_NED x/y/z (absolute, local frame).
    if (m.position_valid != 1 || m.frame != mv::mav_frame::kLocalNed || !finite3(m.x, m.y, m.z))
      return void(++ignored_);
    target_ = ned_to_enu({m.x, m.y, m.z});
  } else {
    // ArduPilot AC_PrecLand_MAVLink (PLND_TYPE 1): MAV_FRAME_BODY_FRD; x/y/z when
    // position_valid = 1, else the angles (tan angle_x forward, tan angle_y right per metre
    // down) scaled by `distance` or the range finder's height.
    if (p_.PLND_ENABLED != 1 || p_.PLND_TYPE != 1 || m.frame != mv::mav_frame::kBodyFrd) return void(++ignored_);
    const Eigen::Matrix3d R = ned_from_frd(truth_.roll, truth_.pitch, truth_.yaw);
    Eigen::Vector3d rel_ned;
    if (m.position_valid == 1) {
      if (!finite3(m.x, m.y, m.z)) return void(++ignored_);
      rel_ned = R * Eigen::Vector3d(m.x, m.y, m.z);
    } else {
      if (!finite3(m.angle_x, m.angle_y, 0.0f) || std::abs(m.angle_x) >= 1.5f || std::abs(m.angle_y) >= 1.5f)
        return void(++ignored_);
      const Eigen::Vector3d los = R * Eigen::Vector3d(std::tan(m.angle_x), std::tan(m.angle_y), 1.0);
      if (std::isfinite(m.distance) && m.distance > 0) {
        rel_ned = los.normalized() * m.distance;
      } else {
        const double h = truth_.position.z() - ground_z_;
        if (!(los.z() > 1e-3) || h <= 0.05) return void(++ignored_);
        rel_ned = los * (h / los.z());
      }
    }
    target_ = est_ + ned_to_enu(rel_ned);
  }
  have_target_ = true;
  target_last_ = t;
}

// ---------------------------------------------------------------------------------------------
// Estimator: the position estimate is the truth plus an error state; each vision sample pulls
// the error towards its innovation (vision - (truth at the measurement time + error)) with weight
// kVisionWeight, so a biased vision moves the estimate (and the held vehicle) by the bias. The
// measurement time is the arrival time minus EKF2_EV_DELAY / VISO_DELAY_MS. Between samples a
// clean IMU carries the error unchanged (no drift modelled).

Eigen::Vector3d SimAutopilot::truth_at(double t) const {
  if (truth_hist_.empty()) return truth_.position;
  if (t <= truth_hist_.front().first) return truth_hist_.front().second;
  for (size_t i = 1; i < truth_hist_.size(); ++i) {
    if (truth_hist_[i].first >= t) {
      const auto& [t0, p0] = truth_hist_[i - 1];
      const auto& [t1, p1] = truth_hist_[i];
      const double w = t1 > t0 ? (t - t0) / (t1 - t0) : 1.0;
      return p0 + w * (p1 - p0);
    }
  }
  return truth_hist_.back().second;
}

void SimAutopilot::estimator_step(double t, const MultirotorState& truth) {
  truth_hist_.emplace_back(t, truth.position);
  while (truth_hist_.size() > 2 && truth_hist_.front().first < t - 2.0) truth_hist_.pop_front();
  const bool fuse_xy = fusion_configured();
  const bool fuse_z = vertical_from_vision();
  while (!vision_pending_.empty() && vision_pending_.front().t_meas <= t + 1e-9) {
    const VisionSample v = vision_pending_.front();
    vision_pending_.pop_front();
    const Eigen::Vector3d tm = truth_at(v.t_meas);
    const Eigen::Vector3d innovation = v.p - (tm + est_err_);
    // First sample, first after a timeout, or a reset_counter change: the EKF resets to the vision position.
    const double w = (have_vision_ && xy_valid_ && !v.reset) ? kVisionWeight : 1.0;
    if (v.reset) ++vision_resets_;
    if (fuse_xy) est_err_.head<2>() += w * innovation.head<2>();
    if (fuse_z) est_err_.z() += w * innovation.z();
    have_vision_ = true;
  }
  const bool vision_fresh = have_vision_ && t - vision_last_ <= kVisionTimeout_s + 1e-9;
  const bool flow = on_flow(t);
  if (flow) {  // optical flow integrates velocity: the position error walks
    if (flow_t_ >= 0 && t > flow_t_) {
      std::normal_distribution<double> n01(0.0, 1.0);
      const double step = p_.flow_drift_m_per_sqrt_s * std::sqrt(t - flow_t_);
      est_err_.x() += step * n01(flow_rng_);
      est_err_.y() += step * n01(flow_rng_);
    }
    flow_t_ = t;
  } else if (!fuse_xy) {
    est_err_.head<2>().setZero();
  }
  if (!fuse_z) est_err_.z() = 0;  // baro / range finder height: clean
  const bool xy_valid = (fuse_xy && vision_fresh) || flow;
  z_valid_ = !fuse_z || vision_fresh;
  est_ = truth.position + est_err_;
  const bool px = personality_ == Personality::Px4;
  if (xy_valid_ && !xy_valid) {
    statustext(mv::mav_severity::kCritical,
               px ? "Vision data stopped: local position estimate invalid" : "EKF3 IMU0 stopped aiding");
  } else if (!xy_valid_ && xy_valid && !px) {
    statustext(mv::mav_severity::kInfo, "EKF3 IMU0 is using external nav data");
  }
  xy_valid_ = xy_valid;
}

// ---------------------------------------------------------------------------------------------
// Precision landing: PX4 navigator PrecLand (precland.cpp) states and transitions.

bool SimAutopilot::target_valid(double t) const {
  const double timeout = personality_ == Personality::Px4 ? p_.PLD_BTOUT : kArduTargetTimeout_s;
  return have_target_ && t - target_last_ <= timeout + 1e-9;
}

void SimAutopilot::start_precland(PrecLandMode mode, double t) {
  enter_mode(FlightMode::PrecLand, t);
  pl_mode_ = mode;
  pl_search_count_ = 0;
  pl_hold_ = est_;
  pl_switch(PrecLandState::Start, t);
  precland_step(t);
}

void SimAutopilot::pl_switch(PrecLandState s, double t) {
  pl_state_ = s;
  pl_state_since_ = t;
  switch (s) {
    case PrecLandState::HorizontalApproach: pl_hold_ = est_; break;  // keeps the altitude
    case PrecLandState::FinalApproach:
      pl_hold_ = est_;
      if (target_valid(t)) pl_hold_.head<2>() = target_.head<2>();
      statustext(mv::mav_severity::kInfo, "Final approach");
      break;
    case PrecLandState::Search:
      pl_hold_ = est_;
      ++pl_search_count_;
      statustext(mv::mav_severity::kInfo, "Climbing to search altitude.");
      break;
    case PrecLandState::Fallback:
      pl_hold_ = est_;
      statustext(mv::mav_severity::kWarning, "Falling back to normal land.");
      break;
    default: break;
  }
}

void SimAutopilot::precland_step(double t) {
  for (int iteration = 0; iteration < 4; ++iteration) {
    const PrecLandState before = pl_state_;
    const bool valid = target_valid(t);
    const double target_z = have_target_ ? target_.z() : home_.z();
    const double height = est_.z() - target_z;
    switch (pl_state_) {
      case PrecLandState::Start:
        if (valid) pl_switch(PrecLandState::HorizontalApproach, t);
        else if (pl_mode_ == PrecLandMode::Opportunistic) pl_switch(PrecLandState::Fallback, t);
        else if (pl_search_count_ >= p_.PLD_MAX_SRCH) {
          statustext(mv::mav_severity::kWarning, "Maximum search attempts reached (PLD_MAX_SRCH).");
          pl_switch(PrecLandState::Fallback, t);
        } else pl_switch(PrecLandState::Search, t);
        break;
      case PrecLandState::HorizontalApproach:
        if (!valid) {
          statustext(mv::mav_severity::kWarning, "Lost landing target while landing (horizontal approach).");
          pl_switch(PrecLandState::Start, t);
        } else if ((est_.head<2>() - target_.head<2>()).norm() < p_.PLD_HACC_RAD) {
          pl_switch(PrecLandState::DescendAboveTarget, t);
        } else if (t - pl_state_since_ > kPrecLandStateTimeout_s) {
          statustext(mv::mav_severity::kCritical, "Precision landing took too long during horizontal approach phase.");
          pl_switch(PrecLandState::Fallback, t);
        }
        break;
      case PrecLandState::DescendAboveTarget:
        if (height < p_.PLD_FAPPR_ALT) pl_switch(PrecLandState::FinalApproach, t);
        else if (!valid) {
          statustext(mv::mav_severity::kWarning, "Lost landing target while landing (descending).");
          pl_switch(PrecLandState::Start, t);
        }
        break;
      case PrecLandState::Search:
        if (valid && target_last_ >= pl_state_since_) pl_switch(PrecLandState::HorizontalApproach, t);
        else if (t - pl_state_since_ > p_.PLD_SRCH_TOUT + 1e-9) {
          statustext(mv::mav_severity::kWarning, "Search timed out.");
          pl_switch(PrecLandState::Fallback, t);
        }
        break;
      case PrecLandState::FinalApproach:
      case PrecLandState::Fallback:
        if (landed_ && was_airborne_) pl_switch(PrecLandState::Done, t);
        break;
      case PrecLandState::Idle:
      case PrecLandState::Done: break;
    }
    if (pl_state_ == before) break;
  }
}

// ---------------------------------------------------------------------------------------------
// step()

StepOutput SimAutopilot::step(double t, const MultirotorState& truth) {
  if (stepped_ && t < t_ - 1e-12)
    throw std::invalid_argument("SimAutopilot::step: time went back (" + std::to_string(t) + " < " +
                                std::to_string(t_) + ")");
  const double dt = stepped_ ? t - t_ : 0.0;
  if (!stepped_) {
    ground_z_ = truth.position.z();
    home_ = truth.position;
    for (auto& [id, s] : streams_) s.next = t;
    prev_roll_ = truth.roll;
    prev_pitch_ = truth.pitch;
  }
  if (dt > 0) {
    roll_rate_ = (truth.roll - prev_roll_) / dt;
    pitch_rate_ = (truth.pitch - prev_pitch_) / dt;
  }
  prev_roll_ = truth.roll;
  prev_pitch_ = truth.pitch;
  stepped_ = true;
  t_ = t;
  truth_ = truth;
  const bool px = personality_ == Personality::Px4;

  estimator_step(t, truth);

  // Land detector (ground contact without vertical motion for kLandDetect_s).
  if (!truth.on_ground || std::abs(truth.velocity.z()) > 0.1) {
    if (landed_ && armed_) was_airborne_ = true;
    landed_ = false;
    ground_contact_since_ = -1;
  } else if (!landed_) {
    if (ground_contact_since_ < 0) ground_contact_since_ = t;
    if (t - ground_contact_since_ >= kLandDetect_s - 1e-9) {
      landed_ = true;
      landed_since_ = t;
      if (armed_) statustext(mv::mav_severity::kInfo, "Landing detected");
    }
  }
  if (!landed_ && armed_) was_airborne_ = true;

  // Companion link (COM_OBC_LOSS_T).
  if (companion_alive_ && t - companion_last_ > p_.COM_OBC_LOSS_T) {
    companion_alive_ = false;
    statustext(mv::mav_severity::kCritical, "Onboard computer lost");
  }

  // Battery: a constant current per state.
  consumed_mah_ += (armed_ ? p_.battery_flight_current_a : p_.battery_idle_current_a) * dt / 3.6;

  if (armed_) {
    // Local position lost in a mode that needs it: PX4 descends (no RC to fall back to;
    // COM_POSCTL_NAVL), ArduCopter's EKF failsafe (FS_EKF_ACTION) lands.
    const bool uses_xy = mode_needs_position(mode_) || (mode_ == FlightMode::Land && !descend_);
    if (!xy_valid_ && uses_xy && !landed_) {
      if (mode_ == FlightMode::Land) {
        descend_ = true;
        statustext(mv::mav_severity::kCritical, px ? "Failsafe: no local position, descending"
                                                   : "EKF Failsafe: no position, landing without it");
      } else {
        failsafe(FlightMode::Land, t,
                 px ? "Failsafe: no local position, switching to Descend" : "EKF Failsafe: changed to LAND mode");
      }
    }
    // PX4 offboard loss: COM_OF_LOSS_T without a setpoint, then COM_OBL_RC_ACT.
    if (px && mode_ == FlightMode::Offboard && t - sp_last_ > p_.COM_OF_LOSS_T + 1e-9) {
      static const FlightMode kActions[] = {FlightMode::Position, FlightMode::Altitude, FlightMode::Manual,
                                            FlightMode::Return,   FlightMode::Land,     FlightMode::Hold};
      const FlightMode action = kActions[p_.COM_OBL_RC_ACT];
      failsafe(action, t, "Failsafe: offboard control lost, switching to " + name_of(action));
    }
    // ArduCopter GUIDED: GUID_TIMEOUT without a velocity setpoint, then it stops (holds).
    if (!px && mode_ == FlightMode::Guided && have_sp_ && !guided_stopped_ && t - sp_last_ > p_.GUID_TIMEOUT + 1e-9)
      guided_stopped_ = true;
    // ArduCopter LAND: a precision-landing target dropped -> hold where the vehicle is.
    const bool tracking = !px && mode_ == FlightMode::Land && p_.PLND_ENABLED == 1 && p_.PLND_TYPE == 1 &&
                          target_valid(t);
    if (tracking_target_ && !tracking) hold_sp_ = est_;
    tracking_target_ = tracking;
    if (mode_ == FlightMode::Takeoff && est_.z() >= takeoff_z_ - kTakeoffAcceptance_m) {
      enter_mode(px ? FlightMode::Hold : FlightMode::Guided, t);
      hold_sp_.z() = takeoff_z_;
      have_sp_ = false;
      if (px) statustext(mv::mav_severity::kInfo, "Takeoff complete");
    }
    if (mode_ == FlightMode::Return && (est_.head<2>() - home_.head<2>()).norm() < kReturnAcceptance_m)
      enter_mode(FlightMode::Land, t);
    if (mode_ == FlightMode::PrecLand) precland_step(t);
    // Auto-disarm after landing: PX4 COM_DISARM_LAND; ArduCopter LAND disarms on land complete.
    if (landed_ && was_airborne_) {
      if (px && p_.COM_DISARM_LAND >= 0 && t - landed_since_ >= p_.COM_DISARM_LAND - 1e-9) {
        disarm(t, "Disarmed by landing");
      } else if (!px && (mode_ == FlightMode::Land || mode_ == FlightMode::PrecLand)) {
        disarm(t, "Disarming motors");
      }
    }
  }

  StepOutput out;
  out.command = guidance(t, truth);

  for (auto& [id, s] : streams_) {
    if (s.interval <= 0 || t + 1e-9 < s.next) continue;
    if (id == mv::LocalPositionNed::kId && !xy_valid_) {  // only a valid local position is reported
      s.next = t + s.interval;
      continue;
    }
    send(make(id, t, truth));
    s.next += s.interval;
    if (s.next <= t + 1e-9) s.next = t + s.interval;
  }
  out.messages = std::move(outbox_);
  outbox_.clear();
  return out;
}

Eigen::Vector3d SimAutopilot::hold_velocity(const Eigen::Vector3d& sp, bool hold_z) const {
  const bool px = personality_ == Personality::Px4;
  const double kxy = px ? p_.MPC_XY_P : p_.PSC_POSXY_P;
  const double kz = px ? p_.MPC_Z_P : p_.PSC_POSZ_P;
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  if (xy_valid_) v.head<2>() = kxy * (sp.head<2>() - est_.head<2>());
  if (hold_z && z_valid_) v.z() = kz * (sp.z() - est_.z());
  return v;
}

AutopilotCommand SimAutopilot::guidance(double t, const MultirotorState& truth) {
  AutopilotCommand cmd;
  const bool px = personality_ == Personality::Px4;
  if (!armed_) {
    // Disarmed: the motors stop. The Multirotor has no motor cut-off: LAND stops them on the
    // ground (it disarms on contact), and models a forced disarm in the air as a land.
    cmd.mode = truth.armed ? AutopilotCommand::Mode::Land : AutopilotCommand::Mode::Hover;
    return cmd;
  }
  const double land_speed = px ? p_.MPC_LAND_SPEED : p_.LAND_SPEED / 100.0;
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  double yaw_rate_cw = 0;
  bool landing = false;  // descending to touch down
  auto descend_at = [&](const Eigen::Vector3d& xy_sp) {
    v = descend_ ? Eigen::Vector3d::Zero() : hold_velocity(xy_sp, false);
    v.z() = -land_speed;
    landing = true;
  };
  switch (mode_) {
    case FlightMode::Manual:
    case FlightMode::Altitude: break;  // no RC: sticks centred
    case FlightMode::Position:
    case FlightMode::Hold:
    case FlightMode::Brake: v = hold_velocity(hold_sp_, true); break;
    case FlightMode::Offboard:
    case FlightMode::Guided:
      if (mode_ == FlightMode::Guided && (guided_stopped_ || landed_)) {
        // GUID_TIMEOUT: the vehicle stops (zero velocity); on the ground ArduCopter flies no
        // GUIDED velocities (NAV_TAKEOFF first).
        v.setZero();
      } else if (have_sp_ && (mode_ == FlightMode::Offboard || t - sp_last_ <= p_.GUID_TIMEOUT + 1e-9)) {
        v = sp_.v_world;
        yaw_rate_cw = sp_.yaw_rate_cw;
        if (sp_.has_yaw) {
          const double yaw_ned = std::remainder(kPi / 2 - truth.yaw, 2 * kPi);
          yaw_rate_cw = std::remainder(sp_.yaw_ned - yaw_ned, 2 * kPi);
        }
      } else {
        v = hold_velocity(hold_sp_, true);
      }
      break;
    case FlightMode::Takeoff: {
      const double climb = px ? p_.MPC_TKO_SPEED : p_.WPNAV_SPEED_UP / 100.0;
      v = hold_velocity(hold_sp_, false);
      const double kz = px ? p_.MPC_Z_P : p_.PSC_POSZ_P;
      v.z() = std::clamp(kz * (takeoff_z_ - est_.z()), -climb, climb);
      break;
    }
    case FlightMode::Land:
      if (!px && p_.PLND_ENABLED == 1 && p_.PLND_TYPE == 1 && target_valid(t)) {
        descend_at(target_);  // ArduCopter LAND with precision landing: track the target
      } else {
        descend_at(hold_sp_);
      }
      break;
    case FlightMode::Return: {
      Eigen::Vector3d sp = home_;
      sp.z() = hold_sp_.z();
      v = hold_velocity(sp, true);
      break;
    }
    case FlightMode::PrecLand:
      switch (pl_state_) {
        case PrecLandState::HorizontalApproach: {
          Eigen::Vector3d sp = target_;
          sp.z() = pl_hold_.z();
          v = hold_velocity(sp, true);
          break;
        }
        case PrecLandState::DescendAboveTarget: descend_at(target_); break;
        case PrecLandState::Search: {
          Eigen::Vector3d sp = pl_hold_;
          sp.z() = home_.z() + p_.PLD_SRCH_ALT;
          v = hold_velocity(sp, true);
          break;
        }
        case PrecLandState::FinalApproach:
        case PrecLandState::Fallback:
        case PrecLandState::Done:
        case PrecLandState::Start:
        case PrecLandState::Idle: descend_at(pl_hold_); break;
      }
      break;
  }
  // With no vision fused, the estimate is the vehicle's own odometry (optical flow), which the
  // Multirotor models in its own position hold, at the physics rate and without the companion's
  // command latency (multirotor.hpp): the autopilot's holds and its plain landing fly there
  // rather than through a second, slower loop of this model's.
  if (on_flow(t) && truth.armed) {
    if (mode_ == FlightMode::Land && !tracking_target_) {
      cmd.mode = AutopilotCommand::Mode::Land;
      return cmd;
    }
    if (mode_ == FlightMode::Position || mode_ == FlightMode::Hold || mode_ == FlightMode::Brake) {
      cmd.mode = AutopilotCommand::Mode::Hover;
      return cmd;
    }
  }
  if (landing && landed_) {  // touched down: motors to idle (the Multirotor disarms on contact in LAND)
    cmd.mode = AutopilotCommand::Mode::Land;
    return cmd;
  }
  if (!truth.armed) {  // motors not running: spin up only to climb
    cmd.mode = v.z() > 0.05 ? AutopilotCommand::Mode::Takeoff : AutopilotCommand::Mode::Hover;
    return cmd;
  }
  // World ENU -> heading frame (x forward, y left, z up).
  const double c = std::cos(truth.yaw), s = std::sin(truth.yaw);
  cmd.mode = AutopilotCommand::Mode::Velocity;
  cmd.velocity = {c * v.x() + s * v.y(), -s * v.x() + c * v.y(), v.z()};
  cmd.yaw_rate_deg_s = yaw_rate_cw * 180.0 / kPi;
  return cmd;
}

// ---------------------------------------------------------------------------------------------
// Telemetry

void SimAutopilot::statustext(uint8_t severity, const std::string& text) {
  texts_.push_back(text);
  constexpr size_t kChunk = 50;
  if (text.size() <= kChunk) {
    mv::Statustext m;
    m.severity = severity;
    set_text(m.text, text);
    send(m);
    return;
  }
  // Longer texts go in chunks (MAVLink 2 STATUSTEXT id / chunk_seq): one non-zero id, chunk_seq
  // from 0; a NUL in a chunk ends the text (an empty last chunk when the length is a multiple of 50).
  if (++statustext_id_ == 0) statustext_id_ = 1;
  for (size_t at = 0, seq = 0; at <= text.size(); at += kChunk, ++seq) {
    if (at == text.size() && text.size() % kChunk != 0) break;
    mv::Statustext m;
    m.severity = severity;
    set_text(m.text, std::string_view(text).substr(at, kChunk));
    m.id = statustext_id_;
    m.chunk_seq = static_cast<uint8_t>(seq);
    send(m);
  }
}

mv::Message SimAutopilot::heartbeat() const {
  namespace f = mv::mav_mode_flag;
  mv::Heartbeat h;
  h.type = mv::mav_type::kQuadrotor;
  h.autopilot = personality_ == Personality::Px4 ? mv::mav_autopilot::kPx4 : mv::mav_autopilot::kArdupilotmega;
  uint8_t base = f::kCustomModeEnabled | f::kStabilizeEnabled;
  switch (mode_) {
    case FlightMode::Manual:
    case FlightMode::Altitude: base |= f::kManualInputEnabled; break;
    case FlightMode::Position: base |= f::kManualInputEnabled | f::kGuidedEnabled; break;
    case FlightMode::Offboard:
    case FlightMode::Guided: base |= f::kGuidedEnabled; break;
    default: base |= f::kAutoEnabled | f::kGuidedEnabled; break;
  }
  if (armed_) base |= f::kSafetyArmed;
  h.base_mode = base;
  h.custom_mode = custom_mode();
  h.system_status = descend_ ? mv::mav_state::kCritical : armed_ ? mv::mav_state::kActive : mv::mav_state::kStandby;
  h.mavlink_version = 3;
  return h;
}

mv::Message SimAutopilot::autopilot_version() const {
  mv::AutopilotVersion v;
  const bool px = personality_ == Personality::Px4;
  // MAV_PROTOCOL_CAPABILITY: SET_POSITION_TARGET_LOCAL_NED 128, MAVLINK2 8192,
  // PARAM_ENCODE_BYTEWISE 16 (PX4) / PARAM_ENCODE_C_CAST 131072 (ArduPilot). Not COMMAND_INT
  // (both firmwares have it; this model answers COMMAND_LONG only).
  v.capabilities = 128u | 8192u | (px ? 16u : 131072u);
  // major << 24 | minor << 16 | patch << 8 | FIRMWARE_VERSION_TYPE_OFFICIAL (255)
  v.flight_sw_version = px ? ((1u << 24) | (14u << 16) | 255u) : ((4u << 24) | (5u << 16) | 255u);
  v.vendor_id = 0;
  v.product_id = 0;
  v.uid = 0xAE1E000000000001ull;
  return v;
}

mv::Message SimAutopilot::make(uint32_t id, double t, const MultirotorState& truth) {
  const auto boot_ms = static_cast<uint32_t>(std::llround(t * 1e3));
  const auto usec = static_cast<uint64_t>(std::llround(t * 1e6));
  const Eigen::Matrix3d R = ned_from_frd(truth.roll, truth.pitch, truth.yaw);
  // Body rates FRD (small-angle: Euler rates ~ body rates): FLU (roll', pitch', yaw') -> (p, -q, -r).
  const Eigen::Vector3d rates(roll_rate_, -pitch_rate_, -truth.yaw_rate);
  const double soc = std::clamp(1.0 - consumed_mah_ / p_.battery_capacity_mah, 0.0, 1.0);
  const double volts = p_.battery_cells * (3.5 + 0.7 * soc);
  const double amps = armed_ ? p_.battery_flight_current_a : p_.battery_idle_current_a;
  switch (id) {
    case mv::Heartbeat::kId: return heartbeat();
    case mv::HighresImu::kId: {
      // Specific force in FRD: R^T (a - g) with NED gravity (0, 0, g): at rest z reads -g.
      const Eigen::Vector3d a_ned = enu_to_ned(truth.acceleration) - Eigen::Vector3d(0, 0, kG);
      Eigen::Vector3d f = R.transpose() * a_ned;
      Eigen::Vector3d w = rates;
      if (p_.imu_accel_noise_m_s2 > 0 || p_.imu_gyro_noise_rad_s > 0) {
        std::normal_distribution<double> n01(0.0, 1.0);
        for (int i = 0; i < 3; ++i) f[i] += p_.imu_accel_noise_m_s2 * n01(rng_);
        for (int i = 0; i < 3; ++i) w[i] += p_.imu_gyro_noise_rad_s * n01(rng_);
      }
      const Eigen::Vector3d mag = R.transpose() * Eigen::Vector3d(0.21, 0.0, 0.43);  // gauss, NED
      mv::HighresImu m;
      m.time_usec = usec;
      m.xacc = static_cast<float>(f.x());
      m.yacc = static_cast<float>(f.y());
      m.zacc = static_cast<float>(f.z());
      m.xgyro = static_cast<float>(w.x());
      m.ygyro = static_cast<float>(w.y());
      m.zgyro = static_cast<float>(w.z());
      m.xmag = static_cast<float>(mag.x());
      m.ymag = static_cast<float>(mag.y());
      m.zmag = static_cast<float>(mag.z());
      const double alt = truth.position.z();  // home at 0 m AMSL
      m.abs_pressure = static_cast<float>(1013.25 * std::pow(1.0 - 2.25577e-5 * alt, 5.25588));  // ISA, hPa
      m.pressure_alt = static_cast<float>(alt);
      m.temperature = 25.0f;
      m.fields_updated = 0x1FFF;
      return m;
    }
    case mv::AttitudeQuaternion::kId: {
      const Eigen::Quaterniond q(R);  // FRD body -> NED
      mv::AttitudeQuaternion m;
      m.time_boot_ms = boot_ms;
      m.q1 = static_cast<float>(q.w());
      m.q2 = static_cast<float>(q.x());
      m.q3 = static_cast<float>(q.y());
      m.q4 = static_cast<float>(q.z());
      m.rollspeed = static_cast<float>(rates.x());
      m.pitchspeed = static_cast<float>(rates.y());
      m.yawspeed = static_cast<float>(rates.z());
      return m;
    }
    case mv::LocalPositionNed::kId: {
      const Eigen::Vector3d p = enu_to_ned(est_), v = enu_to_ned(truth.velocity);
      mv::LocalPositionNed m;
      m.time_boot_ms = boot_ms;
      m.x = static_cast<float>(p.x());
      m.y = static_cast<float>(p.y());
      m.z = static_cast<float>(p.z());
      m.vx = static_cast<float>(v.x());
      m.vy = static_cast<float>(v.y());
      m.vz = static_cast<float>(v.z());
      return m;
    }
    case mv::ExtendedSysState::kId: {
      mv::ExtendedSysState m;
      namespace ls = mv::mav_landed_state;
      const bool landing_mode = mode_ == FlightMode::Land || mode_ == FlightMode::PrecLand;
      m.landed_state = (!armed_ || landed_) ? ls::kOnGround
                       : mode_ == FlightMode::Takeoff ? ls::kTakeoff
                       : landing_mode ? ls::kLanding
                                      : ls::kInAir;
      return m;
    }
    case mv::SysStatus::kId: {
      mv::SysStatus m;
      m.voltage_battery = static_cast<uint16_t>(std::lround(volts * 1000));
      m.current_battery = static_cast<int16_t>(std::lround(amps * 100));
      m.battery_remaining = static_cast<int8_t>(std::lround(soc * 100));
      m.load = 300;  // 30 %
      return m;
    }
    case mv::BatteryStatus::kId: {
      mv::BatteryStatus m;
      m.id = 0;
      m.battery_function = 1;  // MAV_BATTERY_FUNCTION_ALL
      m.type = 1;              // MAV_BATTERY_TYPE_LIPO
      m.temperature = INT16_MAX;
      m.voltages.fill(UINT16_MAX);
      m.voltages[0] = static_cast<uint16_t>(std::lround(volts * 1000));
      m.current_battery = static_cast<int16_t>(std::lround(amps * 100));
      m.current_consumed = static_cast<int32_t>(std::lround(consumed_mah_));
      m.energy_consumed = -1;
      m.battery_remaining = static_cast<int8_t>(std::lround(soc * 100));
      return m;
    }
    case mv::DistanceSensor::kId: {
      // Downward range finder (MAV_SENSOR_ROTATION_PITCH_270) over flat ground at the start height.
      const double tilt = std::max(0.2, std::cos(truth.roll) * std::cos(truth.pitch));
      const double d = std::max(0.0, truth.position.z() - ground_z_) / tilt;
      mv::DistanceSensor m;
      m.time_boot_ms = boot_ms;
      m.min_distance = 10;
      m.max_distance = 4000;
      m.current_distance = static_cast<uint16_t>(std::clamp(std::lround(d * 100), 10L, 4000L));
      m.type = 0;  // MAV_DISTANCE_SENSOR_LASER
      m.orientation = 25;
      m.covariance = 255;  // unknown
      return m;
    }
    default: break;
  }
  return heartbeat();
}

}  // namespace aerie::sim::autopilot
