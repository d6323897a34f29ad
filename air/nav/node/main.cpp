// aerie-nav: the VO + IMU error-state EKF on the air side. IMU + VO_POSE -> NAV_STATE; status on
// STATUS_NAV. See docs/nav.md.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>

#include "air/nav/nav_config.hpp"
#include "air/nav/node/nav_node.hpp"
#include "common/bus/node.hpp"
#include "common/util/cli.hpp"

using namespace aerie;

int main(int argc, char** argv) {
  CLI::App app{"aerie-nav: error-state EKF fusing the IMU with VO poses (IMU + VO_POSE -> NAV_STATE)"};
  util::CommonOptions common;
  common.config = "config/nav.yaml";
  util::add_common_options(app, common);
  nav::NavNodeOptions opt;
  double rate = -1.0;
  app.add_option("--imu", opt.imu_channel, "IMU channel (aerie.imu_t)")->capture_default_str();
  app.add_option("--vo", opt.vo_channel, "VO pose channel (aerie.pose_t)")->capture_default_str();
  app.add_option("--output", opt.state_channel, "navigation state channel (aerie.nav_state_t)")->capture_default_str();
  app.add_option("--rate", rate, "NAV_STATE rate in Hz, message time (0 = every IMU sample; overrides the config)")
      ->check(CLI::NonNegativeNumber);
  CLI11_PARSE(app, argc, argv);
  util::init_logging("nav", common.log_level);
  try {
    const util::Config cfg = common.config.empty() ? util::Config() : util::Config::load(common.config);
    nav::NavConfig nc = nav::load_nav_config(cfg);
    if (rate >= 0.0) nc.publish_rate_hz = rate;
    bus::Bus bus(common.lcm_url);
    bus::StatusReporter status(bus, "nav");
    nav::NavNode node(bus, nc, opt);
    spdlog::info("{} + {} -> {} ({}), alignment window {} s, VO frame {}, gate chi2 {}", opt.imu_channel,
                 opt.vo_channel, opt.state_channel,
                 nc.publish_rate_hz > 0 ? std::to_string(nc.publish_rate_hz) + " Hz" : "every IMU sample",
                 nc.eskf.static_window_s, nc.eskf.vo_frame == nav::VoFrame::Anchor ? "anchored" : "fixed",
                 nc.eskf.gate_chi2);
    bus::run(bus, status, [&] {
      node.report(status);
      return true;
    });
    spdlog::info("stopped in {}", nav::to_string(node.filter().status()));
    return 0;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
