// aerie-pilot: the flight manager (mission state machine + landing controllers) on the
// air side. TARGET_POSE/TRACK/IMU/PILOT_CMD -> CTRL_CMD, PILOT_STATE; status on
// STATUS_PILOT. See docs/pilot.md.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>

#include "air/pilot/node/pilot_node.hpp"
#include "air/pilot/pilot_config.hpp"
#include "common/bus/deployment.hpp"
#include "common/bus/node.hpp"
#include "common/util/cli.hpp"

using namespace aerie;

int main(int argc, char** argv) {
  CLI::App app{"aerie-pilot: take off, find the target, land on it (TARGET_POSE/TRACK/IMU -> CTRL_CMD, PILOT_STATE)"};
  util::CommonOptions common;
  common.config = "config/pilot.yaml";
  util::add_common_options(app, common);
  std::string controller;
  bool wait_for_start = false;
  app.add_option("--controller", controller, "landing controller: fuzzy or pid (overrides the config)")
      ->check(CLI::IsMember({"fuzzy", "pid"}));
  app.add_flag("--wait-for-start", wait_for_start, "stay IDLE until an operator START on PILOT_CMD");
  pilot::PilotNodeOptions options;
  app.add_flag("--replay", options.message_clock,
               "replaying a log: judge the inputs' age on the log's time (the newest message time seen) instead "
               "of the wall clock");
  CLI11_PARSE(app, argc, argv);
  util::init_logging("pilot", common.log_level);
  try {
    util::Config cfg = common.config.empty() ? util::Config() : util::Config::load(common.config);
    pilot::PilotConfig pc = pilot::load_pilot_config(cfg);
    if (!controller.empty() && controller != pc.controller) {
      YAML::Node n = YAML::Clone(cfg.node());
      n["controller"] = controller;
      YAML::Emitter out;
      out << n;
      pc = pilot::load_pilot_config(util::Config::parse(out.c_str(), cfg.origin()));
    }
    if (wait_for_start) pc.wait_for_start = true;
    bus::require_host_local_commands("aerie-pilot", "PILOT_CMD", common.lcm_url);
    bus::Bus bus(common.lcm_url);
    bus::StatusReporter status(bus, "pilot");
    pilot::PilotNode node(bus, pc, options);
    spdlog::info("{} controller, approach at {} m, descent at {} m/s, touchdown below {} m{}", pc.controller,
                 pc.approach_height_m, pc.descent_speed_m_s, pc.touchdown_height_m,
                 pc.wait_for_start ? "; waiting for START on PILOT_CMD" : "");
    bus::run(bus, status, [&] {
      node.report(status);
      return true;
    });
    spdlog::info("stopped in {}", pilot::state_name(node.pilot().state()));
    return 0;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
