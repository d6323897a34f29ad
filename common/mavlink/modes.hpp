#pragma once
// The flight modes of the two autopilots Aerie flies with, as HEARTBEAT.custom_mode carries
// them and MAV_CMD_DO_SET_MODE asks for them: one table each, used by the bridge (to name the
// mode and to ask for one) and by the simulator's autopilot (to report its own).
//
//  * PX4 (px4_custom_mode.h): custom_mode = main_mode << 16 | sub_mode << 24; DO_SET_MODE
//    param1 = MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, param2 = main mode, param3 = sub mode.
//  * ArduCopter (Copter's mode numbers, `enum class Mode::Number`): custom_mode = the number;
//    DO_SET_MODE param1 = MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, param2 = the number.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace aerie::mavlink {

enum class Autopilot { Other, Px4, ArduPilot };
// From HEARTBEAT.autopilot (MAV_AUTOPILOT_PX4 12, MAV_AUTOPILOT_ARDUPILOTMEGA 3).
Autopilot autopilot_of(uint8_t mav_autopilot);
const char* to_string(Autopilot a);  // "PX4", "ArduPilot", "other"

namespace px4 {
enum MainMode : uint8_t { kManual = 1, kAltctl = 2, kPosctl = 3, kAuto = 4, kAcro = 5, kOffboard = 6, kStabilized = 7 };
enum AutoSubMode : uint8_t {
  kAutoReady = 1, kAutoTakeoff = 2, kAutoLoiter = 3, kAutoMission = 4, kAutoRtl = 5, kAutoLand = 6,
  kAutoFollowTarget = 8, kAutoPrecland = 9
};
constexpr uint32_t custom_mode(uint8_t main, uint8_t sub = 0) {
  return static_cast<uint32_t>(main) << 16 | static_cast<uint32_t>(sub) << 24;
}
}  // namespace px4

namespace copter {
enum Mode : uint8_t {
  kStabilize = 0, kAcro = 1, kAltHold = 2, kAuto = 3, kGuided = 4, kLoiter = 5, kRtl = 6, kCircle = 7,
  kLand = 9, kDrift = 11, kSport = 13, kPoshold = 16, kBrake = 17, kThrow = 18, kGuidedNoGps = 20, kSmartRtl = 21
};
}  // namespace copter

// "OFFBOARD", "AUTO.PRECLAND", "POSCTL", "GUIDED", "LAND", ...; "mode 0x00070000" when unknown.
std::string mode_name(Autopilot a, uint32_t custom_mode);
// The custom_mode of a mode named as mode_name() names it; nullopt when the autopilot has no such mode.
std::optional<uint32_t> custom_mode_of(Autopilot a, std::string_view name);

// MAV_CMD_DO_SET_MODE's parameters for a custom_mode.
struct SetModeParams {
  float param1 = 0, param2 = 0, param3 = 0;
};
SetModeParams set_mode_params(Autopilot a, uint32_t custom_mode);
// The custom_mode a DO_SET_MODE asks for (the inverse of set_mode_params).
uint32_t custom_mode_from_params(Autopilot a, float param2, float param3);

// The mode in which the autopilot flies a companion's velocity setpoints: PX4 OFFBOARD, ArduCopter GUIDED.
uint32_t companion_mode(Autopilot a);
bool in_companion_mode(Autopilot a, uint32_t custom_mode);

}  // namespace aerie::mavlink
