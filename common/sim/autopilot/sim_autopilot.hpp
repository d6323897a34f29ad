#pragma once
// The simulator's autopilot face (issue 45, section 3): a flight controller that speaks MAVLink
// with the documented behaviour of PX4 (default personality) or ArduCopter, between the
// companion computer's typed MAVLink messages (common/mavlink/catalogue.hpp) and the
// simulated vehicle's AutopilotCommand (common/sim/flight/multirotor.hpp). No bytes, no
// sockets, no LCM, no wall clock: receive() and step() take simulation time, so a lock-step
// run is a function of its inputs. docs/mavlink.md ("The simulator's autopilot") lists every behaviour with the
// parameter or document it models, and what is not modelled.
//
// Frames: the vehicle's world is ENU (x east, y north, z up; yaw counter-clockwise from east);
// the autopilot's local frame is NED with the same origin (x north, y east, z down), so
// (n, e, d) = (y, x, -z). Body FRD = x forward, y right, z down; the Multirotor's heading
// frame is x forward, y left, z up (yaw only).
//
// Usage (lock-step, one call of each per simulation step):
//   SimAutopilot ap(Personality::Px4, Params{});
//   ap.receive(msg, sysid, compid, t);                 // every message from the companion
//   StepOutput out = ap.step(t, multirotor.state());   // the command + messages to send now
//   multirotor.command(t, out.command);
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <deque>
#include <limits>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "common/mavlink/catalogue.hpp"
#include "common/sim/flight/multirotor.hpp"

namespace aerie::sim::autopilot {

enum class Personality { Px4, ArduCopter };

// The parameters modelled, named as the real ones (units as the real ones: PX4 EKF2_EV_DELAY
// in ms, ArduCopter speeds/altitudes in cm or cm/s). PARAM_REQUEST_READ answers them by name
// or index (param()). Defaults are the firmware defaults unless the comment says otherwise.
struct Params {
  // --- PX4 -------------------------------------------------------------------------------
  double COM_OF_LOSS_T = 1.0;    // s: offboard setpoints missing this long = offboard lost
  int COM_OBL_RC_ACT = 0;        // action on offboard loss: 0 Position, 1 Altitude, 2 Manual, 3 Return, 4 Land, 5 Hold
  int COM_RC_IN_MODE = 4;        // 0-3 need manual control (RC/joystick) to arm; 4 = stick input disabled
                                 // (a companion-only set-up; the firmware default is 3)
  double COM_DISARM_LAND = 2.0;  // s after land detection before auto-disarm; < 0 = never
  double COM_OBC_LOSS_T = 5.0;   // s without the onboard computer's HEARTBEAT = onboard computer lost
  double MIS_TAKEOFF_ALT = 2.5;  // m above home for NAV_TAKEOFF without an altitude
  double MPC_TKO_SPEED = 1.5;    // m/s take-off climb
  double MPC_LAND_SPEED = 0.7;   // m/s descent of AUTO.LAND / PRECLAND / Descend
  double MPC_XY_P = 0.95;        // 1/s horizontal position gain
  double MPC_Z_P = 1.0;          // 1/s vertical position gain
  int EKF2_EV_CTRL = 15;         // vision aiding bits: 0 horizontal position, 1 vertical position, 2 velocity, 3 yaw
  double EKF2_EV_DELAY = 0.0;    // ms: vision measurement delay relative to the IMU
  int EKF2_OF_CTRL = 0;          // optical flow fusion: 1 = on (a flow sensor + rangefinder holds position without GPS or vision)
  int EKF2_HGT_REF = 3;          // height reference: 0 baro, 1 GNSS, 2 range finder, 3 vision (a vision set-up; firmware default 1)
  double PLD_HACC_RAD = 0.2;     // m: start descending when this close above the target
  double PLD_BTOUT = 5.0;        // s: landing target lost after this without a measurement
  double PLD_FAPPR_ALT = 0.1;    // m: final approach (no horizontal positioning) below this above the target
  double PLD_SRCH_ALT = 10.0;    // m above home: search altitude
  double PLD_SRCH_TOUT = 10.0;   // s: search timeout
  int PLD_MAX_SRCH = 3;          // maximum number of search attempts
  // --- ArduCopter -------------------------------------------------------------------------
  double GUID_TIMEOUT = 3.0;     // s: GUIDED stops after this without a velocity setpoint
  int VISO_TYPE = 1;             // visual odometry: 0 none, 1 MAVLink (a vision set-up; firmware default 0)
  int VISO_DELAY_MS = 10;        // ms: visual odometry delay
  int EK3_SRC1_POSXY = 6;        // horizontal position source: 3 GPS, 6 ExternalNav (a vision set-up; default 3)
  int EK3_SRC1_VELXY = 6;        // horizontal velocity source (not used by this model beyond reporting)
  int EK3_SRC1_POSZ = 1;         // vertical position source: 1 baro, 2 range finder, 6 ExternalNav
  int EK3_SRC1_YAW = 6;          // yaw source (not used by this model beyond reporting)
  int FS_EKF_ACTION = 1;         // EKF failsafe: 1 LAND, 2 ALTHOLD (modelled as LAND too), 3 LAND even in STABILIZE
  int PLND_ENABLED = 1;          // precision landing on (a precland set-up; firmware default 0)
  int PLND_TYPE = 1;             // 1 = MAVLink LANDING_TARGET
  int LAND_SPEED = 50;           // cm/s final descent of LAND
  double PILOT_TKOFF_ALT = 250;  // cm: NAV_TAKEOFF altitude when param7 is 0 (this model's use of it)
  double WPNAV_SPEED_UP = 250;   // cm/s climb of a GUIDED take-off
  double PSC_POSXY_P = 1.0;      // 1/s horizontal position gain
  double PSC_POSZ_P = 1.0;       // 1/s vertical position gain
  // --- the simulated battery (not parameters of either firmware) --------------------------
  double battery_capacity_mah = 5000;
  int battery_cells = 4;
  double battery_idle_current_a = 0.5;   // disarmed
  double battery_flight_current_a = 15;  // armed
  // --- the simulated optical-flow odometry (not a firmware parameter): the position it holds on
  // drifts as a random walk, as the Multirotor's own hold does (multirotor.hpp, hold_drift_m_per_sqrt_s)
  double flow_drift_m_per_sqrt_s = 0.01;
  // --- HIGHRES_IMU noise (white, per axis, 1 sigma; 0 = clean), seeded ---------------------
  double imu_accel_noise_m_s2 = 0;
  double imu_gyro_noise_rad_s = 0;
  uint64_t noise_seed = 1;

