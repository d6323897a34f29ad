#include "common/mavlink/modes.hpp"

#include <array>
#include <cstdio>
#include <utility>

#include "common/mavlink/catalogue.hpp"

namespace aerie::mavlink {

namespace {

struct Named {
  uint32_t custom_mode;
  std::string_view name;
};

constexpr std::array kPx4Modes{
    Named{px4::custom_mode(px4::kManual), "MANUAL"},
    Named{px4::custom_mode(px4::kAltctl), "ALTCTL"},
    Named{px4::custom_mode(px4::kPosctl), "POSCTL"},
    Named{px4::custom_mode(px4::kAcro), "ACRO"},
    Named{px4::custom_mode(px4::kOffboard), "OFFBOARD"},
    Named{px4::custom_mode(px4::kStabilized), "STABILIZED"},
    Named{px4::custom_mode(px4::kAuto, px4::kAutoReady), "AUTO.READY"},
    Named{px4::custom_mode(px4::kAuto, px4::kAutoTakeoff), "AUTO.TAKEOFF"},
    Named{px4::custom_mode(px4::kAuto, px4::kAutoLoiter), "AUTO.LOITER"},
    Named{px4::custom_mode(px4::kAuto, px4::kAutoMission), "AUTO.MISSION"},
    Named{px4::custom_mode(px4::kAuto, px4::kAutoRtl), "AUTO.RTL"},
    Named{px4::custom_mode(px4::kAuto, px4::kAutoLand), "AUTO.LAND"},
    Named{px4::custom_mode(px4::kAuto, px4::kAutoFollowTarget), "AUTO.FOLLOW_TARGET"},
    Named{px4::custom_mode(px4::kAuto, px4::kAutoPrecland), "AUTO.PRECLAND"},
};

constexpr std::array kCopterModes{
    Named{copter::kStabilize, "STABILIZE"}, Named{copter::kAcro, "ACRO"},     Named{copter::kAltHold, "ALT_HOLD"},
    Named{copter::kAuto, "AUTO"},           Named{copter::kGuided, "GUIDED"}, Named{copter::kLoiter, "LOITER"},
    Named{copter::kRtl, "RTL"},             Named{copter::kCircle, "CIRCLE"}, Named{copter::kLand, "LAND"},
    Named{copter::kDrift, "DRIFT"},         Named{copter::kSport, "SPORT"},   Named{copter::kPoshold, "POSHOLD"},
    Named{copter::kBrake, "BRAKE"},         Named{copter::kThrow, "THROW"},   Named{copter::kGuidedNoGps, "GUIDED_NOGPS"},
    Named{copter::kSmartRtl, "SMART_RTL"},
};

template <size_t N>
const Named* find_mode(const std::array<Named, N>& table, uint32_t custom_mode) {
  for (const Named& m : table)
    if (m.custom_mode == custom_mode) return &m;
  return nullptr;
}
template <size_t N>
const Named* find_mode(const std::array<Named, N>& table, std::string_view name) {
  for (const Named& m : table)
    if (m.name == name) return &m;
  return nullptr;
}

}  // namespace

Autopilot autopilot_of(uint8_t mav_autopilot) {
  if (mav_autopilot == mav_autopilot::kPx4) return Autopilot::Px4;
  if (mav_autopilot == mav_autopilot::kArdupilotmega) return Autopilot::ArduPilot;
  return Autopilot::Other;
}

const char* to_string(Autopilot a) {
  switch (a) {
    case Autopilot::Px4: return "PX4";
    case Autopilot::ArduPilot: return "ArduPilot";
    default: return "other";
  }
}

std::string mode_name(Autopilot a, uint32_t custom_mode) {
  const Named* m = a == Autopilot::Px4         ? find_mode(kPx4Modes, custom_mode)
                   : a == Autopilot::ArduPilot ? find_mode(kCopterModes, custom_mode)
                                               : nullptr;
  if (m) return std::string(m->name);
  char buf[32];
  std::snprintf(buf, sizeof buf, "mode 0x%08x", static_cast<unsigned>(custom_mode));
  return buf;
}

std::optional<uint32_t> custom_mode_of(Autopilot a, std::string_view name) {
  const Named* m = a == Autopilot::Px4         ? find_mode(kPx4Modes, name)
                   : a == Autopilot::ArduPilot ? find_mode(kCopterModes, name)
                                               : nullptr;
  if (!m) return std::nullopt;
  return m->custom_mode;
}

SetModeParams set_mode_params(Autopilot a, uint32_t custom_mode) {
  SetModeParams p;
  p.param1 = mav_mode_flag::kCustomModeEnabled;
  if (a == Autopilot::Px4) {
    p.param2 = static_cast<float>((custom_mode >> 16) & 0xFF);
    p.param3 = static_cast<float>((custom_mode >> 24) & 0xFF);
  } else {
    p.param2 = static_cast<float>(custom_mode);
  }
  return p;
}

uint32_t custom_mode_from_params(Autopilot a, float param2, float param3) {
  if (a == Autopilot::Px4) return px4::custom_mode(static_cast<uint8_t>(param2), static_cast<uint8_t>(param3));
  return static_cast<uint32_t>(param2);
}

uint32_t companion_mode(Autopilot a) {
  return a == Autopilot::ArduPilot ? static_cast<uint32_t>(copter::kGuided) : px4::custom_mode(px4::kOffboard);
}

bool in_companion_mode(Autopilot a, uint32_t custom_mode) {
  if (a == Autopilot::Px4) return ((custom_mode >> 16) & 0xFF) == px4::kOffboard;
  return a == Autopilot::ArduPilot && custom_mode == copter::kGuided;
}

}  // namespace aerie::mavlink
