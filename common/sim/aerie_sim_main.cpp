// aerie-sim: renders the simulator's sequences to disk and describes its world.
//   aerie-sim info      [--config F]              world, trajectory, rig summary
//   aerie-sim stereo    [--config F] --out DIR    KITTI-odometry-style stereo folder + depth
//   aerie-sim landing   [--config F] --out DIR    helipad-landing tracking sequence (OTB-style)
//   aerie-sim intruder  [--config F] --out DIR    intruder-aircraft tracking sequence (OTB-style)
//   aerie-sim exits     [--config F] --out DIR    sequences where the target leaves the image and returns
#include <CLI/CLI.hpp>
#include <opencv2/imgcodecs.hpp>
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "common/camera/calibration_io.hpp"
#include "common/sim/sim_config.hpp"
#include "common/util/cli.hpp"

namespace fs = std::filesystem;
using namespace aerie;

namespace {

util::Config load(const std::string& path) { return path.empty() ? util::Config() : util::Config::load(path); }

void write_image(const fs::path& path, const cv::Mat& img) {
  if (!cv::imwrite(path.string(), img)) throw std::runtime_error(path.string() + ": cannot write image");
}

std::ofstream open_out(const fs::path& path) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error(path.string() + ": cannot open for writing");
  return f;
}

char* frame_name(char* buf, size_t n, const char* fmt, int k) {
  std::snprintf(buf, n, fmt, k);
  return buf;
}

void info(const sim::SimulationConfig& cfg, const sim::StereoSimulation& s) {
  const auto& w = s.world();
  const auto K = s.intrinsics();
  std::printf("room %.1f x %.1f x %.1f m, seed %llu, %zu obstacles\n", w.config().room_x, w.config().room_y,
              w.config().room_z, static_cast<unsigned long long>(w.config().seed), w.obstacles().size());
  for (const auto& o : w.obstacles())
    std::printf("  %-6s min (%.2f %.2f %.2f) max (%.2f %.2f %.2f)\n",
                o.kind == sim::Obstacle::Kind::Pillar ? "pillar" : "box", o.box.min.x(), o.box.min.y(),
                o.box.min.z(), o.box.max.x(), o.box.max.y(), o.box.max.z());
  const auto& pad = w.helipad();
  std::printf("helipad centre (%.2f %.2f) size %.2f m yaw %.1f deg\n", pad.center.x(), pad.center.y(), pad.size,
              pad.yaw * 180 / M_PI);
  std::printf("rig %dx%d fx %.3f fy %.3f cx %.1f cy %.1f baseline %.3f m pitch %.1f deg\n", K.width, K.height,
              K.fx, K.fy, K.cx, K.cy, K.baseline, cfg.rig.pitch_deg);
  const auto& tr = s.trajectory();
  std::printf("trajectory '%s': %.1f s, %.1f m, %d frames at %.1f Hz\n", cfg.trajectory.kind.c_str(),
              tr.duration(), tr.length(), s.frame_count(), s.rate_hz());
  for (const auto& p : tr.phases()) std::printf("  %-9s %7.2f .. %7.2f s\n", p.name.c_str(), p.t_begin, p.t_end);
}

