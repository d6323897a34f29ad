// aerie-viewer: the ground operator's dashboard (see docs/viewer.md).
#include <spdlog/spdlog.h>
#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <thread>

#include "air/nav/nav_config.hpp"
#include "common/bus/node.hpp"
#include "common/util/cli.hpp"
#include "common/util/heap.hpp"
#include "common/util/time.hpp"
#include "ground/viewer/renderers/panel.hpp"
#include "ground/viewer/viewer.hpp"

namespace {
std::atomic<bool> g_snapshot_requested{false};
extern "C" void on_usr1(int) { g_snapshot_requested = true; }

double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"aerie-viewer: VTK ground dashboard — camera pane with tracker overlay, 3D scene (poses, "
               "trajectories, depth, OctoMap), charts and process panel. Drag a box on the camera pane to track it."};
  aerie::util::CommonOptions common;
  aerie::viewer::ViewerOptions opts;
  std::string snapshot, record_dir;
  double after = -1, fps = 20, duration = -1;
  std::vector<std::string> disable;
  aerie::util::add_common_options(app, common, false);
  app.add_option("--image-channel", opts.image_channel, "camera channel for the image pane (image_t, or CAM_STEREO)")
      ->capture_default_str();
  app.add_option("--size", opts.width, "window width in pixels")->capture_default_str();
  app.add_option("--height", opts.height, "window height in pixels")->capture_default_str();
  app.add_flag("--offscreen", opts.offscreen, "render off-screen (no window); implied by --snapshot/--record");
  app.add_option("--snapshot", snapshot,
                 "write a PNG of the whole window: after --after seconds, on SIGUSR1, and at exit");
  app.add_option("--after", after, "with --snapshot: seconds after start to write it, then exit");
  app.add_option("--record", record_dir, "write one PNG of the window per second into this folder");
  app.add_option("--fps", fps, "display frames per second")->capture_default_str()->check(CLI::Range(1.0, 200.0));
  app.add_option("--pane-fps", opts.pane_fps,
                 "at most this many redraws per second of the 3D scene, charts and panel (when they change)")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 200.0));
  app.add_option("--map-max-quads", opts.map_max_quads,
                 "show the OctoMap one level coarser while its surface needs more quads than this (0: no limit)")
      ->capture_default_str();
  app.add_option("--multisamples", opts.multisamples, "OpenGL anti-aliasing samples (0: off, best without a GPU)")
      ->capture_default_str()
      ->check(CLI::Range(0, 16));
  app.add_option("--trajectory-poses", opts.trajectory_poses, "poses of each trajectory drawn (the newest)")
      ->capture_default_str()
      ->check(CLI::Range(size_t{1}, size_t{1000000}));
  app.add_option("--trim-period", opts.trim_period_s,
                 "hand the heap's free memory back to the kernel (malloc_trim) every this many seconds (0: never)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--duration", duration, "exit after this many seconds (headless runs)");
  app.add_option("--disable", disable, "renderers to start disabled (by name, e.g. octomap chart-latency)");
  std::string nav_config;
  app.add_option("--nav-config", nav_config,
                 "aerie-nav's YAML: its camera.T_body_cam (EuRoC: cam0's T_BS) turns IMU gravity into the display's "
                 "z up when no GT_POSE comes (default: the simulator's forward rig)")
      ->check(CLI::ExistingFile);
  app.add_option("--align-period", opts.align_period_s,
                 "seconds between two alignments of GT_POSE to VO_POSE (SE(3), as aerie-eval-traj; 'g': now)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_flag("--frame-vehicle", opts.frame_vehicle,
               "look at the vehicle's start from 8 m once the 3D scene's frame is known (default: the whole scene)");
  std::string key_path;
  app.add_option("--key", key_path,
                 "mission key file (mode 0600): the process panel's start/stop orders are tagged as a keyed "
                 "sheriff's (PMD_ORDERS2_SEALED); without it they are libbot2's plain PMD_ORDERS2, which keyed "
                 "deputies refuse");
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "%s: %s (see --help)\n", "aerie-viewer", e.what());
    return 2;
  }
  aerie::util::init_logging("viewer", common.log_level);
  aerie::util::map_large_blocks();  // util/heap.hpp

  const bool headless = opts.offscreen || !snapshot.empty() || !record_dir.empty();
  opts.offscreen = headless;
  if (!headless && !std::getenv("DISPLAY")) {
    spdlog::error("no DISPLAY: run under X (or xvfb-run -a), or use --offscreen/--snapshot/--record");
    return 2;
  }
  if (!record_dir.empty()) std::filesystem::create_directories(record_dir);
  try {
    if (!nav_config.empty())
      opts.T_body_cam = aerie::nav::load_nav_config(aerie::util::Config::load(nav_config)).eskf.T_body_cam;
    aerie::bus::Bus bus(common.lcm_url);
    aerie::viewer::Viewer viewer(bus, opts);
    viewer.add_default_renderers();
    if (!key_path.empty()) {
      const aerie::seal::SecretKey key = aerie::seal::load_key(key_path);  // refuses a file others can read
      uint32_t id = 0;
      while (id == 0) id = static_cast<uint32_t>(std::random_device{}() & 0x7fffffff);
      if (auto* panel = dynamic_cast<aerie::viewer::ProcmanPanel*>(viewer.find("processes"))) panel->use_key(key, id);
      spdlog::info("process panel: keyed orders (key {}, sheriff id {})", aerie::seal::fingerprint(key), id);
    }
    for (const auto& name : disable) {
      auto* r = viewer.find(name);
      if (!r) {
        spdlog::error("--disable: no renderer named '{}'", name);
        return 2;
      }
      r->set_enabled(false);
    }
    aerie::bus::install_stop_handlers();
    std::signal(SIGUSR1, on_usr1);
    viewer.start();
    const double t0 = aerie::util::mono_ms() / 1000.0, cpu0 = cpu_seconds();
    if (!headless) {
      viewer.run_interactive(fps);
    } else {
      double next_record = t0;
      int record_index = 0;
      const auto period = std::chrono::duration<double>(1.0 / fps);
      while (!aerie::bus::stop_requested()) {
        const auto frame_start = std::chrono::steady_clock::now();
        viewer.render_frame();
        const double now = aerie::util::mono_ms() / 1000.0;
        if (g_snapshot_requested.exchange(false) && !snapshot.empty()) viewer.snapshot(snapshot);
        if (!record_dir.empty() && now >= next_record) {
          char name[64];
          std::snprintf(name, sizeof(name), "frame-%06d.png", record_index++);
          viewer.snapshot((std::filesystem::path(record_dir) / name).string());
          next_record += 1.0;
        }
        if (after >= 0 && now - t0 >= after) break;
        if (duration >= 0 && now - t0 >= duration) break;
        std::this_thread::sleep_until(frame_start + period);
      }
    }
    const double wall = aerie::util::mono_ms() / 1000.0 - t0, cpu = cpu_seconds() - cpu0;
    viewer.stop();
    if (!snapshot.empty()) {
      viewer.snapshot(snapshot);
      spdlog::info("snapshot written to {}", snapshot);
    }
    spdlog::info("displayed {} frames in {:.1f} s: {:.1f} frames/s, CPU {:.0f}% of one core",
                 viewer.frames_rendered(), wall, viewer.frames_rendered() / std::max(wall, 1e-9),
                 100.0 * cpu / std::max(wall, 1e-9));
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
  return 0;
}
