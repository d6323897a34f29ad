#pragma once
// What the fuzz targets of fuzz/targets/ share (docs/fuzz.md): the one rule for exceptions,
// inputs as text or as a temporary file, and the record format of the node targets, which
// publish a sequence of messages on a node's channels over an in-process bus (memq://).
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/bus/bus.hpp"

namespace aerie::fuzz {

// Runs `f` with the project's documented refusal of a bad input, std::invalid_argument or
// std::runtime_error (and what derives from them: YAML::Exception, procman::PmdError, ...),
// as the expected answer. Any other exception escapes, and libFuzzer reports it as a crash:
// a reader that throws std::out_of_range, std::bad_alloc or cv::Exception has not checked
// its input.
template <typename F>
void refusal_ok(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument&) {
  } catch (const std::runtime_error&) {
  }
}

// Logging off (spdlog, OpenCV), once per process: a node logs every refused message.
void quiet();

inline std::string as_text(const uint8_t* data, size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

// Writes the input to `name` in a folder of this process (created on first use, removed at
// exit) and returns the file's path, for readers that take a path.
std::string temp_file(const std::string& name, const uint8_t* data, size_t size);
// An empty folder `name` in the same place (emptied when it exists); returns its path.
std::string empty_temp_folder(const std::string& name);

// The source tree (AERIE_SOURCE_DIR), for the configurations a node target starts from.
std::string source_path(const std::string& relative);

// --- node targets ---------------------------------------------------------------------------
// The input is a sequence of records, each one message on one of the node's channels:
//   1 byte   channel: index into the node's channel list, modulo its length
//   3 bytes  payload length, big-endian (a record cut short by the end of the input keeps the rest)
//   payload  an LCM message as it travels (8-byte fingerprint + fields)
struct Record {
  size_t channel;
  std::span<const uint8_t> payload;
};
std::vector<Record> split_records(const uint8_t* data, size_t size, size_t channels);
// The inverse, for building seeds: appends one record.
void append_record(std::vector<uint8_t>& out, uint8_t channel, std::span<const uint8_t> payload);

// Publishes every record on its channel of `bus` (an in-process memq:// bus) and lets the
// subscriptions handle it, as a node's loop does; `after_each` runs after every record
// (clocks, ticks, status reports).
void publish_records(bus::Bus& bus, const std::vector<std::string>& channels, const uint8_t* data, size_t size,
                     const std::function<void()>& after_each = {});

// The channel list of each node target (the generator of fuzz/corpus writes seeds with them).
// aerie-control runs three nodes on one bus, one per input; each takes controllers on its own
// FLC_PARAMS channel.
inline const std::vector<std::string> kControlChannels = {"VO_POSE",    "NAV_STATE",      "GT_POSE",
                                                          "FLC_PARAMS", "FLC_PARAMS_NAV", "FLC_PARAMS_GT"};
inline const std::vector<std::string> kNavChannels = {"IMU", "VO_POSE"};
inline const std::vector<std::string> kPilotChannels = {"TARGET_POSE", "TRACK", "IMU", "PILOT_CMD"};
inline const std::vector<std::string> kMapChannels = {"VO_POSE", "VO_DEPTH", "MAP_QUERY", "MAP_CMD"};
// aerie-track as in the demo (config/track_landing.yaml): the down camera, operator commands and
// the simulator's box it initialises on.
inline const std::vector<std::string> kTrackChannels = {"CAM_DOWN", "TRACK_CMD", "GT_TRACK"};
inline const std::vector<std::string> kVoChannels = {"CAM_STEREO"};
// aerie-flightsim receives commands; CTRL_CMD is also its lock-step answer channel.
inline const std::vector<std::string> kFlightSimChannels = {"CTRL_CMD"};
// aerie-link (config/link.yaml): the first kLinkAirChannels are published on the air network
// (air_to_ground relays them, but IMU, which stays on board), the others on the ground network
// (ground_to_air relays them). Not PMD_DISCOVER, which both directions relay: aerie-link drops
// the copy it published itself (its echo filter), the in-process link (SimLink) has no such
// filter and would bounce it between the buses.
inline const std::vector<std::string> kLinkChannels = {
    "CAM_DOWN", "CAM_LEFT",  "CAM_STEREO", "GT_TRACK",     "GT_POSE",    "TRACK",     "TARGET_POSE",
    "VO_POSE",  "VO_DEPTH",  "CTRL_CMD",   "MAP_QUERY",    "STATUS_VO",  "PMD_INFO2", "IMU",
    "TRACK_CMD", "FLC_PARAMS", "MAP_RESPONSE", "PMD_ORDERS2"};
inline constexpr size_t kLinkAirChannels = 14;
// procman: orders to a deputy, reports to a sheriff.
inline const std::vector<std::string> kProcmanChannels = {"PMD_ORDERS2", "PMD_INFO2"};

}  // namespace aerie::fuzz