// KITTI odometry layout (image_0, image_1, calib.txt with P0/P1, times.txt, poses.txt as
// T_0_k of the left camera) plus depth_0 (16-bit PNG, millimetres, 0 = none),
// poses_world_tum.txt (T_world_left, TUM format), calib.yaml (Aerie's OpenCV YAML) and
// helipad.txt (utime visible x y w h).
void export_stereo(sim::StereoSimulation& s, const fs::path& out, int every, int max_frames) {
  for (const char* d : {"image_0", "image_1", "depth_0"}) fs::create_directories(out / d);
  const auto K = s.intrinsics();
  camera::write_opencv_stereo(K.calibration(), (out / "calib.yaml").string());
  auto calib = open_out(out / "calib.txt");
  char line[512];
  for (int cam = 0; cam < 2; ++cam) {
    std::snprintf(line, sizeof line, "P%d: %.12e 0 %.12e %.12e 0 %.12e %.12e 0 0 0 1 0\n", cam, K.fx, K.cx,
                  cam ? -K.fx * K.baseline : 0.0, K.fy, K.cy);
    calib << line;
  }
  auto times = open_out(out / "times.txt"), poses = open_out(out / "poses.txt"),
       tum = open_out(out / "poses_world_tum.txt"), pad = open_out(out / "helipad.txt");
  tum << "# timestamp tx ty tz qx qy qz qw  (T_world_left, world z up)\n";
  pad << "# utime visible x y w h  (helipad box in the left image, pixel centres at integers)\n";
  geometry::SE3 T_world_first;
  char name[64];
  int n = 0;
  for (int k = 0; k < s.frame_count() && (max_frames <= 0 || n < max_frames); k += every, ++n) {
    const sim::StereoFrame f = s.frame(k);
    if (n == 0) T_world_first = f.T_world_left;
    write_image(out / "image_0" / frame_name(name, sizeof name, "%06d.png", n), f.left);
    write_image(out / "image_1" / frame_name(name, sizeof name, "%06d.png", n), f.right);
    cv::Mat mm;
    cv::Mat depth = f.depth.clone();
    cv::patchNaNs(depth, 0.0);
    depth.convertTo(mm, CV_16U, 1000.0);
    write_image(out / "depth_0" / frame_name(name, sizeof name, "%06d.png", n), mm);
    const double t = (f.utime - s.utime_of(0)) * 1e-6;
    std::snprintf(line, sizeof line, "%.6e\n", t);
    times << line;
    const Eigen::Matrix4d P = (T_world_first.inverse() * f.T_world_left).matrix();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) {
        std::snprintf(line, sizeof line, "%.9e%c", P(r, c), r == 2 && c == 3 ? '\n' : ' ');
        poses << line;
      }
    const auto& q = f.T_world_left.rotation();
    const auto& p = f.T_world_left.translation();
    std::snprintf(line, sizeof line, "%.6f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", f.utime * 1e-6, p.x(), p.y(),
                  p.z(), q.x(), q.y(), q.z(), q.w());
    tum << line;
    std::snprintf(line, sizeof line, "%lld %d %.3f %.3f %.3f %.3f\n", static_cast<long long>(f.utime),
                  f.target_visible ? 1 : 0, f.target_box.x, f.target_box.y, f.target_box.width,
                  f.target_box.height);
    pad << line;
  }
  spdlog::info("wrote {} stereo frames to {}", n, out.string());
}

// OTB-style tracking folder: img/0001.<ext>, groundtruth.txt (x,y,w,h per frame, pixel
// centres at integers) and groundtruth_full.csv (utime, visibility, corners or x/y/s/theta).
void export_landing(sim::StereoSimulation& s, const fs::path& out, const std::string& ext) {
  // Frames from the first to the last one with the whole helipad in view.
  int first = -1, last = -1;
  for (int k = 0; k < s.frame_count(); ++k) {
    sim::StereoFrame f;
    f.target_visible = false;
    s.renderer().project_helipad(s.trajectory().pose(s.time_of(k)) * s.T_body_left(), f);
    if (f.target_visible) {
      if (first < 0) first = k;
      last = k;
    }
  }
  if (first < 0) throw std::runtime_error("landing: the helipad is never fully in view with this rig");
  fs::create_directories(out / "img");
  auto gt = open_out(out / "groundtruth.txt"), full = open_out(out / "groundtruth_full.csv");
  full << "frame,utime,visible,x,y,w,h,u0,v0,u1,v1,u2,v2,u3,v3\n";
  char name[64], line[512];
  for (int k = first; k <= last; ++k) {
    const sim::StereoFrame f = s.frame(k);
    const int n = k - first + 1;
    write_image(out / "img" / frame_name(name, sizeof name, ("%04d." + ext).c_str(), n), f.left);
    const auto& b = f.target_box;
    std::snprintf(line, sizeof line, "%.3f,%.3f,%.3f,%.3f\n", b.x, b.y, b.width, b.height);
    gt << line;
    const auto& c = f.target_corners;
    std::snprintf(line, sizeof line, "%d,%lld,%d,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f\n", n,
                  static_cast<long long>(f.utime), f.target_visible ? 1 : 0, b.x, b.y, b.width, b.height, c[0].x,
                  c[0].y, c[1].x, c[1].y, c[2].x, c[2].y, c[3].x, c[3].y);
    full << line;
  }
  spdlog::info("wrote {} landing frames ({} .. {} of the approach and descent) to {}", last - first + 1, first,
               last, out.string());
}

