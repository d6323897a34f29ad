// aerie-vo: stereo visual odometry node. CAM_STEREO (rectified pairs) -> VO_POSE, VO_DEPTH,
// STATUS_VO. See docs/stereo.md and config/vo.yaml.
#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <spdlog/spdlog.h>

#include "air/stereo/node/vo_node.hpp"
#include "common/bus/node.hpp"
#include "common/util/cli.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Stereo visual odometry: CAM_STEREO -> VO_POSE + VO_DEPTH (thesis ch. 4)", "aerie-vo"};
  aerie::util::CommonOptions common;
  aerie::util::add_common_options(app, common);
  std::string input, pose, depth;
  bool no_ba = false, replay = false;
  app.add_option("--input", input, "stereo channel (default from config: CAM_STEREO)");
  app.add_option("--pose-channel", pose, "pose channel (default VO_POSE)");
  app.add_option("--depth-channel", depth, "spherical depth channel (default VO_DEPTH; \"none\" turns it off)");
  app.add_flag("--no-ba", no_ba, "run without the keyframe bundle adjustment");
  app.add_flag("--replay", replay,
               "replaying a log: process every pair, whatever the speed (the input queue 1000 pairs instead of "
               "node.queue; still, every pair dropped is counted); with ba.apply next_keyframe (the default) a replay gives the live poses again");
  CLI11_PARSE(app, argc, argv);
  aerie::util::init_logging("vo", common.log_level);
  // The front end is one thread by design (the bundle adjuster has its own): OpenCV's pool
  // would only add hand-off overhead (KITTI: 13.4 ms per frame with it, 10.1 ms without) and
  // hide work from the per-stage thread CPU times in STATUS_VO.
  cv::setNumThreads(1);
  try {
    auto cfg = aerie::stereo::load_vo_node_config(common.config.empty() ? aerie::util::Config()
                                                                          : aerie::util::Config::load(common.config));
    if (!input.empty()) cfg.input = input;
    if (!pose.empty()) cfg.pose = pose;
    if (!depth.empty()) cfg.depth = depth == "none" ? "" : depth;
    if (no_ba) cfg.vo.ba.enabled = false;
    // The node never waits for a bundle adjustment it has just started (ba.synchronous is for
    // offline evaluation); ba.apply decides where its result lands.
    cfg.vo.ba_synchronous = false;
    if (replay) cfg.queue = std::max(cfg.queue, 1000);
    aerie::bus::Bus bus(common.lcm_url);
    aerie::bus::StatusReporter status(bus, "VO");
    aerie::stereo::VoNode node(bus, status, cfg);
    spdlog::info("{} -> {}{}{}", cfg.input, cfg.pose, cfg.depth.empty() ? "" : ", " + cfg.depth,
                 replay ? " (replay: every pair)" : "");
    aerie::bus::run(bus, status, [&] {
      node.tick();  // reports the camera stale during an outage
      return true;
    });
    spdlog::info("stopped after {} stereo pairs ({} refused); {}: {} dropped here (input queue of {} full), {} missing "
                 "upstream (sequence gaps)",
                 node.processed(), node.refused(), cfg.input, node.queue_overflows(), cfg.queue, node.upstream_gaps());
    return 0;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
