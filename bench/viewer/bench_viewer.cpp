// Viewer display rate and CPU under load: 752x480 stereo at 20 Hz plus a 100k-voxel map,
// rendered off-screen (run under xvfb-run -a for software OpenGL), render loop free-running.
//   xvfb-run -a build/default/bin/bench_viewer [--seconds 20] [--voxels 100000] [--out FILE.json]
#include <octomap/OcTree.h>
#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <thread>

#include <aerie/stereo_image_t.hpp>

#include "common/image/image_message.hpp"
#include "common/util/time.hpp"
#include "ground/viewer/renderers/scene.hpp"
#include "ground/viewer/viewer.hpp"

using namespace aerie;

static double cpu_seconds(int who) {
  rusage u{};
  getrusage(who, &u);
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

int main(int argc, char** argv) {
  CLI::App app{"bench_viewer: display rate and CPU of aerie-viewer with 752x480 stereo at 20 Hz + a large OctoMap"};
  double seconds = 20;
  int voxels = 100000;
  std::string out;
  app.add_option("--seconds", seconds, "measurement time")->capture_default_str();
  app.add_option("--voxels", voxels, "occupied voxels in the map")->capture_default_str();
  app.add_option("--out", out, "JSON result file");
  CLI11_PARSE(app, argc, argv);

  bus::Bus bus("memq://");
  viewer::ViewerOptions opts;
  opts.offscreen = true;
  opts.image_channel = "CAM_STEREO";
  viewer::Viewer v(bus, opts);
  v.add_default_renderers();
  v.start();

  // A map of `voxels` occupied 0.1 m voxels: the walls and floor of a 30 m room, then random boxes.
  octomap::OcTree tree(0.1);
  std::mt19937 rng(1);
  int n = 0;
  for (int i = 0; n < voxels; ++i) {
    const float x = 0.05f + 0.1f * (i % 300), y = 0.05f + 0.1f * ((i / 300) % 300), z = 0.05f + 0.1f * (i / 90000);
    tree.updateNode(octomap::point3d(x - 15, y - 15, z), true, true);
    ++n;
  }
  tree.updateInnerOccupancy();
  std::ostringstream os;
  tree.writeBinary(os);
  const std::string bytes = os.str();
  aerie::octomap_t map{};
  map.resolution = 0.1;
  map.binary = true;
  map.full = true;
  map.data.assign(bytes.begin(), bytes.end());
  map.length = static_cast<int32_t>(map.data.size());
  bus.publish("MAP_OCTOMAP", map);

  std::atomic<bool> run{true};
  std::atomic<int64_t> published{0};
  std::thread camera([&] {
    cv::Mat left(480, 752, CV_8UC1), right(480, 752, CV_8UC1);
    cv::randu(left, 0, 255);
    right = left.clone();
    auto next = std::chrono::steady_clock::now();
    for (int64_t k = 0; run; ++k) {
      aerie::stereo_image_t s{};
      s.utime = k * 50000;
      s.seq = k;
      s.left = image::to_message(left, s.utime, k);
      s.right = image::to_message(right, s.utime, k);
      bus.publish("CAM_STEREO", s);
      ++published;
      next += std::chrono::milliseconds(50);
      std::this_thread::sleep_until(next);
    }
  });

  auto* oct = dynamic_cast<viewer::OctomapRenderer*>(v.find("octomap"));
  while (oct->voxels_shown() == 0) v.render_frame();  // map loaded and uploaded
  const int64_t frames0 = v.frames_rendered();
  const double t0 = util::mono_ms() / 1000, cpu0 = cpu_seconds(RUSAGE_SELF);
  while (util::mono_ms() / 1000 - t0 < seconds) v.render_frame();
  const double wall = util::mono_ms() / 1000 - t0, cpu = cpu_seconds(RUSAGE_SELF) - cpu0;
  run = false;
  camera.join();
  v.stop();
  const double fps = (v.frames_rendered() - frames0) / wall;
  std::ostringstream json;
  json << "{\"voxels_shown\": " << oct->voxels_shown() << ", \"seconds\": " << wall << ", \"display_fps\": " << fps
       << ", \"cpu_percent_of_one_core\": " << 100 * cpu / wall << ", \"stereo_frames_published\": " << published
       << "}";
  std::cout << json.str() << std::endl;
  if (!out.empty()) std::ofstream(out) << json.str() << "\n";
  return 0;
}