// One frame of an OTB-style folder: the image, the box of groundtruth.txt (written
// NaN,NaN,NaN,NaN when the target is out of view) and the row of groundtruth_full.csv.
struct OtbFrame {
  cv::Mat image;
  cv::Rect2d box;
  bool in_view = true;
  std::string full;
};

// img/0001.<ext>..., groundtruth.txt, groundtruth_full.csv (`header` + one row a frame).
template <typename FrameFn>
int export_otb(const fs::path& out, const std::string& ext, int frames, const std::string& header, FrameFn frame) {
  fs::create_directories(out / "img");
  auto gt = open_out(out / "groundtruth.txt"), full = open_out(out / "groundtruth_full.csv");
  full << header << "\n";
  char name[64], line[128];
  for (int k = 0; k < frames; ++k) {
    const OtbFrame f = frame(k);
    write_image(out / "img" / frame_name(name, sizeof name, ("%04d." + ext).c_str(), k + 1), f.image);
    const auto& b = f.box;
    if (f.in_view)
      std::snprintf(line, sizeof line, "%.3f,%.3f,%.3f,%.3f\n", b.x, b.y, b.width, b.height);
    else
      std::snprintf(line, sizeof line, "NaN,NaN,NaN,NaN\n");
    gt << line;
    full << f.full;
  }
  return frames;
}

// The intruder's row of groundtruth_full.csv (frame,utime,visible,x,y,w,h,center_x,center_y,scale,angle_rad).
std::string mono_row(int n, const sim::MonoFrame& f, int visible) {
  char line[512];
  const auto& b = f.target_box;
  std::snprintf(line, sizeof line, "%d,%lld,%d,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.6f,%.6f", n,
                static_cast<long long>(f.utime), visible, b.x, b.y, b.width, b.height, f.target_center.x,
                f.target_center.y, f.target_scale, f.target_angle);
  return line;
}

void export_intruder(const sim::IntruderScene& scene, const fs::path& out, const std::string& ext) {
  const int n = export_otb(out, ext, scene.frame_count(),
                           "frame,utime,visible,x,y,w,h,center_x,center_y,scale,angle_rad", [&](int k) {
                             sim::MonoFrame f = scene.frame(k);
                             const std::string row = mono_row(k + 1, f, f.target_visible ? 1 : 0) + "\n";
                             return OtbFrame{std::move(f.image), f.target_box, true, row};
                           });
  spdlog::info("wrote {} intruder frames to {}", n, out.string());
}

