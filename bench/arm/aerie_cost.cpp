// aerie-cost: runs one air-side node's per-frame work in-process, over memq://, on frames read
// and prepared beforehand, so that an instruction counter around the whole process
// (bench/arm, under qemu-user) can be read per frame: bench/arm/arm-cost.sh runs it with
// --frames N1 and --frames N2 and the same --prepare, and takes the difference / (N2 - N1).
// Everything that does not depend on --frames (start-up, loading the libraries, reading and
// decoding the frames, building the messages) is the same in both runs and cancels.
//
//   aerie-cost track   --source folder --path SEQ/img --width 376 --height 240 --frames N --prepare M
//   aerie-cost vo      --source sim|euroc|kitti --path DIR [--width W --height H | --downscale D] [--no-ba]
//   aerie-cost control --frames N --prepare M
//
// The node classes are the ones the node binaries run (TrackNode, VoNode, ControlNode), with
// their defaults (tracker amcmr-ct, VO as aerie-vo with cv::setNumThreads(1), the thesis'
// initial FLC with one command per pose); the capture node is measured as the aerie-capture
// binary itself (bench/arm/arm-cost.sh). Not built by CMake: bench/arm/arm-cost.sh compiles it
// against a build directory's libraries (bench/arm/README.md).
//
// Output, one line on stdout: mode, frames processed, output messages, process CPU seconds of
// the processing loop, and the heap in use (glibc's mallinfo2: allocated bytes of the arenas +
// mmapped blocks, so under qemu it is the target program's own heap, not qemu's): at start,
// after the frames were prepared, its peak (sampled after every frame, so a buffer allocated
// and freed within one frame is not seen), and node_heap = peak - prepared, what the node
// itself holds (its construction, tracker/VO state and maps, queued messages).
#include <CLI/CLI.hpp>
#include <malloc.h>
#include <spdlog/spdlog.h>

#include <aerie/control_cmd_t.hpp>
#include <aerie/pose_t.hpp>
#include <aerie/track_t.hpp>

#include <opencv2/core.hpp>

#include <cmath>
#include <ctime>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "air/capture/capture_node.hpp"
#include "air/capture/output_format.hpp"
#include "air/capture/source_factory.hpp"
#include "air/control/control_config.hpp"
#include "air/control/control_node.hpp"
#include "air/stereo/node/vo_node.hpp"
#include "air/track/node/track_node.hpp"
#include "common/bus/bus.hpp"
#include "common/bus/status.hpp"
#include "common/util/config.hpp"

using namespace aerie;

namespace {

size_t heap_peak = 0, heap_start = 0, heap_prepared = 0;
// Heap in use: malloc'ed bytes of the arenas plus mmapped blocks (glibc mallinfo2).
size_t heap_now() {
  const struct mallinfo2 mi = mallinfo2();
  return mi.uordblks + mi.hblkhd;
}
void sample_heap() { heap_peak = std::max(heap_peak, heap_now()); }

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + ts.tv_nsec * 1e-9;
}

void drain(bus::Bus& bus) {
  while (bus.handle(0) > 0) {
  }
}

struct Options {
  std::string source = "folder", path, groundtruth, tracker = "amcmr-ct";
  int width = 0, height = 0;
  double downscale = 1.0;
  int frames = 0, prepare = 0, start = 0;
  bool no_ba = false;
  uint64_t seed = 1;
};

