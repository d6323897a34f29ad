#include "tools/cmd/cli.hpp"

#include <CLI/CLI.hpp>

#include <charconv>
#include <cmath>
#include <memory>
#include <optional>
#include <ostream>
#include <stdexcept>

#include "common/bus/channels.hpp"
#include "common/util/time.hpp"
#include "tools/cmd/command.hpp"
#include "tools/cmd/sender.hpp"

namespace aerie::cmd {

namespace {

// A usage error found after parsing (a bad value): exit status 2.
struct Usage : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

struct Args {
  std::string url;
  std::string track_action, box, tracker, camera;
  std::string pilot_action;
  std::string map_action, map_name;
  double wait_s = 0;  // 0: do not wait
};

Command track_from(const Args& a, int64_t utime) {
  if (a.track_action == "stop") {
    if (!a.box.empty() || !a.tracker.empty()) throw Usage("track stop: takes no --box or --tracker");
    return {channels::kTrackCmd, track_command(aerie::track_cmd_t::STOP, "", a.camera, std::nullopt, utime, 0)};
  }
  if (!a.track_action.empty())
    throw Usage("track: unknown action '" + a.track_action + "' (expected --box X,Y,W,H or stop)");
  if (a.box.empty()) throw Usage("track: --box X,Y,W,H is required to start tracking (or: track stop)");
  const Box box = parse_box(a.box);
  const std::string tracker = a.tracker.empty() ? "" : check_tracker(a.tracker);
  return {channels::kTrackCmd, track_command(aerie::track_cmd_t::INIT, tracker, a.camera, box, utime, 0)};
}

Command pilot_from(const Args& a, int64_t utime) {
  if (a.pilot_action.empty()) throw Usage("pilot: a command is required (abort, land, resume or start)");
  return {channels::kPilotCmd, pilot_command(pilot_command_code(a.pilot_action), command_source(), utime, 0)};
}

Command map_from(const Args& a, int64_t utime) {
  const std::string& act = a.map_action;
  if (act == "save")
    return {channels::kMapCmd, map_command(aerie::map_cmd_t::SAVE,
                                           a.map_name.empty() ? default_map_name(utime) : check_map_name(a.map_name),
                                           utime, 0)};
  if (act == "load") {
    if (a.map_name.empty()) throw Usage("map load: a file NAME is required (NAME.bt or NAME.ot)");
    return {channels::kMapCmd, map_command(aerie::map_cmd_t::LOAD, check_map_name(a.map_name), utime, 0)};
  }
  if (act == "clear" || act == "publish") {
    if (!a.map_name.empty()) throw Usage("map " + act + ": takes no file name, got '" + a.map_name + "'");
    return {channels::kMapCmd, map_command(act == "clear" ? aerie::map_cmd_t::CLEAR : aerie::map_cmd_t::PUBLISH_FULL,
                                           "", utime, 0)};
  }
  throw Usage("map: unknown command '" + act + "' (expected save [NAME], load NAME, clear or publish)");
}

}  // namespace

int run(const std::vector<std::string>& args, std::ostream& out, std::ostream& err, bus::Bus* bus) {
  Args a;
  CLI::App app{"aerie-cmd: the operator's commands from the shell: TRACK_CMD, PILOT_CMD and MAP_CMD, as the viewer "
               "sends them (docs/cmd.md)",
               "aerie-cmd"};
  app.require_subcommand(1);
  app.add_option("--lcm-url", a.url, "LCM URL, e.g. udpm://239.255.76.67:7667?ttl=0 (default: $LCM_DEFAULT_URL)");
  app.footer("Exit status: 0 sent (with --wait-ack: and seen to take effect), 1 not seen in time or LCM failed, "
             "2 usage error.");
  auto wait_option = [&](CLI::App* sub, const std::string& what) {
    sub->add_option("--wait-ack", a.wait_s, "wait up to S seconds for " + what + "; exit 1 if it does not come")
        ->check(CLI::Validator(
            [](std::string& text) {
              double v = 0;
              const char* end = text.data() + text.size();
              const auto [ptr, ec] = std::from_chars(text.data(), end, v);
              return ec == std::errc() && ptr == end && std::isfinite(v) && v > 0
                         ? std::string()
                         : "expected a number of seconds > 0, got '" + text + "'";
            },
            "S", "seconds"));
  };

  auto* track = app.add_subcommand("track", "Start tracking a box (TRACK_CMD INIT), or stop (TRACK_CMD STOP)");
  track->add_option("action", a.track_action, "stop: end the track (without: INIT on --box)");
  track->add_option("--box", a.box, "X,Y,W,H: the target's box, pixels of the camera image (top-left corner, size)");
  track->add_option("--tracker", a.tracker, "tracker to start (default: the node's, --tracker of aerie-track)");
  track->add_option("--camera", a.camera, "image channel the box is in (default: the node's camera channel)");
  wait_option(track, "a TRACK showing the tracker running (stop: showing it idle)");
  track->footer("Usage: aerie-cmd track --box X,Y,W,H [--tracker NAME] [--camera CH] [--wait-ack S]\n"
               "       aerie-cmd track stop [--camera CH] [--wait-ack S]");

  auto* pilot = app.add_subcommand("pilot", "Order the flight manager (PILOT_CMD): abort, land, resume or start");
  pilot->add_option("command", a.pilot_action, "abort | land | resume | start");
  wait_option(pilot, "a PILOT_STATE in the state the command leads to");
  pilot->footer("Usage: aerie-cmd pilot abort|land|resume|start [--wait-ack S]");

  auto* map = app.add_subcommand("map", "Order the ground map (MAP_CMD): save, load, clear or publish");
  map->add_option("command", a.map_action, "save [NAME] | load NAME | clear | publish (the whole map now)");
  map->add_option("name", a.map_name, "map file NAME.bt or NAME.ot in aerie-map's files.directory "
                                      "(save default: map-YYYYMMDD-HHMMSS.bt, UTC)");
  map->footer("Usage: aerie-cmd map save [NAME] | load NAME | clear | publish");
  for (auto* sub : {track, pilot, map}) sub->fallthrough();

  // Before the sub-command: --lcm-url URL and --help; the first other word names the sub-command.
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--lcm-url") {
      ++i;
    } else if (args[i] == "-h" || args[i] == "--help" || args[i].rfind("--lcm-url=", 0) == 0) {
      continue;
    } else if (!args[i].empty() && args[i][0] == '-') {
      err << "aerie-cmd: unknown option '" << args[i] << "' (see --help)\n";
      return 2;
    } else {
      if (args[i] != "track" && args[i] != "pilot" && args[i] != "map") {
        err << "aerie-cmd: unknown sub-command '" << args[i] << "' (expected track, pilot or map; see --help)\n";
        return 2;
      }
      break;
    }
  }

  std::vector<const char*> argv{"aerie-cmd"};
  for (const auto& s : args) argv.push_back(s.c_str());
  std::string where = "aerie-cmd";
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e, out, err);  // --help
    for (const auto* sub : app.get_subcommands()) where += " " + sub->get_name();
    err << where << ": " << e.what() << " (see " << where << " --help)\n";
    return 2;
  }
  where += " " + app.get_subcommands().front()->get_name();

  Command command;
  try {
    const int64_t utime = util::wall_utime();
    command = *track ? track_from(a, utime) : *pilot ? pilot_from(a, utime) : map_from(a, utime);
  } catch (const std::invalid_argument& e) {
    err << "aerie-cmd: " << e.what() << "\n";
    return 2;
  }

  std::unique_ptr<bus::Bus> own;
  try {
    if (bus == nullptr) bus = (own = std::make_unique<bus::Bus>(a.url)).get();
    if (a.wait_s <= 0) {
      send(*bus, command);
      out << "sent " << describe(command) << "\n";
      return 0;
    }
    const std::string channel = answer_channel(command);
    const Ack ack = send_and_wait(*bus, command, a.wait_s);
    out << "sent " << describe(command) << "\n";
    if (ack.took_effect) {
      out << "took effect: " << ack.message << "\n";
      return 0;
    }
    out << "not seen to take effect within " << a.wait_s << " s: "
        << (ack.seen == 0 ? "no message on " + channel
                          : std::to_string(ack.seen) + " on " + channel + ", the last: " + ack.message)
        << "\n";
    return 1;
  } catch (const std::invalid_argument& e) {  // refused before sending
    err << "aerie-cmd: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << where << ": " << e.what() << "\n";
    return 1;
  }
}

}  // namespace aerie::cmd
