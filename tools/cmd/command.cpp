#include "tools/cmd/command.hpp"

#include <unistd.h>

#include <array>
#include <charconv>
#include <cmath>
#include <ctime>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "air/track/factory.hpp"

namespace aerie::cmd {

namespace {

std::string join(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

std::string fixed(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

const char* track_command_name(int8_t c) {
  switch (c) {
    case aerie::track_cmd_t::INIT: return "INIT";
    case aerie::track_cmd_t::STOP: return "STOP";
    case aerie::track_cmd_t::RESET: return "RESET";
    case aerie::track_cmd_t::SET_TRACKER: return "SET_TRACKER";
    default: return "?";
  }
}

const char* map_command_name(int8_t c) {
  switch (c) {
    case aerie::map_cmd_t::SAVE: return "SAVE";
    case aerie::map_cmd_t::LOAD: return "LOAD";
    case aerie::map_cmd_t::CLEAR: return "CLEAR";
    case aerie::map_cmd_t::PUBLISH_FULL: return "PUBLISH_FULL";
    default: return "?";
  }
}

const char* track_status_name(int8_t s) {
  switch (s) {
    case aerie::track_t::IDLE: return "IDLE";
    case aerie::track_t::TRACKING: return "TRACKING";
    case aerie::track_t::LOST: return "LOST";
    case aerie::track_t::REDETECTED: return "REDETECTED";
    default: return "?";
  }
}

}  // namespace

Box parse_box(const std::string& text) {
  const std::string expected = "--box '" + text + "': expected four numbers X,Y,W,H in pixels (X, Y >= 0; W, H > 0)";
  std::array<double, 4> v{};
  size_t n = 0, start = 0;
  while (true) {
    const size_t comma = text.find(',', start);
    const std::string field = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (n == v.size()) throw std::invalid_argument(expected + ", got more than four");
    const char* end = field.data() + field.size();
    const auto [ptr, ec] = std::from_chars(field.data(), end, v[n]);
    if (field.empty() || ec != std::errc() || ptr != end || !std::isfinite(v[n]))
      throw std::invalid_argument(expected + ", '" + field + "' is not a number");
    ++n;
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (n != v.size()) throw std::invalid_argument(expected + ", got " + std::to_string(n));
  const char* names[] = {"X", "Y", "W", "H"};
  for (size_t i = 0; i < v.size(); ++i)
    if (i < 2 ? v[i] < 0 : v[i] <= 0)
      throw std::invalid_argument(expected + ", " + names[i] + " = " + fixed(v[i]));
  return {v[0], v[1], v[2], v[3]};
}

std::string check_tracker(const std::string& name) {
  if (!track::is_known_tracker(name))
    throw std::invalid_argument("--tracker '" + name + "': unknown tracker (known: " +
                                join(track::aerie_tracker_names()) + "; references: " +
                                join(track::opencv_tracker_names()) + ")");
  return name;
}

aerie::track_cmd_t track_command(int8_t command, const std::string& tracker, const std::string& camera,
                                 const std::optional<Box>& box, int64_t utime, int64_t seq) {
  aerie::track_cmd_t c{};
  c.utime = utime;
  c.seq = seq;
  c.command = command;
  c.tracker = tracker;
  c.camera = camera;
  if (box) {
    c.x = box->x;
    c.y = box->y;
    c.width = box->width;
    c.height = box->height;
  }
  c.nparams = 0;
  return c;
}

int8_t pilot_command_code(const std::string& word) {
  if (word == "start") return aerie::pilot_cmd_t::START;
  if (word == "abort") return aerie::pilot_cmd_t::ABORT;
  if (word == "land") return aerie::pilot_cmd_t::LAND;
  if (word == "resume") return aerie::pilot_cmd_t::RESUME;
  throw std::invalid_argument("pilot: unknown command '" + word + "' (expected abort, land, resume or start)");
}

const char* pilot_command_name(int8_t command) {
  switch (command) {
    case aerie::pilot_cmd_t::START: return "START";
    case aerie::pilot_cmd_t::ABORT: return "ABORT";
    case aerie::pilot_cmd_t::LAND: return "LAND";
    case aerie::pilot_cmd_t::RESUME: return "RESUME";
    default: return "?";
  }
}

aerie::pilot_cmd_t pilot_command(int8_t command, const std::string& source, int64_t utime, int64_t seq) {
  aerie::pilot_cmd_t c{};
  c.utime = utime;
  c.seq = seq;
  c.command = command;
  c.source = source;
  return c;
}

std::string check_map_name(const std::string& name) {
  const std::string what = "map: file name '" + name + "'";
  if (name.empty()) throw std::invalid_argument(what + " is empty (expected NAME.bt or NAME.ot)");
  if (name.find('/') != std::string::npos)
    throw std::invalid_argument(what + " has a directory: aerie-map reads and writes only in its files.directory, "
                                       "give a plain name");
  const auto dot = name.rfind('.');
  const std::string ext = dot == std::string::npos ? "" : name.substr(dot);
  if ((ext != ".bt" && ext != ".ot") || dot == 0)
    throw std::invalid_argument(what + " does not end in .bt or .ot (OctoMap binary or full tree)");
  return name;
}

std::string default_map_name(int64_t utime) {
  const std::time_t t = static_cast<std::time_t>(utime / 1'000'000);
  std::tm tm{};
  ::gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof(buf), "map-%Y%m%d-%H%M%S.bt", &tm);
  return buf;
}

aerie::map_cmd_t map_command(int8_t command, const std::string& path, int64_t utime, int64_t seq) {
  aerie::map_cmd_t c{};
  c.utime = utime;
  c.seq = seq;
  c.command = command;
  c.path = path;
  return c;
}

std::string command_source() {
  std::array<char, 256> host{};
  if (::gethostname(host.data(), host.size() - 1) != 0 || host[0] == '\0') return "aerie-cmd@unknown";
  return std::string("aerie-cmd@") + host.data();
}

std::string describe(const Command& c) {
  std::ostringstream o;
  o << c.channel << " ";
  if (const auto* t = std::get_if<aerie::track_cmd_t>(&c.message)) {
    o << track_command_name(t->command) << " tracker=" << (t->tracker.empty() ? "(node's)" : t->tracker)
      << " camera=" << (t->camera.empty() ? "(node's)" : t->camera);
    if (t->command == aerie::track_cmd_t::INIT)
      o << " box=(" << t->x << ", " << t->y << ", " << t->width << ", " << t->height << ")";
  } else if (const auto* p = std::get_if<aerie::pilot_cmd_t>(&c.message)) {
    o << pilot_command_name(p->command) << " source=" << p->source;
  } else if (const auto* m = std::get_if<aerie::map_cmd_t>(&c.message)) {
    o << map_command_name(m->command);
    if (!m->path.empty()) o << " " << m->path;
  }
  return o.str();
}

bool track_took_effect(const aerie::track_cmd_t& sent, const aerie::track_t& seen) {
  if (!sent.camera.empty() && seen.camera != sent.camera) return false;
  switch (sent.command) {
    case aerie::track_cmd_t::INIT:
      return (seen.status == aerie::track_t::TRACKING || seen.status == aerie::track_t::REDETECTED) &&
             (sent.tracker.empty() || seen.tracker == sent.tracker);
    case aerie::track_cmd_t::STOP:
      return seen.status == aerie::track_t::IDLE;
    default:
      return false;
  }
}

bool pilot_took_effect(int8_t command, const aerie::pilot_state_t& seen) {
  using S = aerie::pilot_state_t;
  const int8_t s = seen.state;
  switch (command) {
    case aerie::pilot_cmd_t::START: return s != S::IDLE;
    case aerie::pilot_cmd_t::ABORT: return s == S::ABORT || s == S::ABORTED;
    case aerie::pilot_cmd_t::LAND: return s == S::TOUCHDOWN || s == S::LANDED;
    case aerie::pilot_cmd_t::RESUME:
      return s == S::ACQUIRE || s == S::APPROACH || s == S::DESCEND || s == S::TOUCHDOWN || s == S::LANDED;
    default: return false;
  }
}

std::string describe(const aerie::track_t& m) {
  std::ostringstream o;
  o << "TRACK seq " << m.seq << ": " << track_status_name(m.status) << " tracker=" << m.tracker
    << " camera=" << m.camera;
  if (m.status != aerie::track_t::IDLE)
    o << " centre=(" << m.x << ", " << m.y << ") size=" << m.width << "x" << m.height << " confidence="
      << m.confidence;
  return o.str();
}

std::string describe(const aerie::pilot_state_t& m) {
  return "PILOT_STATE seq " + std::to_string(m.seq) + ": " + m.state_name + " (" + m.reason + ")";
}

}  // namespace aerie::cmd
