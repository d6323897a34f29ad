// aerie-track: tracks the operator's target in the camera images and publishes TRACK (and
// TARGET_POSE for a target of known size). See docs/track.md.
#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "air/track/factory.hpp"
#include "air/track/node/track_node.hpp"
#include "common/bus/deployment.hpp"
#include "common/bus/node.hpp"
#include "common/util/cli.hpp"

int main(int argc, char** argv) {
  CLI::App app{"aerie-track: online visual tracking of an operator-selected target (TRACK, TARGET_POSE)"};
  aerie::util::CommonOptions common;
  aerie::util::add_common_options(app, common);
  std::string camera, tracker;
  bool stereo = false, replay = false;
  int init_from_gt = -1;
  double target_size = -1;
  app.add_option("--camera", camera, "camera channel (default from the config, else CAM_LEFT)");
  app.add_flag("--stereo", stereo, "the camera channel carries stereo pairs (CAM_STEREO): track the left image");
  app.add_option("--tracker", tracker, "tracker for INIT commands that name none: ipsl, ipsl-mr, ct, amcmr-ct, mil, am3, dcf, eco, opencv-* (default eco)");
  app.add_option("--init-from-gt", init_from_gt,
                 "initialise on the GT_TRACK box after this many frames (simulation demo, no operator)");
  app.add_option("--target-size", target_size, "target width = height in metres (enables TARGET_POSE)");
  app.add_flag("--replay", replay,
               "replaying a log: track every frame in order, whatever the speed (instead of the newest frame)");
  CLI11_PARSE(app, argc, argv);
  aerie::util::init_logging("track", common.log_level);

  try {
    const auto cfg = common.config.empty() ? aerie::util::Config() : aerie::util::Config::load(common.config);
    aerie::track::NodeOptions opt = aerie::track::node_options(cfg);
    if (!camera.empty()) opt.camera_channel = camera;
    if (stereo) opt.stereo = true;
    if (!tracker.empty()) {
      if (!aerie::track::is_known_tracker(tracker)) throw std::invalid_argument("--tracker: unknown tracker '" + tracker + "'");
      opt.tracker = tracker;
    }
    if (init_from_gt >= 0) opt.init_from_gt = init_from_gt;
    opt.every_frame = replay;
    if (target_size > 0) opt.target.width_m = opt.target.height_m = target_size;

    aerie::bus::require_host_local_commands("aerie-track", "TRACK_CMD", common.lcm_url);
    aerie::bus::Bus bus(common.lcm_url);
    aerie::bus::StatusReporter status(bus, "track");
    aerie::track::TrackNode node(bus, opt);
    spdlog::info("tracking {} ({}) with {}; commands on {}, output on {}", opt.camera_channel,
                 opt.stereo ? "stereo" : "mono", opt.tracker, opt.command_channel, opt.track_channel);
    aerie::bus::run(bus, status, [&] {
      node.report(status);
      return true;
    });
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
  return 0;
}
