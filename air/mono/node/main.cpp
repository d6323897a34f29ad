// aerie-mono: monocular keyframe visual odometry node. An aerie.image_t channel (CAM_MONO, or
// CAM_LEFT of a stereo source) -> MONO_POSE (aerie.pose_t, arbitrary scale), STATUS_MONO.
// See docs/mono.md and config/mono.yaml.
#include <opencv2/core/utility.hpp>
#include <spdlog/spdlog.h>

#include <algorithm>

#include "air/mono/node/mono_node.hpp"
#include "common/util/cli.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Monocular keyframe visual odometry: CAM_MONO (aerie.image_t) -> MONO_POSE (aerie.pose_t, "
               "arbitrary scale)", "aerie-mono"};
  aerie::util::CommonOptions common;
  aerie::util::add_common_options(app, common);
  std::string input, pose;
  bool no_ba = false, replay = false;
  app.add_option("--input", input, "image channel (default from config: CAM_MONO; CAM_LEFT for a stereo source's left)");
  app.add_option("--pose-channel", pose, "pose channel (default MONO_POSE)");
  app.add_flag("--no-ba", no_ba, "run without the local bundle adjustment");
  app.add_flag("--replay", replay,
               "replaying a log: process every image (input queue 1000 instead of node.queue); with ba.apply "
               "next_keyframe a replay gives the live poses again");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);  // prints the help or the error
    return rc == 0 ? 0 : 2;
  }
  aerie::util::init_logging("mono", common.log_level);
  cv::setNumThreads(1);  // one front-end thread; the bundle adjuster has its own
  try {
    auto cfg = aerie::mono::load_mono_node_config(common.config.empty() ? aerie::util::Config()
                                                                          : aerie::util::Config::load(common.config));
    if (!input.empty()) cfg.input = input;
    if (!pose.empty()) cfg.pose = pose;
    if (no_ba) cfg.mono.ba.enabled = false;
    if (replay) cfg.queue = std::max(cfg.queue, 1000);
    aerie::bus::Bus bus(common.lcm_url);
    aerie::mono::MonoNode node(bus, cfg);
    spdlog::info("{} -> {}{}", cfg.input, cfg.pose, replay ? " (replay: every image)" : "");
    aerie::bus::run(node);
    spdlog::info("stopped after {} images ({} refused)", node.processed(), node.refused());
    return 0;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