  void validate() const;  // throws std::invalid_argument naming the field
};

// The autopilot as set up on the simulated airframe when no vision is fused: it holds position
// on optical flow (the vehicle's own drifting odometry, MultirotorParams::hold_drift_m_per_sqrt_s),
// its height on a range finder, and climbs and lands at the airframe's speeds (the vehicle refuses
// commands far above its limits). Used by the landing bench and by aerie-flightsim --autopilot.
Params airframe_params(const MultirotorParams& vehicle, uint64_t seed);

// A parameter as PARAM_VALUE reports it.
struct ParamEntry {
  std::string name;
  bool is_int = false;
  double value = 0;
  uint16_t index = 0;
  uint16_t count = 0;
};

// A message to send now, to target (0, 0) = broadcast.
struct Outbound {
  mavlink::Message msg;
  uint8_t target_system = 0;
  uint8_t target_component = 0;
};

struct StepOutput {
  AutopilotCommand command;        // for Multirotor::command(t, ...)
  std::vector<Outbound> messages;  // in the order they are to be sent
};

// The autopilot's flight modes (its own names; the HEARTBEAT custom_mode per personality).
enum class FlightMode { Manual, Altitude, Position, Offboard, Takeoff, Hold, Land, PrecLand, Return, Guided, Brake };

// PX4's PrecLand states (src/modules/navigator/precland.h).
enum class PrecLandState { Idle, Start, HorizontalApproach, DescendAboveTarget, FinalApproach, Search, Fallback, Done };
enum class PrecLandMode { None = 0, Opportunistic = 1, Required = 2 };
const char* to_string(PrecLandState s);  // "idle", "start", "horizontal_approach", ...

class SimAutopilot {
 public:
  static constexpr uint8_t kSystemId = 1;
  static constexpr uint8_t kComponentId = 1;

  explicit SimAutopilot(Personality personality, const Params& params = {});

  // A message from (sysid, compid), received at simulation time t_s. Messages the autopilot
  // does not use, or that target another system, are ignored (counted in ignored()). Replies
  // (COMMAND_ACK, STATUSTEXT, PARAM_VALUE, TIMESYNC, ...) come out of the next step().
  void receive(const mavlink::Message& msg, uint8_t sysid, uint8_t compid, double t_s);
  // Advances the autopilot to t_s (non-decreasing) given the vehicle's true state: estimator,
  // failsafes, mode logic, guidance; returns the vehicle command and the messages due now.
  StepOutput step(double t_s, const MultirotorState& truth);

  // PARAM_VALUE content of a parameter of this personality; nullopt when it does not exist.
  std::optional<ParamEntry> param(const std::string& name) const;
  std::optional<ParamEntry> param(uint16_t index) const;
  uint16_t param_count() const;

