#pragma once
// The MAVLink messages Aerie uses, written once in the project's own form (message.hpp): one
// struct per message, named in CamelCase of the XML name, members named exactly as the XML
// fields, defaulting to zero, and a field list in XML order from which CRC_EXTRA, wire order and
// payload lengths are derived at compile time. Definitions: mavlink/mavlink message_definitions/
// v1.0 minimal.xml, standard.xml, common.xml (tests/common/mavlink checks every message against
// them). To add a message: write its struct here in the same form and add it to `Message` below.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <tuple>
#include <variant>

#include "common/mavlink/message.hpp"

namespace aerie::mavlink {

struct Heartbeat {
  static constexpr uint32_t kId = 0;
  static constexpr std::string_view kName = "HEARTBEAT";
  uint8_t type = 0;
  uint8_t autopilot = 0;
  uint8_t base_mode = 0;
  uint32_t custom_mode = 0;
  uint8_t system_status = 0;
  uint8_t mavlink_version = 0;  // XML type uint8_t_mavlink_version
  static constexpr auto fields() {
    return std::tuple{field("type", &Heartbeat::type), field("autopilot", &Heartbeat::autopilot),
                      field("base_mode", &Heartbeat::base_mode), field("custom_mode", &Heartbeat::custom_mode),
                      field("system_status", &Heartbeat::system_status),
                      field("mavlink_version", &Heartbeat::mavlink_version)};
  }
};

struct SysStatus {
  static constexpr uint32_t kId = 1;
  static constexpr std::string_view kName = "SYS_STATUS";
  uint32_t onboard_control_sensors_present = 0;
  uint32_t onboard_control_sensors_enabled = 0;
  uint32_t onboard_control_sensors_health = 0;
  uint16_t load = 0;
  uint16_t voltage_battery = 0;
  int16_t current_battery = 0;
  int8_t battery_remaining = 0;
  uint16_t drop_rate_comm = 0;
  uint16_t errors_comm = 0;
  uint16_t errors_count1 = 0;
  uint16_t errors_count2 = 0;
  uint16_t errors_count3 = 0;
  uint16_t errors_count4 = 0;
  uint32_t onboard_control_sensors_present_extended = 0;
  uint32_t onboard_control_sensors_enabled_extended = 0;
  uint32_t onboard_control_sensors_health_extended = 0;
  static constexpr auto fields() {
    using S = SysStatus;
    return std::tuple{field("onboard_control_sensors_present", &S::onboard_control_sensors_present),
                      field("onboard_control_sensors_enabled", &S::onboard_control_sensors_enabled),
                      field("onboard_control_sensors_health", &S::onboard_control_sensors_health),
                      field("load", &S::load),
                      field("voltage_battery", &S::voltage_battery),
                      field("current_battery", &S::current_battery),
                      field("battery_remaining", &S::battery_remaining),
                      field("drop_rate_comm", &S::drop_rate_comm),
                      field("errors_comm", &S::errors_comm),
                      field("errors_count1", &S::errors_count1),
                      field("errors_count2", &S::errors_count2),
                      field("errors_count3", &S::errors_count3),
                      field("errors_count4", &S::errors_count4),
                      extension("onboard_control_sensors_present_extended", &S::onboard_control_sensors_present_extended),
                      extension("onboard_control_sensors_enabled_extended", &S::onboard_control_sensors_enabled_extended),
                      extension("onboard_control_sensors_health_extended", &S::onboard_control_sensors_health_extended)};
  }
};

struct SystemTime {
  static constexpr uint32_t kId = 2;
  static constexpr std::string_view kName = "SYSTEM_TIME";
  uint64_t time_unix_usec = 0;
  uint32_t time_boot_ms = 0;
  static constexpr auto fields() {
    return std::tuple{field("time_unix_usec", &SystemTime::time_unix_usec),
                      field("time_boot_ms", &SystemTime::time_boot_ms)};
  }
};

struct ParamRequestRead {
  static constexpr uint32_t kId = 20;
  static constexpr std::string_view kName = "PARAM_REQUEST_READ";
  uint8_t target_system = 0;
  uint8_t target_component = 0;
  std::array<char, 16> param_id{};
  int16_t param_index = 0;
  static constexpr auto fields() {
    using S = ParamRequestRead;
    return std::tuple{field("target_system", &S::target_system), field("target_component", &S::target_component),
                      field("param_id", &S::param_id), field("param_index", &S::param_index)};
  }
};

struct ParamValue {
  static constexpr uint32_t kId = 22;
  static constexpr std::string_view kName = "PARAM_VALUE";
  std::array<char, 16> param_id{};
  float param_value = 0;
  uint8_t param_type = 0;
  uint16_t param_count = 0;
  uint16_t param_index = 0;
  static constexpr auto fields() {
    using S = ParamValue;
    return std::tuple{field("param_id", &S::param_id), field("param_value", &S::param_value),
                      field("param_type", &S::param_type), field("param_count", &S::param_count),
                      field("param_index", &S::param_index)};
  }
};

struct ParamSet {
  static constexpr uint32_t kId = 23;
  static constexpr std::string_view kName = "PARAM_SET";
  uint8_t target_system = 0;
  uint8_t target_component = 0;
  std::array<char, 16> param_id{};
  float param_value = 0;
  uint8_t param_type = 0;
  static constexpr auto fields() {
    using S = ParamSet;
    return std::tuple{field("target_system", &S::target_system), field("target_component", &S::target_component),
                      field("param_id", &S::param_id), field("param_value", &S::param_value),
                      field("param_type", &S::param_type)};
  }
};

struct Attitude {
  static constexpr uint32_t kId = 30;
  static constexpr std::string_view kName = "ATTITUDE";
  uint32_t time_boot_ms = 0;
  float roll = 0;
  float pitch = 0;
  float yaw = 0;
  float rollspeed = 0;
  float pitchspeed = 0;
  float yawspeed = 0;
  static constexpr auto fields() {
    using S = Attitude;
    return std::tuple{field("time_boot_ms", &S::time_boot_ms), field("roll", &S::roll), field("pitch", &S::pitch),
                      field("yaw", &S::yaw), field("rollspeed", &S::rollspeed), field("pitchspeed", &S::pitchspeed),
                      field("yawspeed", &S::yawspeed)};
  }
};

struct AttitudeQuaternion {
  static constexpr uint32_t kId = 31;
  static constexpr std::string_view kName = "ATTITUDE_QUATERNION";
  uint32_t time_boot_ms = 0;
  float q1 = 0;
  float q2 = 0;
  float q3 = 0;
  float q4 = 0;
  float rollspeed = 0;
  float pitchspeed = 0;
  float yawspeed = 0;
  std::array<float, 4> repr_offset_q{};
  static constexpr auto fields() {
    using S = AttitudeQuaternion;
    return std::tuple{field("time_boot_ms", &S::time_boot_ms), field("q1", &S::q1), field("q2", &S::q2),
                      field("q3", &S::q3), field("q4", &S::q4), field("rollspeed", &S::rollspeed),
                      field("pitchspeed", &S::pitchspeed), field("yawspeed", &S::yawspeed),
                      extension("repr_offset_q", &S::repr_offset_q)};
  }
};

struct LocalPositionNed {
  static constexpr uint32_t kId = 32;
  static constexpr std::string_view kName = "LOCAL_POSITION_NED";
  uint32_t time_boot_ms = 0;
  float x = 0;
  float y = 0;
  float z = 0;
  float vx = 0;
  float vy = 0;
  float vz = 0;
  static constexpr auto fields() {
    using S = LocalPositionNed;
    return std::tuple{field("time_boot_ms", &S::time_boot_ms), field("x", &S::x), field("y", &S::y),
                      field("z", &S::z), field("vx", &S::vx), field("vy", &S::vy), field("vz", &S::vz)};
  }
};

struct SetGpsGlobalOrigin {
  static constexpr uint32_t kId = 48;
  static constexpr std::string_view kName = "SET_GPS_GLOBAL_ORIGIN";
  uint8_t target_system = 0;
  int32_t latitude = 0;
  int32_t longitude = 0;
  int32_t altitude = 0;
  uint64_t time_usec = 0;
  static constexpr auto fields() {
    using S = SetGpsGlobalOrigin;
    return std::tuple{field("target_system", &S::target_system), field("latitude", &S::latitude),
                      field("longitude", &S::longitude), field("altitude", &S::altitude),
                      extension("time_usec", &S::time_usec)};
  }
};

struct GpsGlobalOrigin {
  static constexpr uint32_t kId = 49;
  static constexpr std::string_view kName = "GPS_GLOBAL_ORIGIN";
  int32_t latitude = 0;
  int32_t longitude = 0;
  int32_t altitude = 0;
  uint64_t time_usec = 0;
  static constexpr auto fields() {
    using S = GpsGlobalOrigin;
    return std::tuple{field("latitude", &S::latitude), field("longitude", &S::longitude),
                      field("altitude", &S::altitude), extension("time_usec", &S::time_usec)};
  }
};

struct CommandLong {
  static constexpr uint32_t kId = 76;
  static constexpr std::string_view kName = "COMMAND_LONG";
  uint8_t target_system = 0;
  uint8_t target_component = 0;
  uint16_t command = 0;
  uint8_t confirmation = 0;
  float param1 = 0;
  float param2 = 0;
  float param3 = 0;
  float param4 = 0;
  float param5 = 0;
  float param6 = 0;
  float param7 = 0;
  static constexpr auto fields() {
    using S = CommandLong;
    return std::tuple{field("target_system", &S::target_system), field("target_component", &S::target_component),
                      field("command", &S::command), field("confirmation", &S::confirmation),
                      field("param1", &S::param1), field("param2", &S::param2), field("param3", &S::param3),
                      field("param4", &S::param4), field("param5", &S::param5), field("param6", &S::param6),
                      field("param7", &S::param7)};
  }
};

struct CommandAck {
  static constexpr uint32_t kId = 77;
  static constexpr std::string_view kName = "COMMAND_ACK";
  uint16_t command = 0;
  uint8_t result = 0;
  uint8_t progress = 0;
  int32_t result_param2 = 0;
  uint8_t target_system = 0;
  uint8_t target_component = 0;
  static constexpr auto fields() {
    using S = CommandAck;
    return std::tuple{field("command", &S::command), field("result", &S::result),
                      extension("progress", &S::progress), extension("result_param2", &S::result_param2),
                      extension("target_system", &S::target_system),
                      extension("target_component", &S::target_component)};
  }
};

struct SetPositionTargetLocalNed {
  static constexpr uint32_t kId = 84;
  static constexpr std::string_view kName = "SET_POSITION_TARGET_LOCAL_NED";
  uint32_t time_boot_ms = 0;
  uint8_t target_system = 0;
  uint8_t target_component = 0;
  uint8_t coordinate_frame = 0;
  uint16_t type_mask = 0;
  float x = 0;
  float y = 0;
  float z = 0;
  float vx = 0;
  float vy = 0;
  float vz = 0;
  float afx = 0;
  float afy = 0;
  float afz = 0;
  float yaw = 0;
  float yaw_rate = 0;
  static constexpr auto fields() {
    using S = SetPositionTargetLocalNed;
    return std::tuple{field("time_boot_ms", &S::time_boot_ms), field("target_system", &S::target_system),
                      field("target_component", &S::target_component),
                      field("coordinate_frame", &S::coordinate_frame), field("type_mask", &S::type_mask),
                      field("x", &S::x), field("y", &S::y), field("z", &S::z), field("vx", &S::vx),
                      field("vy", &S::vy), field("vz", &S::vz), field("afx", &S::afx), field("afy", &S::afy),
                      field("afz", &S::afz), field("yaw", &S::yaw), field("yaw_rate", &S::yaw_rate)};
  }
};

struct PositionTargetLocalNed {
  static constexpr uint32_t kId = 85;
  static constexpr std::string_view kName = "POSITION_TARGET_LOCAL_NED";
  uint32_t time_boot_ms = 0;
  uint8_t coordinate_frame = 0;
  uint16_t type_mask = 0;
  float x = 0;
  float y = 0;
  float z = 0;
  float vx = 0;
  float vy = 0;
  float vz = 0;
  float afx = 0;
  float afy = 0;
  float afz = 0;
  float yaw = 0;
  float yaw_rate = 0;
  static constexpr auto fields() {
    using S = PositionTargetLocalNed;
    return std::tuple{field("time_boot_ms", &S::time_boot_ms), field("coordinate_frame", &S::coordinate_frame),
                      field("type_mask", &S::type_mask), field("x", &S::x), field("y", &S::y), field("z", &S::z),
                      field("vx", &S::vx), field("vy", &S::vy), field("vz", &S::vz), field("afx", &S::afx),
                      field("afy", &S::afy), field("afz", &S::afz), field("yaw", &S::yaw),
                      field("yaw_rate", &S::yaw_rate)};
  }
};

struct VisionPositionEstimate {
  static constexpr uint32_t kId = 102;
  static constexpr std::string_view kName = "VISION_POSITION_ESTIMATE";
  uint64_t usec = 0;
  float x = 0;
  float y = 0;
  float z = 0;
  float roll = 0;
  float pitch = 0;
  float yaw = 0;
  std::array<float, 21> covariance{};
  uint8_t reset_counter = 0;
  static constexpr auto fields() {
    using S = VisionPositionEstimate;
    return std::tuple{field("usec", &S::usec), field("x", &S::x), field("y", &S::y), field("z", &S::z),
                      field("roll", &S::roll), field("pitch", &S::pitch), field("yaw", &S::yaw),
                      extension("covariance", &S::covariance), extension("reset_counter", &S::reset_counter)};
  }
};

struct HighresImu {
  static constexpr uint32_t kId = 105;
  static constexpr std::string_view kName = "HIGHRES_IMU";
  uint64_t time_usec = 0;
  float xacc = 0;
  float yacc = 0;
  float zacc = 0;
  float xgyro = 0;
  float ygyro = 0;
  float zgyro = 0;
  float xmag = 0;
  float ymag = 0;
  float zmag = 0;
  float abs_pressure = 0;
  float diff_pressure = 0;
  float pressure_alt = 0;
  float temperature = 0;
  uint16_t fields_updated = 0;
  uint8_t id = 0;
  static constexpr auto fields() {
    using S = HighresImu;
    return std::tuple{field("time_usec", &S::time_usec), field("xacc", &S::xacc), field("yacc", &S::yacc),
                      field("zacc", &S::zacc), field("xgyro", &S::xgyro), field("ygyro", &S::ygyro),
                      field("zgyro", &S::zgyro), field("xmag", &S::xmag), field("ymag", &S::ymag),
                      field("zmag", &S::zmag), field("abs_pressure", &S::abs_pressure),
                      field("diff_pressure", &S::diff_pressure), field("pressure_alt", &S::pressure_alt),
                      field("temperature", &S::temperature), field("fields_updated", &S::fields_updated),
                      extension("id", &S::id)};
  }
};

struct RadioStatus {
  static constexpr uint32_t kId = 109;
  static constexpr std::string_view kName = "RADIO_STATUS";
  uint8_t rssi = 0;
  uint8_t remrssi = 0;
  uint8_t txbuf = 0;
  uint8_t noise = 0;
  uint8_t remnoise = 0;
  uint16_t rxerrors = 0;
  uint16_t fixed = 0;
  static constexpr auto fields() {
    using S = RadioStatus;
    return std::tuple{field("rssi", &S::rssi), field("remrssi", &S::remrssi), field("txbuf", &S::txbuf),
                      field("noise", &S::noise), field("remnoise", &S::remnoise), field("rxerrors", &S::rxerrors),
                      field("fixed", &S::fixed)};
  }
};

struct Timesync {
  static constexpr uint32_t kId = 111;
  static constexpr std::string_view kName = "TIMESYNC";
  int64_t tc1 = 0;
  int64_t ts1 = 0;
  uint8_t target_system = 0;
  uint8_t target_component = 0;
  static constexpr auto fields() {
    using S = Timesync;
    return std::tuple{field("tc1", &S::tc1), field("ts1", &S::ts1), extension("target_system", &S::target_system),
                      extension("target_component", &S::target_component)};
  }
};

struct DistanceSensor {
  static constexpr uint32_t kId = 132;
  static constexpr std::string_view kName = "DISTANCE_SENSOR";
  uint32_t time_boot_ms = 0;
  uint16_t min_distance = 0;
  uint16_t max_distance = 0;
  uint16_t current_distance = 0;
  uint8_t type = 0;
  uint8_t id = 0;
  uint8_t orientation = 0;
  uint8_t covariance = 0;
  float horizontal_fov = 0;
  float vertical_fov = 0;
  std::array<float, 4> quaternion{};
  uint8_t signal_quality = 0;
  static constexpr auto fields() {
    using S = DistanceSensor;
    return std::tuple{field("time_boot_ms", &S::time_boot_ms), field("min_distance", &S::min_distance),
                      field("max_distance", &S::max_distance), field("current_distance", &S::current_distance),
                      field("type", &S::type), field("id", &S::id), field("orientation", &S::orientation),
                      field("covariance", &S::covariance), extension("horizontal_fov", &S::horizontal_fov),
                      extension("vertical_fov", &S::vertical_fov), extension("quaternion", &S::quaternion),
                      extension("signal_quality", &S::signal_quality)};
  }
};

struct BatteryStatus {
  static constexpr uint32_t kId = 147;
  static constexpr std::string_view kName = "BATTERY_STATUS";
  uint8_t id = 0;
  uint8_t battery_function = 0;
  uint8_t type = 0;
  int16_t temperature = 0;
  std::array<uint16_t, 10> voltages{};
  int16_t current_battery = 0;
  int32_t current_consumed = 0;
  int32_t energy_consumed = 0;
  int8_t battery_remaining = 0;
  int32_t time_remaining = 0;
  uint8_t charge_state = 0;
  std::array<uint16_t, 4> voltages_ext{};
  uint8_t mode = 0;
  uint32_t fault_bitmask = 0;
  static constexpr auto fields() {
    using S = BatteryStatus;
    return std::tuple{field("id", &S::id), field("battery_function", &S::battery_function), field("type", &S::type),
                      field("temperature", &S::temperature), field("voltages", &S::voltages),
                      field("current_battery", &S::current_battery), field("current_consumed", &S::current_consumed),
                      field("energy_consumed", &S::energy_consumed),
                      field("battery_remaining", &S::battery_remaining),
                      extension("time_remaining", &S::time_remaining), extension("charge_state", &S::charge_state),
                      extension("voltages_ext", &S::voltages_ext), extension("mode", &S::mode),
                      extension("fault_bitmask", &S::fault_bitmask)};
  }
};

// In standard.xml.
struct AutopilotVersion {
  static constexpr uint32_t kId = 148;
  static constexpr std::string_view kName = "AUTOPILOT_VERSION";
  uint64_t capabilities = 0;
  uint32_t flight_sw_version = 0;
  uint32_t middleware_sw_version = 0;
  uint32_t os_sw_version = 0;
  uint32_t board_version = 0;
  std::array<uint8_t, 8> flight_custom_version{};
  std::array<uint8_t, 8> middleware_custom_version{};
  std::array<uint8_t, 8> os_custom_version{};
  uint16_t vendor_id = 0;
  uint16_t product_id = 0;
  uint64_t uid = 0;
  std::array<uint8_t, 18> uid2{};
  static constexpr auto fields() {
    using S = AutopilotVersion;
    return std::tuple{field("capabilities", &S::capabilities), field("flight_sw_version", &S::flight_sw_version),
                      field("middleware_sw_version", &S::middleware_sw_version),
                      field("os_sw_version", &S::os_sw_version), field("board_version", &S::board_version),
                      field("flight_custom_version", &S::flight_custom_version),
                      field("middleware_custom_version", &S::middleware_custom_version),
                      field("os_custom_version", &S::os_custom_version), field("vendor_id", &S::vendor_id),
                      field("product_id", &S::product_id), field("uid", &S::uid), extension("uid2", &S::uid2)};
  }
};

struct LandingTarget {
  static constexpr uint32_t kId = 149;
  static constexpr std::string_view kName = "LANDING_TARGET";
  uint64_t time_usec = 0;
  uint8_t target_num = 0;
  uint8_t frame = 0;
  float angle_x = 0;
  float angle_y = 0;
  float distance = 0;
  float size_x = 0;
  float size_y = 0;
  float x = 0;
  float y = 0;
  float z = 0;
  std::array<float, 4> q{};
  uint8_t type = 0;
  uint8_t position_valid = 0;
  static constexpr auto fields() {
    using S = LandingTarget;
    return std::tuple{field("time_usec", &S::time_usec), field("target_num", &S::target_num),
                      field("frame", &S::frame), field("angle_x", &S::angle_x), field("angle_y", &S::angle_y),
                      field("distance", &S::distance), field("size_x", &S::size_x), field("size_y", &S::size_y),
                      extension("x", &S::x), extension("y", &S::y), extension("z", &S::z), extension("q", &S::q),
                      extension("type", &S::type), extension("position_valid", &S::position_valid)};
  }
};

struct MessageInterval {
  static constexpr uint32_t kId = 244;
  static constexpr std::string_view kName = "MESSAGE_INTERVAL";
  uint16_t message_id = 0;
  int32_t interval_us = 0;
  static constexpr auto fields() {
    return std::tuple{field("message_id", &MessageInterval::message_id),
                      field("interval_us", &MessageInterval::interval_us)};
  }
};

struct EstimatorStatus {
  static constexpr uint32_t kId = 230;
  static constexpr std::string_view kName = "ESTIMATOR_STATUS";
  uint64_t time_usec = 0;
  uint16_t flags = 0;  // ESTIMATOR_STATUS_FLAGS
  float vel_ratio = 0;
  float pos_horiz_ratio = 0;
  float pos_vert_ratio = 0;
  float mag_ratio = 0;
  float hagl_ratio = 0;
  float tas_ratio = 0;
  float pos_horiz_accuracy = 0;
  float pos_vert_accuracy = 0;
  static constexpr auto fields() {
    using S = EstimatorStatus;
    return std::tuple{field("time_usec", &S::time_usec), field("flags", &S::flags), field("vel_ratio", &S::vel_ratio),
                      field("pos_horiz_ratio", &S::pos_horiz_ratio), field("pos_vert_ratio", &S::pos_vert_ratio),
                      field("mag_ratio", &S::mag_ratio), field("hagl_ratio", &S::hagl_ratio),
                      field("tas_ratio", &S::tas_ratio), field("pos_horiz_accuracy", &S::pos_horiz_accuracy),
                      field("pos_vert_accuracy", &S::pos_vert_accuracy)};
  }
};

struct ExtendedSysState {
  static constexpr uint32_t kId = 245;
  static constexpr std::string_view kName = "EXTENDED_SYS_STATE";
  uint8_t vtol_state = 0;
  uint8_t landed_state = 0;
  static constexpr auto fields() {
    return std::tuple{field("vtol_state", &ExtendedSysState::vtol_state),
                      field("landed_state", &ExtendedSysState::landed_state)};
  }
};

struct Statustext {
  static constexpr uint32_t kId = 253;
  static constexpr std::string_view kName = "STATUSTEXT";
  uint8_t severity = 0;
  std::array<char, 50> text{};  // not NUL-terminated when all 50 are used
  uint16_t id = 0;
  uint8_t chunk_seq = 0;
  static constexpr auto fields() {
    return std::tuple{field("severity", &Statustext::severity), field("text", &Statustext::text),
                      extension("id", &Statustext::id), extension("chunk_seq", &Statustext::chunk_seq)};
  }
};

struct SetupSigning {
  static constexpr uint32_t kId = 256;
  static constexpr std::string_view kName = "SETUP_SIGNING";
  uint8_t target_system = 0;
  uint8_t target_component = 0;
  std::array<uint8_t, 32> secret_key{};
  uint64_t initial_timestamp = 0;
  static constexpr auto fields() {
    using S = SetupSigning;
    return std::tuple{field("target_system", &S::target_system), field("target_component", &S::target_component),
                      field("secret_key", &S::secret_key), field("initial_timestamp", &S::initial_timestamp)};
  }
};

struct Odometry {
  static constexpr uint32_t kId = 331;
  static constexpr std::string_view kName = "ODOMETRY";
  uint64_t time_usec = 0;
  uint8_t frame_id = 0;
  uint8_t child_frame_id = 0;
  float x = 0;
  float y = 0;
  float z = 0;
  std::array<float, 4> q{};
  float vx = 0;
  float vy = 0;
  float vz = 0;
  float rollspeed = 0;
  float pitchspeed = 0;
  float yawspeed = 0;
  std::array<float, 21> pose_covariance{};
  std::array<float, 21> velocity_covariance{};
  uint8_t reset_counter = 0;
  uint8_t estimator_type = 0;
  int8_t quality = 0;
  static constexpr auto fields() {
    using S = Odometry;
    return std::tuple{field("time_usec", &S::time_usec), field("frame_id", &S::frame_id),
                      field("child_frame_id", &S::child_frame_id), field("x", &S::x), field("y", &S::y),
                      field("z", &S::z), field("q", &S::q), field("vx", &S::vx), field("vy", &S::vy),
                      field("vz", &S::vz), field("rollspeed", &S::rollspeed), field("pitchspeed", &S::pitchspeed),
                      field("yawspeed", &S::yawspeed), field("pose_covariance", &S::pose_covariance),
                      field("velocity_covariance", &S::velocity_covariance),
                      extension("reset_counter", &S::reset_counter), extension("estimator_type", &S::estimator_type),
                      extension("quality", &S::quality)};
  }
};

// Every catalogue message (AUTOPILOT_VERSION_REQUEST does not exist in the definitions).
using Message = std::variant<Heartbeat, SysStatus, SystemTime, ParamRequestRead, ParamValue, ParamSet, Attitude,
                             AttitudeQuaternion, LocalPositionNed, SetGpsGlobalOrigin, GpsGlobalOrigin, CommandLong,
                             CommandAck, SetPositionTargetLocalNed, PositionTargetLocalNed, VisionPositionEstimate,
                             HighresImu, RadioStatus, Timesync, DistanceSensor, BatteryStatus, AutopilotVersion,
                             LandingTarget, MessageInterval, EstimatorStatus, ExtendedSysState, Statustext, SetupSigning,
                             Odometry>;

// What a parser needs to check a frame of a message id.
struct MessageInfo {
  uint32_t id;
  std::string_view name;
  uint8_t crc_extra;
  uint8_t min_length;
  uint8_t max_length;
};

namespace detail {
template <class V>
struct CatalogueTable;
template <class... M>
struct CatalogueTable<std::variant<M...>> {
  static constexpr std::array<MessageInfo, sizeof...(M)> kInfos{
      MessageInfo{M::kId, M::kName, crc_extra<M>(), static_cast<uint8_t>(min_length<M>()),
                  static_cast<uint8_t>(max_length<M>())}...};
};
}  // namespace detail

// Every catalogue message's id, name, CRC_EXTRA and payload lengths, in `Message` order.
inline constexpr auto kCatalogue = detail::CatalogueTable<Message>::kInfos;

// The catalogue entry of `id`, or nullptr when Aerie does not know the message.
constexpr const MessageInfo* find_message(uint32_t id) {
  for (const MessageInfo& info : kCatalogue)
    if (info.id == id) return &info;
  return nullptr;
}

static_assert(crc_extra<Heartbeat>() == 50 && min_length<Heartbeat>() == 9);
static_assert(crc_extra<SetPositionTargetLocalNed>() == 143 && max_length<SetPositionTargetLocalNed>() == 53);
static_assert(crc_extra<Odometry>() == 91 && min_length<Odometry>() == 230 && max_length<Odometry>() == 233);

// --- enum constants Aerie uses (common.xml / minimal.xml) -----------------------------------
namespace mav_cmd {
inline constexpr uint16_t kNavLand = 21;
inline constexpr uint16_t kNavTakeoff = 22;
inline constexpr uint16_t kDoSetMode = 176;
inline constexpr uint16_t kComponentArmDisarm = 400;
inline constexpr uint16_t kSetMessageInterval = 511;
inline constexpr uint16_t kRequestMessage = 512;
inline constexpr uint16_t kRequestAutopilotCapabilities = 520;
}  // namespace mav_cmd

namespace mav_result {
inline constexpr uint8_t kAccepted = 0;
inline constexpr uint8_t kTemporarilyRejected = 1;
inline constexpr uint8_t kDenied = 2;
inline constexpr uint8_t kUnsupported = 3;
inline constexpr uint8_t kFailed = 4;
inline constexpr uint8_t kInProgress = 5;
inline constexpr uint8_t kCancelled = 6;
inline constexpr uint8_t kCommandLongOnly = 7;
inline constexpr uint8_t kCommandIntOnly = 8;
inline constexpr uint8_t kCommandUnsupportedMavFrame = 9;
inline constexpr uint8_t kNotInControl = 10;
// "ACCEPTED", "TEMPORARILY_REJECTED", "DENIED", ...; "UNKNOWN (n)" for a value not in MAV_RESULT.
std::string to_string(uint8_t result);
}  // namespace mav_result

namespace mav_frame {
inline constexpr uint8_t kLocalNed = 1;
inline constexpr uint8_t kBodyNed = 8;
inline constexpr uint8_t kBodyFrd = 12;
inline constexpr uint8_t kLocalFrd = 20;
}  // namespace mav_frame

namespace mav_type {
inline constexpr uint8_t kGeneric = 0;
inline constexpr uint8_t kFixedWing = 1;
inline constexpr uint8_t kQuadrotor = 2;
inline constexpr uint8_t kGcs = 6;
inline constexpr uint8_t kHexarotor = 13;
inline constexpr uint8_t kOctorotor = 14;
inline constexpr uint8_t kOnboardController = 18;
}  // namespace mav_type

namespace mav_autopilot {
inline constexpr uint8_t kGeneric = 0;
inline constexpr uint8_t kArdupilotmega = 3;
inline constexpr uint8_t kInvalid = 8;  // not an autopilot (a GCS, a companion computer)
inline constexpr uint8_t kPx4 = 12;
}  // namespace mav_autopilot

namespace mav_state {
inline constexpr uint8_t kUninit = 0;
inline constexpr uint8_t kBoot = 1;
inline constexpr uint8_t kCalibrating = 2;
inline constexpr uint8_t kStandby = 3;
inline constexpr uint8_t kActive = 4;
inline constexpr uint8_t kCritical = 5;
inline constexpr uint8_t kEmergency = 6;
inline constexpr uint8_t kPoweroff = 7;
inline constexpr uint8_t kFlightTermination = 8;
// "UNINIT", "BOOT", ..., "FLIGHT_TERMINATION"; "UNKNOWN (n)" for a value not in MAV_STATE.
std::string to_string(uint8_t state);
}  // namespace mav_state

namespace mav_mode_flag {
inline constexpr uint8_t kCustomModeEnabled = 1;
inline constexpr uint8_t kTestEnabled = 2;
inline constexpr uint8_t kAutoEnabled = 4;
inline constexpr uint8_t kGuidedEnabled = 8;
inline constexpr uint8_t kStabilizeEnabled = 16;
inline constexpr uint8_t kHilEnabled = 32;
inline constexpr uint8_t kManualInputEnabled = 64;
inline constexpr uint8_t kSafetyArmed = 128;
}  // namespace mav_mode_flag

namespace mav_severity {
inline constexpr uint8_t kEmergency = 0;
inline constexpr uint8_t kAlert = 1;
inline constexpr uint8_t kCritical = 2;
inline constexpr uint8_t kError = 3;
inline constexpr uint8_t kWarning = 4;
inline constexpr uint8_t kNotice = 5;
inline constexpr uint8_t kInfo = 6;
inline constexpr uint8_t kDebug = 7;
}  // namespace mav_severity

namespace mav_landed_state {
inline constexpr uint8_t kUndefined = 0;
inline constexpr uint8_t kOnGround = 1;
inline constexpr uint8_t kInAir = 2;
inline constexpr uint8_t kTakeoff = 3;
inline constexpr uint8_t kLanding = 4;
}  // namespace mav_landed_state

namespace mav_component {
inline constexpr uint8_t kAll = 0;
inline constexpr uint8_t kAutopilot1 = 1;
inline constexpr uint8_t kOnboardComputer = 191;
}  // namespace mav_component

namespace mav_estimator_type {
inline constexpr uint8_t kVision = 2;
inline constexpr uint8_t kVio = 3;
}  // namespace mav_estimator_type

// POSITION_TARGET_TYPEMASK: a set bit means "ignore this field".
namespace type_mask {
inline constexpr uint16_t kXIgnore = 1;
inline constexpr uint16_t kYIgnore = 2;
inline constexpr uint16_t kZIgnore = 4;
inline constexpr uint16_t kVxIgnore = 8;
inline constexpr uint16_t kVyIgnore = 16;
inline constexpr uint16_t kVzIgnore = 32;
inline constexpr uint16_t kAxIgnore = 64;
inline constexpr uint16_t kAyIgnore = 128;
inline constexpr uint16_t kAzIgnore = 256;
inline constexpr uint16_t kForceSet = 512;
inline constexpr uint16_t kYawIgnore = 1024;
inline constexpr uint16_t kYawRateIgnore = 2048;
inline constexpr uint16_t kPositionIgnore = kXIgnore | kYIgnore | kZIgnore;
inline constexpr uint16_t kAccelerationIgnore = kAxIgnore | kAyIgnore | kAzIgnore;
// Velocity and yaw rate only (PX4 offboard velocity control).
inline constexpr uint16_t kVelocityYawRate = kPositionIgnore | kAccelerationIgnore | kYawIgnore;
static_assert(kVelocityYawRate == 0x05C7);
}  // namespace type_mask


}  // namespace aerie::mavlink
