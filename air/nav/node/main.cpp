// aerie-nav: the VO + IMU error-state EKF on the air side. IMU + VO_POSE -> NAV_STATE; status on
// STATUS_NAV. See docs/nav.md.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>

#include "air/nav/nav_config.hpp"
#include "air/nav/node/mono_nav_node.hpp"
#include "air/nav/node/nav_node.hpp"
#include "common/bus/node.hpp"
#include "common/util/cli.hpp"

using namespace aerie;

int main(int argc, char** argv) {
  CLI::App app{"aerie-nav: error-state EKF fusing the IMU with VO poses (IMU + VO_POSE or MONO_POSE -> NAV_STATE)"};
  util::CommonOptions common;
  common.config = "config/nav.yaml";
  util::add_common_options(app, common);
  nav::NavNodeOptions opt;
  double rate = -1.0;
  std::string source, mono_channel;
  app.add_option("--source", source, "pose source: stereo (VO_POSE) or mono (arbitrary scale; overrides the config)")
      ->check(CLI::IsMember({"stereo", "mono"}));
  app.add_option("--mono", mono_channel, "mono pose channel (aerie.pose_t, SCALE_ARBITRARY; overrides mono.channel)");
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
    if (!source.empty()) nc.source = source == "mono" ? nav::NavConfig::Source::Mono : nav::NavConfig::Source::Stereo;
    if (!mono_channel.empty()) nc.mono_channel = mono_channel;
    bus::Bus bus(common.lcm_url);
    bus::StatusReporter status(bus, "nav");
    if (nc.source == nav::NavConfig::Source::Mono) {
      nav::MonoNavNode node(bus, nc, opt);
      spdlog::info("{} + {} (mono, arbitrary scale) -> {}, scale prior {} (sigma {} in log), SCALE_OK below {}",
                   opt.imu_channel, nc.mono_channel, opt.state_channel, nc.mono.scale_prior, nc.mono.scale_prior_sigma,
                   nc.mono.scale_sigma_ok);
      bus::run(bus, status, [&] {
        node.report(status);
        return true;
      });
      spdlog::info("stopped in {}, scale {:.4f}", nav::to_string(node.filter().status()), node.filter().scale());
      return 0;
    }
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
