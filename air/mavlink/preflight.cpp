#include "air/mavlink/preflight.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <stdexcept>

namespace aerie::bridge {

namespace mav = aerie::mavlink;

namespace {

// MAV_PARAM_TYPE (common.xml).
constexpr uint8_t kUint8 = 1, kInt8 = 2, kUint16 = 3, kInt16 = 4, kUint32 = 5, kInt32 = 6, kReal32 = 9, kReal64 = 10;
// MAV_PROTOCOL_CAPABILITY (common.xml).
constexpr uint64_t kCapParamBytewise = 16, kCapParamCCast = 131072;

std::string id_string(const std::array<char, 16>& id) {
  size_t n = 0;
  while (n < id.size() && id[n] != '\0') ++n;
  return std::string(id.data(), n);
}

bool is_real(uint8_t type) { return type == kReal32 || type == kReal64; }

// PARAM_VALUE.param_value as a number. Integers: bytewise (PX4: the integer's bytes in the
// float's place) or C cast (ArduPilot: the integer converted to float), as the autopilot says.
double param_number(const mav::ParamValue& v, bool bytewise) {
  if (is_real(v.param_type) || !bytewise) return is_real(v.param_type) ? v.param_value : std::round(v.param_value);
  uint8_t b[4];
  std::memcpy(b, &v.param_value, 4);
  switch (v.param_type) {
    case kUint8: return b[0];
    case kInt8: return static_cast<int8_t>(b[0]);
    case kUint16: return static_cast<uint16_t>(b[0] | b[1] << 8);
    case kInt16: return static_cast<int16_t>(b[0] | b[1] << 8);
    case kUint32: return static_cast<uint32_t>(b[0] | b[1] << 8 | b[2] << 16 | static_cast<uint32_t>(b[3]) << 24);
    case kInt32:
    default: {
      int32_t i;
      std::memcpy(&i, &v.param_value, 4);
      return i;
    }
  }
}

// 921600 -> "921600", 1.0f -> "1", 0.2f -> "0.2" (a float parameter to its float's precision).
std::string num(double v, bool is_int) {
  char buf[32];
  if (is_int) std::snprintf(buf, sizeof buf, "%.0f", v);
  else std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

int as_int(double v) { return static_cast<int>(std::lround(v)); }

// "N (name)" with a name from a table, or "N" alone.
std::string named(double v, std::initializer_list<std::pair<int, const char*>> names) {
  for (const auto& [k, n] : names)
    if (as_int(v) == k) return num(v, true) + " (" + n + ")";
  return num(v, true);
}

bool is_multirotor(uint8_t mav_type) {
  // MAV_TYPE: QUADROTOR 2, COAXIAL 3, HELICOPTER 4, HEXAROTOR 13, OCTOROTOR 14, TRICOPTER 15, DODECAROTOR 29
  return mav_type == 2 || mav_type == 3 || mav_type == 4 || mav_type == 13 || mav_type == 14 || mav_type == 15 ||
         mav_type == 29;
}

// What one parameter is, for one autopilot and configuration.
struct ParamPlan {
  std::string name;
  bool item = true;       // printed; else read only to judge another one
  bool optional = false;  // not found: WARN (it may be elsewhere) instead of FAIL
  std::string not_found_fix;
};

std::vector<ParamPlan> plan_for(mav::Autopilot ap, const PreflightConfig& c) {
  const bool odo = c.send_odometry, precland = c.landing_path == LandingPath::Autopilot;
  std::vector<ParamPlan> p;
  if (ap == mav::Autopilot::Px4) {
    const std::string port =
        "the companion may be on another port (USB, Ethernet, another MAV_n instance): fine then; on TELEM2 set ";
    p.push_back({"MAV_1_CONFIG", true, true, port + "MAV_1_CONFIG 102 (TELEM2)"});
    p.push_back({"MAV_1_MODE", true, true, "appears once MAV_1_CONFIG is set; " + port + "MAV_1_MODE 2 (Onboard)"});
    p.push_back({"SER_TEL2_BAUD", true, true, "appears once a MAVLink instance is on TELEM2; " + port +
                                                 "SER_TEL2_BAUD 921600"});
    p.push_back({"COM_OF_LOSS_T", true, false, "this firmware has no offboard-loss time-out: use PX4 1.14 or newer"});
    p.push_back({"COM_OBL_RC_ACT", true, false, "this firmware has no offboard-loss action: use PX4 1.14 or newer"});
    p.push_back({"EKF2_OF_CTRL", false, true, ""});  // a position source of its own (flow), for COM_OBL_RC_ACT
    if (odo)
      p.push_back({"EKF2_EV_CTRL", true, false,
                   "PX4 before 1.14 has EKF2_AID_MASK instead: use PX4 1.14 or newer (docs/mavlink.md)"});
    p.push_back({"EKF2_HGT_REF", true, false, "PX4 before 1.14 has EKF2_HGT_MODE instead: use PX4 1.14 or newer"});
    if (odo) p.push_back({"EKF2_EV_DELAY", true, false, "use PX4 1.14 or newer"});
    if (precland)
      for (const char* n : {"PLD_HACC_RAD", "PLD_BTOUT", "PLD_FAPPR_ALT", "PLD_SRCH_ALT", "PLD_SRCH_TOUT", "PLD_MAX_SRCH"})
        p.push_back({n, true, false,
                     "this firmware has no precision landing (PX4's precland and landing_target_estimator): "
                     "build them in, or land with --landing aerie"});
  } else if (ap == mav::Autopilot::ArduPilot) {
    const std::string port = "the companion may be on another port (USB, Ethernet, another SERIALn): fine then; on "
                             "TELEM2 set ";
    p.push_back({"SERIAL2_PROTOCOL", true, true, port + "SERIAL2_PROTOCOL 2 (MAVLink 2)"});
    p.push_back({"SERIAL2_BAUD", true, true, port + "SERIAL2_BAUD 921"});
    if (odo)
      p.push_back({"VISO_TYPE", true, false, "this firmware has no visual odometry (HAL_VISUALODOM_ENABLED): "
                                             "use ArduCopter 4.0 or newer"});
    p.push_back({"EK3_SRC1_POSXY", true, false, "EKF3 source selection needs ArduCopter 4.0 or newer (EK3_ENABLE 1)"});
    if (odo)
      p.push_back({"EK3_SRC1_VELXY", true, false, "EKF3 source selection needs ArduCopter 4.0 or newer (EK3_ENABLE 1)"});
    p.push_back({"GUID_TIMEOUT", true, false, "GUIDED's time-out needs ArduCopter 4.0 or newer"});
    if (precland) {
      p.push_back({"PLND_ENABLED", true, false, "this firmware has no precision landing (AC_PRECLAND_ENABLED): "
                                                "build it in, or land with --landing aerie"});
      p.push_back({"PLND_TYPE", true, false, "appears once PLND_ENABLED is 1 (after a reboot); then set PLND_TYPE 1"});
    }
  }
  return p;
}

struct Judgement {
  Verdict verdict;
  std::string found, fix;
};

using Lookup = std::function<std::optional<double>(const std::string&)>;

Judgement judge_px4(const std::string& n, double v, const PreflightConfig& c, const Lookup& get) {
  const int i = as_int(v);
  if (n == "MAV_1_CONFIG") {
    const std::string f = named(v, {{0, "disabled"}, {101, "TELEM1"}, {102, "TELEM2"}, {103, "TELEM3"},
                                    {104, "TELEM/SERIAL4"}});
    if (i == 102) return {Verdict::Pass, f, ""};
    return {Verdict::Warn, f, "fine if the companion is on another port (USB, Ethernet, another MAV_n); on TELEM2 "
                              "set MAV_1_CONFIG 102"};
  }
  if (n == "MAV_1_MODE") {
    const std::string f = named(v, {{0, "Normal"}, {1, "Custom"}, {2, "Onboard"}, {3, "OSD"}, {4, "Magic"},
                                    {5, "Config"}, {7, "Minimal"}, {8, "External Vision"},
                                    {11, "Onboard Low Bandwidth"}, {13, "Low Bandwidth"}});
    if (i == 2) return {Verdict::Pass, f, ""};
    if (get("MAV_1_CONFIG") == 102.0)
      return {Verdict::Fail, f + ", the companion's TELEM2 link", "set MAV_1_MODE 2 (Onboard)"};
    return {Verdict::Warn, f, "fine if the companion is not on MAV_1; else set MAV_1_MODE 2 (Onboard)"};
  }
  if (n == "SER_TEL2_BAUD") {
    const std::string f = num(v, true);
    if (i == 921600) return {Verdict::Pass, f, ""};
    if (get("MAV_1_CONFIG") == 102.0 && i < 460800)
      return {Verdict::Fail, f + " (too slow for Aerie's setpoints, odometry and the autopilot's IMU stream)",
              "set SER_TEL2_BAUD 921600 (and serial:...:921600 on the companion)"};
    return {Verdict::Warn, f, "set SER_TEL2_BAUD 921600 if the companion is on TELEM2 (and serial:...:921600 on it)"};
  }
  if (n == "COM_OF_LOSS_T") {
    if (v <= 0) return {Verdict::Fail, num(v, false) + " (offboard loss never detected)", "set COM_OF_LOSS_T 1.0"};
    if (v > 2)
      return {Verdict::Fail, num(v, false) + " (Aerie's last setpoint flown " + num(v, false) + " s after it stops)",
              "set COM_OF_LOSS_T 1.0"};
    return {Verdict::Pass, num(v, false) + " s", ""};
  }
  if (n == "COM_OBL_RC_ACT") {
    const std::string f = named(v, {{0, "Position"}, {1, "Altitude"}, {2, "Manual"}, {3, "Return"}, {4, "Land"},
                                    {5, "Hold"}, {6, "Terminate"}, {7, "Disarm"}});
    if (i == 4) return {Verdict::Pass, f, ""};
    if (i == 0 || i == 3 || i == 5) {
      const bool vision = c.send_odometry && (as_int(get("EKF2_EV_CTRL").value_or(0)) & 1);
      const bool flow = as_int(get("EKF2_OF_CTRL").value_or(0)) != 0;
      if (vision || flow) return {Verdict::Pass, f + ", position from " + (flow ? "optical flow" : "vision"), ""};
      return {Verdict::Warn, f + " without a position source (no vision, no optical flow)",
              "set COM_OBL_RC_ACT 4 (Land), unless GPS is fitted"};
    }
    if (i == 1 || i == 2)
      return {Verdict::Warn, f + " (the vehicle drifts unless a pilot takes over)",
              "set COM_OBL_RC_ACT 4 (Land), or keep a pilot on the sticks"};
    if (i == 6 || i == 7) return {Verdict::Fail, f + " (the vehicle falls)", "set COM_OBL_RC_ACT 4 (Land)"};
    return {Verdict::Warn, f + " (unknown action)", "set COM_OBL_RC_ACT 4 (Land)"};
  }
  if (n == "EKF2_EV_CTRL") {
    std::string bits;
    const char* names[] = {"horizontal position", "vertical position", "velocity", "yaw"};
    for (int b = 0; b < 4; ++b)
      if (i & (1 << b)) bits += std::string(bits.empty() ? "" : ", ") + names[b];
    const std::string f = num(v, true) + " (" + (bits.empty() ? "no vision fused" : bits) + ")";
    if ((i & 3) == 3) return {Verdict::Pass, f, ""};
    return {Verdict::Fail, f + ": Aerie's vision position not fused", "set EKF2_EV_CTRL 15 (or 11 without vision yaw)"};
  }
  if (n == "EKF2_HGT_REF") {
    const std::string f = named(v, {{0, "baro"}, {1, "GNSS"}, {2, "range finder"}, {3, "vision"}});
    if (!c.send_odometry) {
      if (i == 3)
        return {Verdict::Fail, f + ", but Aerie sends no odometry",
                "set EKF2_HGT_REF 2 (range finder) or 0 (baro), or turn send_odometry on"};
      return {Verdict::Pass, f, ""};
    }
    if (i == 2 || i == 3) return {Verdict::Pass, f, ""};
    return {Verdict::Warn, f + " (drifts near the ground)", "set EKF2_HGT_REF 3 (vision) or 2 (range finder)"};
  }
  if (n == "EKF2_EV_DELAY") {
    if (v > 0) return {Verdict::Pass, num(v, false) + " ms", ""};
    return {Verdict::Warn, num(v, false) + " ms (vision taken as measured now)",
            "set EKF2_EV_DELAY to the measured camera-to-estimate latency (ms)"};
  }
  // PLD_*: present is what matters.
  return {Verdict::Pass, "", ""};
}

Judgement judge_ardupilot(const std::string& n, double v, const PreflightConfig& c, const Lookup& get) {
  const int i = as_int(v);
  if (n == "SERIAL2_PROTOCOL") {
    const std::string f = named(v, {{-1, "none"}, {1, "MAVLink 1"}, {2, "MAVLink 2"}, {5, "GPS"}, {10, "FrSky"},
                                    {23, "RCIN"}, {28, "Scripting"}});
    if (i == 2) return {Verdict::Pass, f, ""};
    return {Verdict::Warn, f, "fine if the companion is on another port (USB, Ethernet, another SERIALn); on TELEM2 "
                              "set SERIAL2_PROTOCOL 2 (MAVLink 2)"};
  }
  if (n == "SERIAL2_BAUD") {
    const std::string f = num(v, true);
    if (i == 921) return {Verdict::Pass, f + " (921600 baud)", ""};
    if (get("SERIAL2_PROTOCOL") == 2.0 && i < 460)
      return {Verdict::Fail, f + " (too slow for Aerie's setpoints, odometry and the autopilot's IMU stream)",
              "set SERIAL2_BAUD 921 (and serial:...:921600 on the companion)"};
    return {Verdict::Warn, f, "set SERIAL2_BAUD 921 if the companion is on TELEM2 (and serial:...:921600 on it)"};
  }
  if (n == "VISO_TYPE") {
    const std::string f = named(v, {{0, "none"}, {1, "MAVLink"}, {2, "IntelT265"}, {3, "VOXL"}});
    if (i == 1) return {Verdict::Pass, f, ""};
    return {Verdict::Fail, f + ": Aerie's ODOMETRY not used", "set VISO_TYPE 1 (MAVLink) and reboot"};
  }
  if (n == "EK3_SRC1_POSXY" || n == "EK3_SRC1_VELXY") {
    const std::string f = named(v, {{0, "none"}, {3, "GPS"}, {4, "Beacon"}, {5, "OpticalFlow"}, {6, "ExternalNav"}});
    if (!c.send_odometry) {
      if (i == 6)
        return {Verdict::Fail, f + ", but Aerie sends no odometry",
                "set " + n + " 3 (GPS), or turn send_odometry on"};
      return {Verdict::Pass, f, ""};
    }
    if (i == 6) return {Verdict::Pass, f, ""};
    return {Verdict::Fail, f + ": Aerie's vision not used", "set " + n + " 6 (ExternalNav)"};
  }
  if (n == "GUID_TIMEOUT") {
    if (v <= 0) return {Verdict::Fail, num(v, false) + " (GUIDED never notices Aerie stopped)", "set GUID_TIMEOUT 3"};
    if (v > 5)
      return {Verdict::Fail, num(v, false) + " (Aerie's last setpoint flown " + num(v, false) + " s after it stops)",
              "set GUID_TIMEOUT 3"};
    return {Verdict::Pass, num(v, false) + " s", ""};
  }
  if (n == "PLND_ENABLED") {
    if (i == 1) return {Verdict::Pass, "1 (on)", ""};
    return {Verdict::Fail, num(v, true) + " (precision landing off)", "set PLND_ENABLED 1 and reboot"};
  }
  if (n == "PLND_TYPE") {
    const std::string f = named(v, {{0, "none"}, {1, "companion computer"}, {2, "IRLock"}, {3, "SITL Gazebo"},
                                    {4, "SITL"}});
    if (i == 1) return {Verdict::Pass, f, ""};
    return {Verdict::Fail, f + ": Aerie's LANDING_TARGET not used", "set PLND_TYPE 1 (companion computer, MAVLink)"};
  }
  return {Verdict::Pass, "", ""};
}

std::string version_string(uint32_t v) {
  const int type = static_cast<int>(v & 0xFF);
  const char* t = type == 0 ? "dev" : type == 64 ? "alpha" : type == 128 ? "beta" : type == 192 ? "rc"
                  : type == 255 ? "official" : "type?";
  char buf[48];
  std::snprintf(buf, sizeof buf, "%u.%u.%u (%s)", v >> 24, (v >> 16) & 0xFF, (v >> 8) & 0xFF, t);
  return buf;
}

}  // namespace

const char* to_string(Verdict v) {
  switch (v) {
    case Verdict::Pass: return "PASS";
    case Verdict::Warn: return "WARN";
    case Verdict::Fail: return "FAIL";
  }
  return "?";
}

std::string to_line(const CheckItem& item) {
  std::string line = std::string(to_string(item.verdict)) + " " + item.name + (item.has_value ? " = " : ": ") +
                     item.found;
  if (!item.fix.empty()) line += " — " + item.fix;
  return line;
}

void PreflightConfig::validate() const {
  auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) throw std::invalid_argument(std::string("preflight check: ") + field + " must be " + expected);
  };
  require(system_id >= 1 && system_id <= 255, "system_id", "in [1, 255]");
  require(component_id >= 1 && component_id <= 255, "component_id", "in [1, 255]");
  require(autopilot_system_id >= 0 && autopilot_system_id <= 255, "autopilot_system_id", "in [0, 255]");
  require(heartbeat_timeout_s > 0 && heartbeat_timeout_s <= 600, "heartbeat_timeout_s", "in (0, 600]");
  require(retry_s > 0 && retry_s <= 60, "retry_s", "in (0, 60]");
  require(attempts >= 1 && attempts <= 20, "attempts", "in [1, 20]");
  require(window >= 1 && window <= 100, "window", "in [1, 100]");
  require(timeout_s > 0 && timeout_s <= 3600, "timeout_s", "in (0, 3600]");
}