  Personality personality() const { return personality_; }
  const Params& params() const { return p_; }
  bool armed() const { return armed_; }
  FlightMode mode() const { return mode_; }
  std::string mode_name() const;  // "OFFBOARD", "AUTO.PRECLAND", "GUIDED", ...
  uint32_t custom_mode() const;   // as in HEARTBEAT
  PrecLandState precland_state() const { return pl_state_; }
  int precland_searches() const { return pl_search_count_; }
  bool landed() const { return landed_; }
  bool position_valid() const { return xy_valid_; }
  // The autopilot's position estimate (world ENU): truth + its estimation error.
  Eigen::Vector3d estimate() const { return est_; }
  bool companion_alive() const { return companion_alive_; }
  bool descending_without_position() const { return descend_; }
  // Every STATUSTEXT sent so far (also in the step outputs), for logs and tests.
  const std::vector<std::string>& texts() const { return texts_; }
  int64_t commands_executed() const { return commands_executed_; }
  int64_t ignored() const { return ignored_; }
  int64_t setpoints_refused() const { return setpoints_refused_; }
  int64_t vision_resets() const { return vision_resets_; }  // reset_counter changes fused
  // Current stream interval of a message id (s; 0 = off).
  double stream_interval(uint32_t msg_id) const;

 private:
  struct VisionSample {
    double t_meas;
    Eigen::Vector3d p;  // ENU
    bool reset = false;  // reset_counter changed with this sample
  };
  struct Setpoint {
    Eigen::Vector3d v_world = Eigen::Vector3d::Zero();  // ENU m/s
    double yaw_rate_cw = 0;                             // rad/s, clockwise positive
    bool has_yaw = false;                               // absolute yaw instead of a rate
    double yaw_ned = 0;                                 // rad, clockwise from north
  };
  struct Stream {
    double interval = 0;  // s, 0 = off
    double default_interval = 0;
    double next = 0;
  };
  struct LastCommand {
    uint16_t command = 0;
    std::array<float, 7> params{};
    uint8_t result = 0;
    bool valid = false;
  };

  // receive() handlers
  void on_command(const mavlink::CommandLong& c, uint8_t sysid, uint8_t compid, double t);
  void on_setpoint(const mavlink::SetPositionTargetLocalNed& m, double t);
  void on_vision(const Eigen::Vector3d& p_ned, uint8_t reset_counter, double t);
  void on_landing_target(const mavlink::LandingTarget& m, double t);
  void on_param_request(const mavlink::ParamRequestRead& m, uint8_t sysid, uint8_t compid);

  // commands: return MAV_RESULT, may set a reason (STATUSTEXT)
  uint8_t cmd_arm(const mavlink::CommandLong& c, double t);
  uint8_t cmd_set_mode(const mavlink::CommandLong& c, double t);
  uint8_t cmd_takeoff(const mavlink::CommandLong& c, double t);
  uint8_t cmd_land(const mavlink::CommandLong& c, double t);
  uint8_t cmd_message_interval(const mavlink::CommandLong& c);
  uint8_t cmd_request_message(const mavlink::CommandLong& c, uint8_t sysid, uint8_t compid, double t);

  // mode logic
  std::string name_of(FlightMode m) const;
  bool mode_needs_position(FlightMode m) const;
  bool offboard_stream_ok(double t) const;
  // Refusal reason to enter mode m now ("" = allowed).
  std::string mode_refusal(FlightMode m, double t) const;
  void enter_mode(FlightMode m, double t);
  void start_precland(PrecLandMode mode, double t);
  void disarm(double t, const std::string& why);
  void failsafe(FlightMode fallback, double t, const std::string& text);
  bool target_valid(double t) const;
  void precland_step(double t);
  void pl_switch(PrecLandState s, double t);

  // estimator
  Eigen::Vector3d truth_at(double t) const;
  void estimator_step(double t, const MultirotorState& truth);
  bool fusion_configured() const;
  bool flow_configured() const;  // PX4 EKF2_OF_CTRL, ArduCopter EK3_SRC1_VELXY = 5 (OpticalFlow)
  bool on_flow(double t) const;  // flow configured and no fresh vision fused: the position is the flow's
  bool vertical_from_vision() const;

  // guidance: desired world velocity (ENU) and clockwise yaw rate; the vehicle command
  AutopilotCommand guidance(double t, const MultirotorState& truth);
  Eigen::Vector3d hold_velocity(const Eigen::Vector3d& sp, bool hold_z) const;

  // telemetry
  void statustext(uint8_t severity, const std::string& text);
  void send(mavlink::Message m, uint8_t ts = 0, uint8_t tc = 0) { outbox_.push_back({std::move(m), ts, tc}); }
  mavlink::Message make(uint32_t msg_id, double t, const MultirotorState& truth);
  mavlink::Message heartbeat() const;
  mavlink::Message autopilot_version() const;