// `count` sequences <out>/<name>_01 ... with seeds seed, seed + 1, ...; in groundtruth.txt a frame
// with less than min_visible of the box in view is NaN,NaN,NaN,NaN.
void export_exits(sim::ExitsConfig cfg, const fs::path& out, const std::string& name, int count,
                  const std::string& ext) {
  const uint64_t seed = cfg.look.seed;
  for (int i = 1; i <= count; ++i) {
    cfg.look.seed = seed + static_cast<uint64_t>(i - 1);
    const sim::ExitsScene scene(cfg);
    char dir[256];
    std::snprintf(dir, sizeof dir, "%s_%02d", name.c_str(), i);
    int out_of_view = 0;
    export_otb(out / dir, ext, scene.frame_count(),
               "frame,utime,visible,x,y,w,h,center_x,center_y,scale,angle_rad,visible_fraction,event",
               [&](int k) {
                 sim::ExitsFrame f = scene.frame(k);
                 char tail[64];
                 std::snprintf(tail, sizeof tail, ",%.4f,%s\n", f.visible_fraction, f.event.c_str());
                 out_of_view += f.in_view ? 0 : 1;
                 return OtbFrame{std::move(f.mono.image), f.mono.target_box, f.in_view,
                                 mono_row(k + 1, f.mono, f.in_view ? 1 : 0) + tail};
               });
    spdlog::info("wrote {} frames ({} out of view, seed {}) to {}", scene.frame_count(), out_of_view, cfg.look.seed,
                 (out / dir).string());
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Aerie simulator: renders the simulated stereo flights and tracking sequences to disk."};
  app.require_subcommand(1);
  std::string config, out, ext = "png", log_level = "info";
  std::string name = "exits";
  int every = 1, max_frames = 0, count = 6;
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error, off")->capture_default_str();
  auto add_config = [&](CLI::App* sub) {
    sub->add_option("--config", config, "YAML with world/rig/trajectory/intruder sections (config/sim/*.yaml)")
        ->check(CLI::ExistingFile);
  };
  auto* info_cmd = app.add_subcommand("info", "describe the world, rig and trajectory of a config");
  add_config(info_cmd);
  auto* stereo = app.add_subcommand("stereo", "stereo sequence in KITTI odometry layout, with depth and poses");
  add_config(stereo);
  stereo->add_option("--out", out, "output folder")->required();
  stereo->add_option("--every", every, "keep every k-th frame")->capture_default_str()->check(CLI::PositiveNumber);
  stereo->add_option("--max-frames", max_frames, "stop after this many frames (0 = all)")->capture_default_str();
  auto* landing = app.add_subcommand("landing", "helipad-landing tracking sequence (OTB-style folder)");
  add_config(landing);
  landing->add_option("--out", out, "output folder")->required();
  landing->add_option("--ext", ext, "image format")->check(CLI::IsMember({"png", "jpg"}))->capture_default_str();
  auto* intruder = app.add_subcommand("intruder", "intruder-aircraft tracking sequence (OTB-style folder)");
  add_config(intruder);
  intruder->add_option("--out", out, "output folder")->required();
  intruder->add_option("--ext", ext, "image format")->check(CLI::IsMember({"png", "jpg"}))->capture_default_str();
  auto* exits = app.add_subcommand(
      "exits",
      "tracking sequences where the intruder aircraft leaves the image (fast pan, slow drift, behind a foreground "
      "mast) and comes back: <out>/<name>_01... OTB-style folders, seeds seed, seed+1, ...; out-of-view frames are "
      "NaN,NaN,NaN,NaN in groundtruth.txt (config/sim/exits.yaml)");
  exits->add_option("--config", config, "YAML with an `exits` section (config/sim/exits.yaml)")
      ->check(CLI::ExistingFile);
  exits->add_option("--out", out, "output folder")->required();
  exits->add_option("--count", count, "number of sequences")->capture_default_str()->check(CLI::Range(1, 99));
  exits->add_option("--name", name, "sequence folder prefix")->capture_default_str();
  exits->add_option("--ext", ext, "image format")->check(CLI::IsMember({"png", "jpg"}))->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  util::init_logging("aerie-sim", log_level);

  try {
    const util::Config cfg = load(config);
    if (*exits) {
      export_exits(sim::load_exits_config(cfg), out, name, count, ext);
      return 0;
    }
    if (*intruder) {
      sim::IntruderScene scene(sim::load_intruder_config(cfg.section("intruder")));
      export_intruder(scene, out, ext);
      return 0;
    }
    sim::SimulationConfig sc = sim::load_simulation_config(cfg);
    if (*landing) {
      // The landing sequence is the demo's approach and descent; the rig looks down unless
      // the config says otherwise.
      if (!cfg.has("rig.pitch_deg")) sc.rig.pitch_deg = sim::landing_rig().pitch_deg;
      if (!cfg.has("trajectory.kind")) sc.trajectory.kind = "landing";
    }
    sim::StereoSimulation s = sim::make_simulation(sc);
    if (*info_cmd) info(sc, s);
    if (*stereo) export_stereo(s, out, every, max_frames);
    if (*landing) export_landing(s, out, ext);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
  return 0;
}
