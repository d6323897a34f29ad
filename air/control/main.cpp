// aerie-control: the onboard heading controller (thesis 5.1.2-5.1.3, 5.1.6). Runs the
// FLC on the heading from VO_POSE (or GT_POSE in simulation) against the reference,
// publishes CTRL_CMD at a fixed rate, takes new controllers from FLC_PARAMS, hovers
// when its input goes stale. Status on STATUS_CONTROL.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>

#include "air/control/control_config.hpp"
#include "air/control/control_node.hpp"
#include "common/bus/deployment.hpp"
#include "common/bus/node.hpp"
#include "common/flc/flc_io.hpp"
#include "common/util/cli.hpp"

using namespace aerie;

int main(int argc, char** argv) {
  CLI::App app{"aerie-control: fuzzy heading controller (VO_POSE/NAV_STATE/GT_POSE -> CTRL_CMD, FLC_PARAMS at run time)"};
  util::CommonOptions common;
  util::add_common_options(app, common);
  control::CliOverrides cli;
  app.add_option("--controller", cli.controller, "controller file (.yaml or .fll); default: config or the thesis' initial FLC");
  app.add_option("--input", cli.input, "heading source: vo (VO_POSE, aerie.pose_t), nav (NAV_STATE, aerie.nav_state_t: VO + IMU) "
                 "or gt (GT_POSE, aerie.gt_pose_t)")
      ->check(CLI::IsMember({"vo", "nav", "gt"}));
  app.add_option("--pose-channel", cli.pose_channel, "pose channel (default VO_POSE, NAV_STATE or GT_POSE)");
  app.add_option("--reference", cli.reference_deg, "heading reference in degrees");
  app.add_option("--speed", cli.forward_speed, "forward speed commanded while active (m/s)");
  app.add_option("--rate", cli.rate_hz, "CTRL_CMD rate (Hz); 0 = one command per input message");
  app.add_option("--stale-timeout", cli.stale_timeout_s, "hover when no heading for this long (s)");
  bool replay = false;
  app.add_flag("--replay", replay,
               "replaying a log: judge the poses' age and staleness on the log's time (the newest message time "
               "seen) instead of the wall clock");
  CLI11_PARSE(app, argc, argv);
  util::init_logging("control", common.log_level);
  try {
    const util::Config cfg = common.config.empty() ? util::Config() : util::Config::load(common.config);
    control::NodeSetup setup = control::node_setup(cfg, cli);
    setup.options.message_clock = replay;
    bus::require_host_local_commands("aerie-control", "FLC_PARAMS", common.lcm_url);
    bus::Bus bus(common.lcm_url);
    bus::StatusReporter status(bus, "control");
    control::ControlNode node(bus, status, setup.controller, setup.options);
    spdlog::info("controller '{}' ({} rules), input {} on {}, CTRL_CMD at {} Hz, reference {} deg{}, stale after {} s{}",
                 setup.controller.id, setup.controller.rules.size(),
                 cli.input.empty() ? cfg.get<std::string>("input", "vo") : cli.input,
                 setup.options.pose_channel, setup.options.rate_hz,
                 setup.options.control.reference_deg, setup.options.control.reference_relative ? " (relative)" : "",
                 setup.options.control.stale_timeout_s, replay ? " (replay: on the log's time)" : "");
    bus::run(bus, status, [&] {
      node.tick(node.now());
      return true;
    }, 2);
    spdlog::info("stopped");
    return 0;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
