#include "common/mavlink/catalogue.hpp"

#include <array>
#include <string>

namespace aerie::mavlink {

namespace {
template <size_t N>
std::string name_of(const std::array<const char*, N>& names, uint8_t value) {
  if (value < N) return names[value];
  return "UNKNOWN (" + std::to_string(value) + ")";
}
}  // namespace

std::string mav_result::to_string(uint8_t result) {
  static constexpr std::array<const char*, 11> kNames{
      "ACCEPTED", "TEMPORARILY_REJECTED", "DENIED",           "UNSUPPORTED",
      "FAILED",   "IN_PROGRESS",          "CANCELLED",        "COMMAND_LONG_ONLY",
      "COMMAND_INT_ONLY", "COMMAND_UNSUPPORTED_MAV_FRAME", "NOT_IN_CONTROL"};
  return name_of(kNames, result);
}

std::string mav_state::to_string(uint8_t state) {
  static constexpr std::array<const char*, 9> kNames{"UNINIT",   "BOOT",      "CALIBRATING",
                                                     "STANDBY",  "ACTIVE",    "CRITICAL",
                                                     "EMERGENCY", "POWEROFF", "FLIGHT_TERMINATION"};
  return name_of(kNames, state);
}

}  // namespace aerie::mavlink