PreflightConfig PreflightConfig::from(const BridgeConfig& b) {
  PreflightConfig c;
  c.system_id = b.system_id;
  c.component_id = b.component_id;
  c.autopilot_system_id = b.autopilot_system_id;
  c.send_odometry = b.send_odometry;
  c.landing_path = b.landing_path;
  return c;
}

PreflightCheck::PreflightCheck(PreflightConfig cfg) : cfg_(cfg) { cfg_.validate(); }

void PreflightCheck::enable_signing(const mav::Key& key, uint8_t link_id, uint64_t persisted_timestamp) {
  const mav::SigningClock clock = [now = now_us_] { return signing_ticks(*now); };
  signer_.emplace(key, link_id, persisted_timestamp, clock);
  parser_.set_signing(key, /*require=*/true, clock);
  key_fingerprint_ = mav::fingerprint(key);
}

bool PreflightCheck::passed() const {
  return done_ && std::none_of(items_.begin(), items_.end(), [](const CheckItem& i) { return i.verdict == Verdict::Fail; });
}

std::vector<std::string> PreflightCheck::parameters_asked() const {
  std::vector<std::string> out;
  for (const auto& p : params_)
    if (p.sent > 0) out.push_back(p.name);
  return out;
}

template <class Msg>
void PreflightCheck::emit(const Msg& msg) {
  const mav::Header h{static_cast<uint8_t>(cfg_.system_id), static_cast<uint8_t>(cfg_.component_id), seq_++};
  out_.push_back(signer_ ? mav::encode(msg, h, *signer_) : mav::encode(msg, h));
  ++frames_out_;
}