// Reads `count` frames through the capture node's own source, format and message builder.
std::vector<capture::FrameMessages> read_frames(const Options& o, cv::Size* out_size, cv::Size* src_size) {
  capture::CaptureConfig cfg;
  cfg.source.type = o.source;
  cfg.source.path = o.path;
  cfg.source.sim.trajectory = "survey";  // as bench/vo/sim_loops_376.yaml: loops at 1 m/s, noise 1
  cfg.source.sim.speed = 1.0;
  cfg.source.sim.loops = 10;
  cfg.source.sim.noise_sigma = 1.0;
  cfg.source.sim.seed = o.seed;
  cfg.source.sim.start_utime = 1'000'000;
  cfg.output.width = o.width, cfg.output.height = o.height, cfg.output.downscale = o.downscale;
  heap_start = heap_now();
  auto src = capture::make_source(cfg.source_options());
  *src_size = src->size();
  capture::OutputFormat fmt(cfg.output, src->size());
  *out_size = fmt.size();
  const auto rect = src->rectified();
  capture::MessageBuilder builder(cfg, src->stereo(), rect ? std::optional(fmt.apply(*rect)) : std::nullopt);
  if (o.start > 0) src->seek(o.start);
  std::vector<capture::FrameMessages> out;
  capture::Frame f;
  // utimes 50 ms apart from 1 s: the node's message clock sees a steady 20 Hz camera.
  for (int i = 0; i < o.prepare && src->next(f); ++i) {
    fmt.apply(f);
    out.push_back(builder.build(f, 1'000'000 + 50'000 * static_cast<int64_t>(i), i));
  }
  if (static_cast<int>(out.size()) < o.prepare)
    throw std::runtime_error("the source has only " + std::to_string(out.size()) + " frames, --prepare " +
                             std::to_string(o.prepare));
  return out;
}

// The prepared frames; the heap is sampled once the source (e.g. the simulator's world) is gone.
std::vector<capture::FrameMessages> prepare_frames(const Options& o, cv::Size* out_size, cv::Size* src_size) {
  auto frames = read_frames(o, out_size, src_size);
  heap_prepared = heap_now();
  return frames;
}

// First box of an OTB-style groundtruth.txt (x,y,w,h; commas, tabs or spaces).
cv::Rect2d first_box(const std::string& file, int line_no) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot read " + file);
  std::string line;
  for (int i = 0; i <= line_no; ++i)
    if (!std::getline(in, line)) throw std::runtime_error(file + ": no line " + std::to_string(line_no + 1));
  for (char& c : line)
    if (c == ',' || c == '\t') c = ' ';
  std::istringstream s(line);
  double x, y, w, h;
  if (!(s >> x >> y >> w >> h) || !std::isfinite(x) || !(w > 0 && h > 0))
    throw std::runtime_error(file + ": line " + std::to_string(line_no + 1) + " is not a box: " + line);
  return {x, y, w, h};
}

void report(const std::string& mode, int frames, int64_t outputs, double cpu_s, const std::string& extra) {
  std::cout << "mode=" << mode << " frames=" << frames << " outputs=" << outputs << " loop_cpu_s=" << cpu_s
            << " heap_peak_bytes=" << heap_peak << " heap_start_bytes=" << heap_start
            << " heap_prepared_bytes=" << heap_prepared
            << " node_heap_bytes=" << (heap_peak > heap_prepared ? heap_peak - heap_prepared : 0) << " " << extra
            << std::endl;
}

int run_track(const Options& o) {
  cv::Size out_size, src_size;
  auto frames = prepare_frames(o, &out_size, &src_size);
  std::string gt = o.groundtruth;
  if (gt.empty()) gt = o.path + "/../groundtruth.txt";
  cv::Rect2d box = first_box(gt, o.start);
  const double sx = static_cast<double>(out_size.width) / src_size.width;
  const double sy = static_cast<double>(out_size.height) / src_size.height;
  box = cv::Rect2d(box.x * sx, box.y * sy, box.width * sx, box.height * sy);

  bus::Bus bus("memq://");
  int64_t tracks = 0, lost = 0;
  bus.subscribe<aerie::track_t>("TRACK", [&](const aerie::track_t& m, const bus::ReceiveInfo&) {
    ++tracks;
    if (m.status == aerie::track_t::LOST) ++lost;
  });
  track::NodeOptions opt;
  opt.every_frame = true;
  opt.tracker = o.tracker;
  track::TrackNode node(bus, opt);
  auto image_of = [&](const capture::FrameMessages& m) -> const aerie::image_t& {
    if (m.left) return *m.left;
    if (m.mono) return *m.mono;
    throw std::runtime_error("the source gives no left/mono image");
  };
  auto settle = [&] {
    for (int round = 0; round < 3; ++round) {
      drain(bus);
      if (!node.wait_idle(600'000)) throw std::runtime_error("the tracker did not finish a frame in 600 s");
    }
    drain(bus);
  };
  // Frame 0 and the INIT on its ground-truth box are part of every run (they cancel).
  bus.publish("CAM_LEFT", image_of(frames[0]));
  settle();
  aerie::track_cmd_t c{};
  c.command = aerie::track_cmd_t::INIT;
  c.tracker = o.tracker;
  c.x = box.x, c.y = box.y, c.width = box.width, c.height = box.height;
  bus.publish("TRACK_CMD", c);
  settle();
  sample_heap();
  const double t0 = cpu_seconds();
  for (int i = 1; i <= o.frames; ++i) {
    bus.publish("CAM_LEFT", image_of(frames[static_cast<size_t>(i)]));
    settle();
    sample_heap();
  }
  const double cpu = cpu_seconds() - t0;
  std::ostringstream extra;
  extra << "size=" << out_size.width << "x" << out_size.height << " source=" << src_size.width << "x"
        << src_size.height << " box=" << box.width << "x" << box.height << " lost=" << lost
        << " tracker=" << o.tracker;
  report("track", o.frames, tracks, cpu, extra.str());
  return 0;
}

int run_vo(const Options& o) {
  cv::setNumThreads(1);  // as aerie-vo (air/stereo/node/main.cpp)
  cv::Size out_size, src_size;
  auto frames = prepare_frames(o, &out_size, &src_size);
  bus::Bus bus("memq://");
  bus::StatusReporter status(bus, "VO");
  int64_t poses = 0, ok = 0;
  bus.subscribe<aerie::pose_t>("VO_POSE", [&](const aerie::pose_t& p, const bus::ReceiveInfo&) {
    ++poses;
    if (p.status == aerie::pose_t::OK) ++ok;
  });
  stereo::VoNodeConfig cfg = stereo::load_vo_node_config(util::Config());
  if (o.no_ba) cfg.vo.ba.enabled = false;
  // Every bundle adjustment is waited for, so that the count is the same from run to run (the
  // node runs it on a second thread, asynchronously; the work is the same).
  cfg.vo.ba_synchronous = true;
  cfg.queue = 1000;
  stereo::VoNode node(bus, status, cfg);
  auto pair_of = [&](const capture::FrameMessages& m) -> const aerie::stereo_image_t& {
    if (!m.stereo) throw std::runtime_error("the source gives no rectified stereo pair");
    return *m.stereo;
  };
  // Frame 0 (the VO's initialisation) is part of every run.
  bus.publish("CAM_STEREO", pair_of(frames[0]));
  drain(bus);
  sample_heap();
  const double t0 = cpu_seconds();
  for (int i = 1; i <= o.frames; ++i) {
    bus.publish("CAM_STEREO", pair_of(frames[static_cast<size_t>(i)]));
    drain(bus);
    sample_heap();
  }
  const double cpu = cpu_seconds() - t0;
  std::ostringstream extra;
  extra << "size=" << out_size.width << "x" << out_size.height << " source=" << src_size.width << "x"
        << src_size.height << " ok=" << ok << " processed=" << node.processed() << " refused=" << node.refused()
        << " ba=" << (cfg.vo.ba.enabled ? "on" : "off");
  report("vo", o.frames, poses, cpu, extra.str());
  return 0;
}

int run_control(const Options& o) {
  heap_start = heap_prepared = heap_now();
  bus::Bus bus("memq://");
  bus::StatusReporter status(bus, "control");
  control::CliOverrides cli;
  cli.rate_hz = 0;  // one CTRL_CMD per VO_POSE
  control::NodeSetup setup = control::node_setup(util::Config(), cli);
  int64_t cmds = 0;
  bus.subscribe<aerie::control_cmd_t>("CTRL_CMD", [&](const aerie::control_cmd_t&, const bus::ReceiveInfo&) { ++cmds; });
  control::ControlNode node(bus, status, setup.controller, setup.options);
  // Poses of a slow turn (the heading sweeps the FLC's whole input range), 20 Hz.
  std::vector<aerie::pose_t> poses(static_cast<size_t>(std::max(o.prepare, o.frames + 1)));
  for (size_t i = 0; i < poses.size(); ++i) {
    aerie::pose_t& p = poses[i];
    p = aerie::pose_t{};
    p.utime = 1'000'000 + 50'000 * static_cast<int64_t>(i);
    p.seq = static_cast<int64_t>(i);
    const double yaw = 0.05 * static_cast<double>(i);
    // camera frame: heading is a rotation about the camera's y axis (down-looking conventions
    // aside, any rotation gives the FLC a heading to work on)
    p.orientation[0] = std::cos(yaw / 2), p.orientation[2] = std::sin(yaw / 2);
    p.position[2] = 0.1 * static_cast<double>(i);
    p.status = aerie::pose_t::OK;
  }
  bus.publish("VO_POSE", poses[0]);
  drain(bus);
  const double t0 = cpu_seconds();
  for (int i = 1; i <= o.frames; ++i) {
    bus.publish("VO_POSE", poses[static_cast<size_t>(i)]);
    drain(bus);
    sample_heap();
  }
  const double cpu = cpu_seconds() - t0;
  report("control", o.frames, cmds, cpu, "controller=" + setup.controller.id);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"aerie-cost: one air-side node's per-frame work in-process (bench/arm, bench/arm/arm-cost.sh)"};
  app.require_subcommand(1);
  Options o;
  std::string mode;
  for (const char* name : {"track", "vo", "control"}) {
    CLI::App* s = app.add_subcommand(name);
    s->callback([&mode, name] { mode = name; });
    s->add_option("--frames", o.frames, "frames processed after the first (which every run has)")->required();
    s->add_option("--prepare", o.prepare, "frames read and prepared (>= frames + 1, the same in the runs compared)");
    if (std::string(name) != "control") {
      s->add_option("--source", o.source, "capture source: folder, euroc, kitti or sim");
      s->add_option("--path", o.path, "the source's folder");
      s->add_option("--width", o.width, "output width (with --height)");
      s->add_option("--height", o.height, "output height");
      s->add_option("--downscale", o.downscale, "divide the source size by this (without --width/--height)");
      s->add_option("--start", o.start, "first frame of the source");
    }
    if (std::string(name) == "track") {
      s->add_option("--groundtruth", o.groundtruth, "OTB groundtruth.txt (default PATH/../groundtruth.txt)");
      s->add_option("--tracker", o.tracker, "tracker (default amcmr-ct, as aerie-track)");
    }
    if (std::string(name) == "vo") s->add_flag("--no-ba", o.no_ba, "without the keyframe bundle adjustment");
  }
  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(spdlog::level::warn);
  if (o.prepare == 0) o.prepare = o.frames + 1;
  try {
    if (o.frames < 0 || o.prepare < o.frames + 1) throw std::invalid_argument("need 0 <= --frames < --prepare");
    if (mode == "track") return run_track(o);
    if (mode == "vo") return run_vo(o);
    return run_control(o);
  } catch (const std::exception& e) {
    std::cerr << "aerie-cost " << mode << ": " << e.what() << std::endl;
    return 1;
  }
}
