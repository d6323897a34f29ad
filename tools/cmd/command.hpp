#pragma once
// The operator's commands as messages (docs/cmd.md): TRACK_CMD (aerie.track_cmd_t), PILOT_CMD
// (aerie.pilot_cmd_t) and MAP_CMD (aerie.map_cmd_t) built from what an operator types, and the
// rules by which a TRACK or PILOT_STATE shows that a command took effect. No LCM: the sending
// is tools/cmd/sender.hpp. Every parser throws std::invalid_argument naming the option and
// the bad value.
#include <aerie/map_cmd_t.hpp>
#include <aerie/pilot_cmd_t.hpp>
#include <aerie/pilot_state_t.hpp>
#include <aerie/track_cmd_t.hpp>
#include <aerie/track_t.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <variant>

namespace aerie::cmd {

// An INIT box in pixels of the camera's image: top-left corner and size.
struct Box {
  double x = 0, y = 0, width = 0, height = 0;
};

// "X,Y,W,H": four finite numbers, X, Y >= 0 and W, H > 0 (pixels).
Box parse_box(const std::string& text);
// `name` when the tracker factory (air/track/factory.hpp) knows it; the error lists the known names.
std::string check_tracker(const std::string& name);

// TRACK_CMD as the viewer sends it (ground/viewer/viewer.cpp): `tracker` "" keeps the node's,
// `camera` "" means the node's camera channel; the box only for INIT, nparams 0.
aerie::track_cmd_t track_command(int8_t command, const std::string& tracker, const std::string& camera,
                                 const std::optional<Box>& box, int64_t utime, int64_t seq);

// "start", "abort", "land", "resume" -> aerie.pilot_cmd_t's constant.
int8_t pilot_command_code(const std::string& word);
const char* pilot_command_name(int8_t command);  // "START" ... ("?" for another value)
aerie::pilot_cmd_t pilot_command(int8_t command, const std::string& source, int64_t utime, int64_t seq);

// A map file name for SAVE / LOAD: a plain name (no directory: aerie-map keeps its files in its
// files.directory, docs/map.md) ending in .bt or .ot. aerie-map applies the rest of its rules.
std::string check_map_name(const std::string& name);
// "map-YYYYMMDD-HHMMSS.bt" (UTC) for a SAVE that names no file.
std::string default_map_name(int64_t utime);
aerie::map_cmd_t map_command(int8_t command, const std::string& path, int64_t utime, int64_t seq);

// "aerie-cmd@<hostname>": the pilot_cmd_t source field.
std::string command_source();

// One command ready to go: its channel and its message.
struct Command {
  std::string channel;
  std::variant<aerie::track_cmd_t, aerie::pilot_cmd_t, aerie::map_cmd_t> message;
};
// One line for the operator: "TRACK_CMD INIT tracker=ct camera=(node's) box=(10, 20, 30, 40)".
std::string describe(const Command& c);

// Did this TRACK show the command took effect? INIT: status TRACKING or REDETECTED, from the
// tracker the command named (any when it named none); STOP: status IDLE. The camera must be
// the command's when it named one. Other commands: never.
bool track_took_effect(const aerie::track_cmd_t& sent, const aerie::track_t& seen);
// Did this PILOT_STATE show the command took effect: is the pilot in a state the command leads
// to? START: any state but IDLE; ABORT: ABORT or ABORTED; LAND: TOUCHDOWN or LANDED; RESUME:
// ACQUIRE, APPROACH, DESCEND, TOUCHDOWN or LANDED (out of HOLD / ABORTED, after the target).
bool pilot_took_effect(int8_t command, const aerie::pilot_state_t& seen);
std::string describe(const aerie::track_t& m);
std::string describe(const aerie::pilot_state_t& m);

}  // namespace aerie::cmd