void PreflightCheck::receive(std::span<const uint8_t> bytes, int64_t now_us) {
  *now_us_ = std::max(*now_us_, now_us);
  if (started_us_ < 0) started_us_ = now_us;
  parser_.feed(bytes, [&](const mav::Frame& f) { on_frame(f, now_us); });
}

void PreflightCheck::on_frame(const mav::Frame& f, int64_t now_us) {
  if (done_) return;
  if (!heard_) {
    if (f.msgid != mav::Heartbeat::kId) return;
    const auto hb = mav::decode<mav::Heartbeat>(f);
    if (hb.autopilot == mav::mav_autopilot::kInvalid) return;  // a ground station, a companion
    if (f.sysid == cfg_.system_id && f.compid == cfg_.component_id) return;  // our own, echoed
    if (cfg_.autopilot_system_id != 0 && f.sysid != cfg_.autopilot_system_id) return;
    heard_ = true;
    heartbeat_ = hb;
    ap_sysid_ = f.sysid;
    ap_compid_ = f.compid;
    autopilot_ = mav::autopilot_of(hb.autopilot);
    if (f.signature) signed_frame_seen_ = true;
    start(now_us);
    return;
  }
  if (f.sysid != ap_sysid_ || f.compid != ap_compid_) return;  // another system or component
  if (f.signature) signed_frame_seen_ = true;
  try {
    if (f.msgid == mav::AutopilotVersion::kId) {
      version_ = mav::decode<mav::AutopilotVersion>(f);
      version_done_ = true;
    } else if (f.msgid == mav::CommandAck::kId) {
      const auto ack = mav::decode<mav::CommandAck>(f);
      if (ack.command != version_command_ || version_done_) return;
      if (ack.result == mav::mav_result::kAccepted || ack.result == mav::mav_result::kInProgress) {
        version_sent_at_us_ = now_us;  // the message follows: wait one more retry period for it
        version_sent_ = std::max(version_sent_, cfg_.attempts);
      } else if (ack.result == mav::mav_result::kUnsupported && version_command_ == mav::mav_cmd::kRequestMessage) {
        version_command_ = mav::mav_cmd::kRequestAutopilotCapabilities;  // older firmware
        version_sent_ = 0;
        send_version_request(now_us);
      } else {
        version_refused_ = ack.result;
        version_done_ = true;
      }
    } else if (f.msgid == mav::ParamValue::kId) {
      const auto v = mav::decode<mav::ParamValue>(f);
      const std::string name = id_string(v.param_id);
      for (auto& p : params_)
        if (p.name == name && !p.answer) p.answer = v;
    }
  } catch (const std::invalid_argument&) {
    // A payload longer than the message's: the parser counts those; nothing to judge.
  }
}

