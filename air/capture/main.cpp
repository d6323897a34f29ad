// aerie-capture: frames from a camera, a video, an image folder, a dataset (EuRoC,
// KITTI) or the simulator, published on LCM. See docs/capture.md and config/capture.yaml.
#include <spdlog/spdlog.h>

#include <functional>
#include <memory>

#include "air/capture/capture_node.hpp"
#include "common/bus/node.hpp"
#include "common/util/cli.hpp"

namespace {

using aerie::capture::CaptureConfig;
using Override = std::function<void(CaptureConfig&)>;

// A command-line option that, when given, overrides the same setting of the config file.
template <typename Get>
void option(CLI::App& app, std::vector<Override>& overrides, const std::string& name, Get get, const std::string& help) {
  using T = std::remove_reference_t<decltype(get(std::declval<CaptureConfig&>()))>;
  static CaptureConfig defaults;
  auto value = std::make_shared<T>(get(defaults));
  CLI::Option* o = app.add_option(name, *value, help);
  overrides.push_back([o, value, get](CaptureConfig& c) {
    if (o->count() > 0) get(c) = *value;
  });
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Publish camera, video, image-folder, dataset or simulator frames on LCM", "aerie-capture"};
  aerie::util::CommonOptions common;
  aerie::util::add_common_options(app, common);
  std::vector<Override> ov;
  option(app, ov, "-s,--source", [](CaptureConfig& c) -> auto& { return c.source.type; },
         "sim, v4l2, video, folder, euroc or kitti");
  option(app, ov, "-p,--path", [](CaptureConfig& c) -> auto& { return c.source.path; },
         "Folder, video file or camera device (/dev/video0)");
  option(app, ov, "--right", [](CaptureConfig& c) -> auto& { return c.source.right; },
         "v4l2: the right camera of a stereo pair");
  option(app, ov, "--calib", [](CaptureConfig& c) -> auto& { return c.source.calib; },
         "v4l2 pair: stereo calibration (EuRoC folder, KITTI calib.txt or OpenCV YAML)");
  option(app, ov, "--timestamps", [](CaptureConfig& c) -> auto& { return c.source.timestamps; },
         "folder: timestamps file, seconds per line");
  option(app, ov, "--groundtruth", [](CaptureConfig& c) -> auto& { return c.source.groundtruth; },
         "euroc: TUM trajectory of the body when the folder has no state_groundtruth_estimate0; kitti: the "
         "poses file (poses/NN.txt; found by itself in KITTI's download layout); refused for other sources");
  option(app, ov, "--fps", [](CaptureConfig& c) -> auto& { return c.source.fps; },
         "Frame rate of sources without timestamps; requested camera rate");
  option(app, ov, "--rate", [](CaptureConfig& c) -> auto& { return c.rate; },
         "Playback speed: 1 real time, 2 twice as fast, 0 as fast as possible");
  option(app, ov, "--start", [](CaptureConfig& c) -> auto& { return c.start; }, "First frame (0-based)");
  option(app, ov, "--stop", [](CaptureConfig& c) -> auto& { return c.stop; }, "Stop before this frame (-1: the end)");
  option(app, ov, "--duration", [](CaptureConfig& c) -> auto& { return c.duration_s; },
         "Stop after this many seconds of source time (0: no limit)");
  option(app, ov, "--loop", [](CaptureConfig& c) -> auto& { return c.loop; },
         "true: play a recorded source again and again (times and seq go on)");
  option(app, ov, "--width", [](CaptureConfig& c) -> auto& { return c.output.width; },
         "Output width (with --height; the simulator renders at this size)");
  option(app, ov, "--height", [](CaptureConfig& c) -> auto& { return c.output.height; }, "Output height");
  option(app, ov, "--downscale", [](CaptureConfig& c) -> auto& { return c.output.downscale; },
         "Divide the image size by this factor");
  option(app, ov, "--color", [](CaptureConfig& c) -> auto& { return c.output.color; },
         "true: BGR colour images, false: 8-bit gray");
  option(app, ov, "--encoding", [](CaptureConfig& c) -> auto& { return c.encoding; }, "raw, jpeg or png payloads");
  option(app, ov, "--jpeg-quality", [](CaptureConfig& c) -> auto& { return c.jpeg_quality; }, "1..100");
  option(app, ov, "--stamp", [](CaptureConfig& c) -> auto& { return c.stamp; },
         "source: the frames' own times; wall: the wall clock at publication");
  option(app, ov, "--left-channel", [](CaptureConfig& c) -> auto& { return c.channels.left; }, "\"\" turns it off");
  option(app, ov, "--right-channel", [](CaptureConfig& c) -> auto& { return c.channels.right; }, "\"\" turns it off");
  option(app, ov, "--stereo-channel", [](CaptureConfig& c) -> auto& { return c.channels.stereo; }, "\"\" turns it off");
  app.add_flag_callback(
      "--split-stereo", [&ov] { ov.push_back([](CaptureConfig& c) { c.channels.split_stereo = true; }); },
      "with CAM_STEREO, also publish the left and right images alone (each image twice on the wire)");
  option(app, ov, "--mono-channel", [](CaptureConfig& c) -> auto& { return c.channels.mono; }, "\"\" turns it off");
  option(app, ov, "--gt-pose-channel", [](CaptureConfig& c) -> auto& { return c.channels.gt_pose; }, "\"\" turns it off");
  option(app, ov, "--gt-track-channel", [](CaptureConfig& c) -> auto& { return c.channels.gt_track; }, "\"\" turns it off");
  option(app, ov, "--sim-seed", [](CaptureConfig& c) -> auto& { return c.source.sim.seed; }, "Simulator world seed");
  option(app, ov, "--sim-trajectory", [](CaptureConfig& c) -> auto& { return c.source.sim.trajectory; },
         "demo or survey");
  option(app, ov, "--sim-speed", [](CaptureConfig& c) -> auto& { return c.source.sim.speed; }, "m/s");
  option(app, ov, "--sim-loops", [](CaptureConfig& c) -> auto& { return c.source.sim.loops; }, "survey loops");
  option(app, ov, "--sim-start-utime", [](CaptureConfig& c) -> auto& { return c.source.sim.start_utime; },
         "utime of the first simulated frame (-1: the wall clock at start)");
  option(app, ov, "--sim-noise", [](CaptureConfig& c) -> auto& { return c.source.sim.noise_sigma; },
         "image noise sigma, gray levels");
  CLI11_PARSE(app, argc, argv);
  aerie::util::init_logging("capture", common.log_level);

  try {
    CaptureConfig cfg = common.config.empty() ? CaptureConfig{}
                                              : aerie::capture::load_capture_config(aerie::util::Config::load(common.config));
    for (const auto& apply : ov) apply(cfg);
    aerie::bus::install_stop_handlers();
    auto source = aerie::capture::make_source(cfg.source_options());
    aerie::bus::Bus bus(common.lcm_url);
    aerie::capture::CaptureNode node(bus, cfg, std::move(source));
    spdlog::info("{} -> {}", node.source().describe(), bus.url().empty() ? "LCM default URL" : bus.url());
    const auto st = node.run();
    spdlog::info("published {} frames in {:.2f} s ({:.1f} frames/s); {} unreadable, {} late", st.published, st.wall_s,
                 st.wall_s > 0 ? st.published / st.wall_s : 0.0, st.unreadable, st.late);
    return 0;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