  Personality personality_;
  Params p_;
  std::vector<Outbound> outbox_;
  std::vector<std::string> texts_;
  std::map<uint32_t, Stream> streams_;
  std::map<std::pair<uint8_t, uint8_t>, LastCommand> last_cmd_;
  int64_t commands_executed_ = 0, ignored_ = 0, setpoints_refused_ = 0;

  double t_ = 0;
  MultirotorState truth_;
  bool armed_ = false;
  FlightMode mode_;
  double mode_since_ = 0;
  bool landed_ = true;
  double ground_contact_since_ = 0;
  double landed_since_ = 0;
  bool descend_ = false;  // Descend failsafe: no horizontal position
  bool was_airborne_ = false;  // left the ground since arming (auto-disarm after landing only then)
  bool guided_stopped_ = false;
  bool tracking_target_ = false;  // ArduCopter LAND following a precision-landing target
  uint16_t statustext_id_ = 0;
  double ground_z_ = 0;  // the range finder's ground: the height the vehicle started from

  // position control setpoints (world ENU)
  Eigen::Vector3d hold_sp_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d home_ = Eigen::Vector3d::Zero();  // the estimate at arming
  double takeoff_z_ = 0;

  // offboard / guided setpoints
  Setpoint sp_;
  bool have_sp_ = false;
  double sp_last_ = -1e9, sp_run_start_ = -1e9;

  // estimator
  std::deque<std::pair<double, Eigen::Vector3d>> truth_hist_;
  std::deque<VisionSample> vision_pending_;
  Eigen::Vector3d est_err_ = Eigen::Vector3d::Zero();  // estimate - truth (ENU)
  Eigen::Vector3d est_ = Eigen::Vector3d::Zero();
  bool have_vision_ = false;
  double vision_last_ = -1e9;
  bool xy_valid_ = false, z_valid_ = true;
  bool origin_set_ = false;  // ArduCopter: SET_GPS_GLOBAL_ORIGIN received
  bool have_reset_counter_ = false;
  uint8_t reset_counter_ = 0;
  int64_t vision_resets_ = 0;

  // precision landing
  PrecLandState pl_state_ = PrecLandState::Idle;
  PrecLandMode pl_mode_ = PrecLandMode::None;
  double pl_state_since_ = 0;
  int pl_search_count_ = 0;
  bool have_target_ = false;
  double target_last_ = -1e9;
  Eigen::Vector3d target_ = Eigen::Vector3d::Zero();  // ENU, in the estimate's frame
  Eigen::Vector3d pl_hold_ = Eigen::Vector3d::Zero();

  // companion link
  double companion_last_ = -1e9;
  bool companion_alive_ = false;

  // battery, IMU
  double consumed_mah_ = 0;
  double prev_roll_ = 0, prev_pitch_ = 0;
  double roll_rate_ = 0, pitch_rate_ = 0;
  bool stepped_ = false;
  std::mt19937_64 rng_;
  std::mt19937_64 flow_rng_;  // its own stream: turning flow on leaves the IMU noise as it was
  double flow_t_ = -1;        // time of the last flow drift step
};

// A velocity in local NED -> the Multirotor's heading frame (x forward, y left, z up) for a
// vehicle whose ENU yaw is yaw_enu: v_enu = (v_e, v_n, -v_d), then rotate by -yaw about z:
//   forward = cos(yaw) v_east + sin(yaw) v_north,  left = -sin(yaw) v_east + cos(yaw) v_north.
Eigen::Vector3d ned_to_heading(const Eigen::Vector3d& v_ned, double yaw_enu);
Eigen::Vector3d heading_to_ned(const Eigen::Vector3d& v_heading, double yaw_enu);
// A velocity in MAV_FRAME_BODY_NED (x forward, y right, z down, yaw-only rotation: PX4's and
// ArduPilot's reading of frame 8) -> heading frame: (x, -y, -z).
Eigen::Vector3d body_ned_to_heading(const Eigen::Vector3d& v_body_ned);
// World ENU <-> local NED (same origin).
Eigen::Vector3d enu_to_ned(const Eigen::Vector3d& v);
Eigen::Vector3d ned_to_enu(const Eigen::Vector3d& v);
// Rotation body FRD -> local NED for the Multirotor's attitude (ENU yaw, ZYX roll/pitch of the
// FLU body): R_ned_frd = T * R_enu_flu * F, T = [[0,1,0],[1,0,0],[0,0,-1]], F = diag(1,-1,-1).
Eigen::Matrix3d ned_from_frd(double roll, double pitch, double yaw_enu);

}  // namespace aerie::sim::autopilot