void PreflightCheck::start(int64_t now_us) {
  for (const ParamPlan& p : plan_for(autopilot_, cfg_)) {
    ParamRequest r;
    r.name = p.name;
    params_.push_back(r);
  }
  send_version_request(now_us);
}

void PreflightCheck::send_version_request(int64_t now_us) {
  mav::CommandLong c;
  c.target_system = ap_sysid_;
  c.target_component = ap_compid_;
  c.command = version_command_;
  c.confirmation = static_cast<uint8_t>(std::min(version_sent_, 255));
  c.param1 = version_command_ == mav::mav_cmd::kRequestMessage ? static_cast<float>(mav::AutopilotVersion::kId) : 1.0f;
  emit(c);
  ++version_sent_;
  version_sent_at_us_ = now_us;
}

std::vector<std::vector<uint8_t>> PreflightCheck::poll(int64_t now_us) {
  *now_us_ = std::max(*now_us_, now_us);
  if (started_us_ < 0) started_us_ = now_us;
  const bool timed_out = now_us - started_us_ >= static_cast<int64_t>(cfg_.timeout_s * 1e6);
  if (!done_ && !heard_ && (timed_out || now_us - started_us_ >= static_cast<int64_t>(cfg_.heartbeat_timeout_s * 1e6)))
    finish(now_us);
  if (!done_ && (!heartbeat_sent_ || now_us - last_heartbeat_sent_ >= 1'000'000)) {
    mav::Heartbeat hb;
    hb.type = mav::mav_type::kOnboardController;
    hb.autopilot = mav::mav_autopilot::kInvalid;
    hb.system_status = mav::mav_state::kActive;
    hb.mavlink_version = 3;
    emit(hb);
    heartbeat_sent_ = true;
    last_heartbeat_sent_ = now_us;
  }
  if (done_ || !heard_) return std::exchange(out_, {});
  if (timed_out) {  // whatever is unanswered now FAILs
    finish(now_us);
    return std::exchange(out_, {});
  }
  const auto retry_us = static_cast<int64_t>(cfg_.retry_s * 1e6);
  if (!version_done_ && now_us - version_sent_at_us_ >= retry_us) {
    if (version_sent_ < cfg_.attempts) send_version_request(now_us);
    else version_done_ = true;
  }
  // Parameters: unanswered ones again after retry_s (until `attempts`), new ones while fewer
  // than `window` are unanswered.
  auto send = [&](ParamRequest& p) {
    mav::ParamRequestRead r;
    r.target_system = ap_sysid_;
    r.target_component = ap_compid_;
    std::memcpy(r.param_id.data(), p.name.data(), std::min(p.name.size(), r.param_id.size()));
    r.param_index = -1;  // by name
    emit(r);
    ++p.sent;
    p.sent_at_us = now_us;
  };
  int in_flight = 0;
  for (auto& p : params_) {
    if (p.sent == 0 || p.answer || p.gave_up) continue;
    if (now_us - p.sent_at_us >= retry_us) {
      if (p.sent >= cfg_.attempts) {
        p.gave_up = true;
        continue;
      }
      send(p);
    }
    ++in_flight;
  }
  for (auto& p : params_) {
    if (in_flight >= cfg_.window) break;
    if (p.sent != 0 || p.answer || p.gave_up) continue;
    send(p);
    ++in_flight;
  }
  if (version_done_ && std::all_of(params_.begin(), params_.end(), [](const ParamRequest& p) {
        return p.answer || p.gave_up;
      }))
    finish(now_us);
  return std::exchange(out_, {});
}

std::optional<double> PreflightCheck::value_of(const std::string& name) const {
  const bool bytewise = version_ && (version_->capabilities & (kCapParamBytewise | kCapParamCCast))
                            ? (version_->capabilities & kCapParamBytewise) != 0
                            : autopilot_ == mav::Autopilot::Px4;
  for (const auto& p : params_)
    if (p.name == name && p.answer) return param_number(*p.answer, bytewise);
  return std::nullopt;
}

void PreflightCheck::finish(int64_t now_us) {
  done_ = true;
  items_.clear();
  const double waited_s = static_cast<double>(now_us - started_us_) * 1e-6;
  if (!heard_) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.1f", waited_s);
    const auto& pc = parser_.counters();
    CheckItem it{"heartbeat", Verdict::Fail, std::string("no autopilot HEARTBEAT in ") + buf + " s",
                 "check the endpoint, the wiring (TX to RX, RX to TX, GND), the baud rate, and that the "
                 "autopilot's port speaks MAVLink 2",
                 false};
    if (pc.bad_signature > 0) {
      it.found += " (" + std::to_string(pc.bad_signature) + " frames with a bad signature refused)";
      it.fix = "the autopilot signs with another key: give it this one (aerie-mavlink --setup-signing over USB)";
    } else if (pc.frames > 0) {
      it.found += " (" + std::to_string(pc.frames) + " frames heard, none an autopilot's heartbeat)";
    }
    items_.push_back(it);
    return;
  }
  // The autopilot.
  {
    static const std::pair<int, const char*> types[] = {{1, "fixed wing"}, {2, "quadrotor"}, {3, "coaxial"},
                                                        {4, "helicopter"}, {13, "hexarotor"}, {14, "octorotor"},
                                                        {15, "tricopter"}, {19, "VTOL"}, {29, "dodecarotor"}};
    std::string type = "MAV_TYPE " + std::to_string(heartbeat_.type);
    for (const auto& [k, n] : types)
      if (heartbeat_.type == k) type = n;
    const std::string found = std::string(mav::to_string(autopilot_)) + " " + type + ", system " +
                              std::to_string(ap_sysid_) + " component " + std::to_string(ap_compid_) + ", " +
                              mav::mode_name(autopilot_, heartbeat_.custom_mode);
    CheckItem it{"heartbeat", Verdict::Pass, found, ""};
    if (autopilot_ == mav::Autopilot::Other) {
      it.verdict = Verdict::Fail;
      it.found = "MAV_AUTOPILOT " + std::to_string(heartbeat_.autopilot) + " " + type + ", system " +
                 std::to_string(ap_sysid_);
      it.fix = "Aerie flies with PX4 and ArduPilot (ArduCopter) only";
    } else if (!is_multirotor(heartbeat_.type)) {
      it.verdict = autopilot_ == mav::Autopilot::ArduPilot ? Verdict::Fail : Verdict::Warn;
      it.fix = autopilot_ == mav::Autopilot::ArduPilot ? "Aerie's modes are ArduCopter's: flash ArduCopter"
                                                       : "Aerie flies multirotors; its setpoints are a multirotor's";
    }
    items_.push_back(it);
  }
  // The version.
  {
    CheckItem it{"version", Verdict::Pass, "", ""};
    if (version_) {
      const uint32_t v = version_->flight_sw_version;
      it.found = version_string(v);
      const unsigned major = v >> 24, minor = (v >> 16) & 0xFF;
      if (autopilot_ == mav::Autopilot::Px4 && (major < 1 || (major == 1 && minor < 14))) {
        it.verdict = Verdict::Warn;
        it.fix = "the parameters checked are PX4 1.14's: update PX4";
      } else if (autopilot_ == mav::Autopilot::ArduPilot && major < 4) {
        it.verdict = Verdict::Warn;
        it.fix = "the parameters checked are ArduCopter 4's: update ArduCopter";
      }
    } else {
      it.verdict = Verdict::Warn;
      it.has_value = false;
      it.found = version_refused_ ? "MAV_CMD_REQUEST_MESSAGE answered " + mav::mav_result::to_string(*version_refused_)
                                  : "no AUTOPILOT_VERSION after " + std::to_string(version_sent_) + " requests";
      it.fix = "not needed to fly; the parameter names checked are those of PX4 1.14 / ArduCopter 4";
    }
    items_.push_back(it);
  }
  // Signing.
  const auto& pc = parser_.counters();
  const uint64_t refused = pc.unsigned_refused + pc.bad_signature + pc.replayed_timestamp + pc.stale_timestamp +
                           pc.mavlink1_refused;
  {
    CheckItem it{"signing", Verdict::Pass, "", "", false};
    if (signer_) {
      if (signed_frame_seen_) {
        it.found = "signed both ways (key " + key_fingerprint_ + ")";
      } else {
        it.verdict = Verdict::Fail;
        it.found = pc.bad_signature > 0
                       ? "the autopilot signs with another key (" + std::to_string(pc.bad_signature) + " bad signatures)"
                       : "the autopilot does not sign (" + std::to_string(pc.unsigned_refused) + " unsigned frames refused)";
        it.fix = "give it this key: aerie-mavlink --setup-signing over USB or a wire";
      }
    } else {
      it.verdict = Verdict::Warn;
      it.found = signed_frame_seen_ ? "the autopilot signs, but without --key nothing is verified"
                                    : "unsigned: anyone on the link can command the autopilot";
      it.fix = "aerie-keys generate --out KEY, then aerie-mavlink --key KEY --setup-signing over USB; check with --key KEY";
    }
    items_.push_back(it);
  }
  // The parameters. A signing autopilot asked without a key answers nothing (it refuses
  // unsigned frames), and says so only by its own signed frames.
  const bool unsigned_ignored =
      !signer_ && signed_frame_seen_ && !version_ && !version_refused_ &&
      std::none_of(params_.begin(), params_.end(), [](const ParamRequest& p) { return p.answer.has_value(); });
  const Lookup get = [this](const std::string& n) { return value_of(n); };
  // Asked `attempts` times (else cut short by the check's timeout).
  auto asked_fully = [this](const std::string& n) {
    for (const auto& p : params_)
      if (p.name == n) return p.gave_up;
    return true;
  };
  for (const ParamPlan& plan : plan_for(autopilot_, cfg_)) {
    if (!plan.item) continue;
    const auto v = value_of(plan.name);
    CheckItem it{plan.name, Verdict::Pass, "", ""};
    if (!v) {
      it.has_value = false;
      it.verdict = plan.optional ? Verdict::Warn : Verdict::Fail;
      if (refused > 0 && signer_) {
        it.found = "no answer accepted";
        it.fix = std::to_string(refused) + " frames from the autopilot refused (" +
                 (pc.bad_signature ? "bad signatures" : "unsigned") + "): fix signing first";
      } else if (!asked_fully(plan.name)) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.0f", cfg_.timeout_s);
        it.found = std::string("no answer within the check's ") + buf + " s";
        it.fix = "a slow or lossy link: check it, and run the check again";
      } else if (unsigned_ignored) {
        it.found = "no answer";
        it.fix = "the autopilot signs and ignores unsigned requests: check with --key KEY";
      } else {
        it.found = "not found on this autopilot";
        it.fix = plan.not_found_fix;
      }
      items_.push_back(it);
      continue;
    }
    const bool is_int = [&] {
      for (const auto& p : params_)
        if (p.name == plan.name && p.answer) return !is_real(p.answer->param_type);
      return false;
    }();
    const Judgement j = autopilot_ == mav::Autopilot::Px4 ? judge_px4(plan.name, *v, cfg_, get)
                                                          : judge_ardupilot(plan.name, *v, cfg_, get);
    it.verdict = j.verdict;
    it.found = j.found.empty() ? num(*v, is_int) : j.found;
    it.fix = j.fix;
    items_.push_back(it);
  }
}

}  // namespace aerie::bridge
