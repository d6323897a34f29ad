// Viewer display rate and CPU: 752x480 stereo at 20 Hz plus a 100k-voxel map, rendered
// off-screen (run under xvfb-run -a for software OpenGL). The render loop polls like the
// viewer's display timer (panes drawn when they change), or with --always-redraw draws
// every pane every frame as fast as it can (the cost of a full frame).
//   xvfb-run -a build/default/bin/bench_viewer [--seconds 20] [--voxels 100000] [--map floor|rough]
//                                             [--always-redraw] [--multisamples 0] [--out FILE.json]
#include <octomap/OcTree.h>
#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <thread>

#include <vtkCallbackCommand.h>
#include <vtkCommand.h>

#include <aerie/pose_t.hpp>
#include <aerie/stereo_image_t.hpp>

#include "common/image/image_message.hpp"
#include "common/util/time.hpp"
#include "ground/map/occupancy.hpp"
#include "ground/map/octomap_message.hpp"
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
  double seconds = 20, map_period = 1.0;
  int voxels = 100000, coarsening = 0;
  bool poses = false;
  std::string out, map_kind = "rough", map_file, snapshot;
  viewer::ViewerOptions opts;
  app.add_option("--seconds", seconds, "measurement time")->capture_default_str();
  app.add_option("--voxels", voxels, "occupied voxels in the map")->capture_default_str();
  app.add_option("--map", map_kind,
                 "floor: a flat 30 m floor (best case for the mesh); rough: columns of random height "
                 "1-4 voxels (a face between almost every pair of columns, worst case)")
      ->check(CLI::IsMember({"floor", "rough"}))
      ->capture_default_str();
  app.add_option("--map-file", map_file, "a saved map (.bt/.ot, e.g. the demo flight's) instead of --map/--voxels")
      ->check(CLI::ExistingFile);
  app.add_option("--map-period", map_period,
                 "seconds between full MAP_OCTOMAP messages (aerie-map's default publish period; 0: once)")
      ->capture_default_str();
  app.add_option("--coarsening", coarsening, "display the map this many levels coarser (the viewer's 'v' key)")
      ->capture_default_str();
  app.add_flag("--poses", poses, "also publish a VO_POSE with every stereo frame (the 3D scene changes at 20 Hz)");
  app.add_flag("--always-redraw", opts.always_redraw, "draw every pane every frame, free-running");
  app.add_option("--multisamples", opts.multisamples, "OpenGL multisampling")->capture_default_str();
  app.add_option("--pane-fps", opts.pane_fps, "redraw rate limit of the non-camera panes")->capture_default_str();
  app.add_option("--map-max-quads", opts.map_max_quads, "quad budget of the map display (0: none)")
      ->capture_default_str();
  app.add_option("--snapshot", snapshot, "write a PNG of the window at the end");
  app.add_option("--out", out, "JSON result file");
  CLI11_PARSE(app, argc, argv);

  bus::Bus bus("memq://");
  opts.offscreen = true;
  opts.image_channel = "CAM_STEREO";
  viewer::Viewer v(bus, opts);
  v.add_default_renderers();
  v.start();

  // A map of `voxels` occupied 0.1 m voxels, or a saved one.
  auto tree_ptr = std::make_unique<octomap::OcTree>(0.1);
  std::mt19937 rng(1);
  if (!map_file.empty()) {
    try {
      tree_ptr = map::read_octree_file(map_file);
    } catch (const std::exception& e) {
      std::cerr << "bench_viewer: " << e.what() << "\n";
      return 2;
    }
    map_kind = map_file;
  } else if (map_kind == "floor") {  // one layer of a 30 m square, then a second layer
    for (int i = 0; i < voxels; ++i) {
      const float x = 0.05f + 0.1f * (i % 300), y = 0.05f + 0.1f * ((i / 300) % 300), z = 0.05f + 0.1f * (i / 90000);
      tree_ptr->updateNode(octomap::point3d(x - 15, y - 15, z), true, true);
    }
  } else {  // columns 1..4 voxels high, side chosen for `voxels` in all (mean height 2.5)
    const int side = static_cast<int>(std::ceil(std::sqrt(voxels / 2.5)));
    std::uniform_int_distribution<int> height(1, 4);
    for (int n = 0, i = 0; n < voxels; ++i)
      for (int h = height(rng); h > 0 && n < voxels; --h, ++n)
        tree_ptr->updateNode(octomap::point3d(0.1f * (i % side - side / 2) + 0.05f, 0.1f * (i / side - side / 2) + 0.05f,
                                              0.1f * h - 0.05f),
                             true, true);
  }
  octomap::OcTree& tree = *tree_ptr;
  tree.updateInnerOccupancy();
  tree.prune();  // as aerie-map's tree is
  aerie::octomap_t map{};
  map.full = true;
  map::encode_octree(tree, true, map);
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
      s.utime = util::wall_utime();  // the latency chart shows the real delivery delay
      s.seq = k;
      s.left = image::to_message(left, s.utime, k);
      s.right = image::to_message(right, s.utime, k);
      bus.publish("CAM_STEREO", s);
      if (map_period > 0 && k > 0 && k % std::max<int64_t>(1, std::llround(map_period * 20)) == 0) {
        map.utime = s.utime;
        bus.publish("MAP_OCTOMAP", map);
      }
      if (poses) {  // a 2 m circle at 1.5 m height
        aerie::pose_t p{};
        p.utime = s.utime;
        p.seq = k;
        p.status = aerie::pose_t::OK;
        const double a = 0.01 * static_cast<double>(k);
        p.position[0] = 2 * std::cos(a);
        p.position[1] = 2 * std::sin(a);
        p.position[2] = 1.5;
        p.orientation[0] = 1;
        bus.publish("VO_POSE", p);
      }
      ++published;
      next += std::chrono::milliseconds(50);
      std::this_thread::sleep_until(next);
    }
  });

  auto* oct = dynamic_cast<viewer::OctomapRenderer*>(v.find("octomap"));
  oct->set_coarsening(coarsening);
  while (voxels > 0 && oct->voxels_shown() == 0) v.render_frame();  // map loaded and uploaded
  // Frames in which the camera pane and the 3D scene were drawn (VTK's StartEvent of each pane).
  int64_t image_draws = 0, scene_draws = 0;
  auto counter = [](int64_t& n) {
    auto cb = vtkSmartPointer<vtkCallbackCommand>::New();
    cb->SetClientData(&n);
    cb->SetCallback([](vtkObject*, unsigned long, void* c, void*) { ++*static_cast<int64_t*>(c); });
    return cb;
  };
  v.layout().image->AddObserver(vtkCommand::StartEvent, counter(image_draws));
  v.layout().scene->AddObserver(vtkCommand::StartEvent, counter(scene_draws));
  const int64_t frames0 = v.frames_rendered(), published0 = published;
  const double t0 = util::mono_ms() / 1000, cpu0 = cpu_seconds(RUSAGE_SELF);
  while (util::mono_ms() / 1000 - t0 < seconds) {
    const int64_t before = v.frames_rendered();
    v.render_frame();
    if (v.frames_rendered() == before) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  const double wall = util::mono_ms() / 1000 - t0, cpu = cpu_seconds(RUSAGE_SELF) - cpu0;
  if (!snapshot.empty()) v.snapshot(snapshot);
  run = false;
  camera.join();
  v.stop();
  const double fps = (v.frames_rendered() - frames0) / wall;
  std::ostringstream json;
  json << "{\"map\": \"" << map_kind << "\", \"poses\": " << poses << ", \"voxels_shown\": " << oct->voxels_shown()
       << ", \"quads_shown\": " << oct->quads_shown() << ", \"coarsening_shown\": " << oct->coarsening_shown() << ", \"always_redraw\": " << opts.always_redraw
       << ", \"map_period_s\": " << map_period << ", \"multisamples\": " << opts.multisamples << ", \"seconds\": " << wall << ", \"display_fps\": " << fps
       << ", \"camera_fps\": " << (published - published0) / wall << ", \"camera_pane_fps\": " << image_draws / wall
       << ", \"scene_fps\": " << scene_draws / wall
       << ", \"cpu_percent_of_one_core\": " << 100 * cpu / wall
       << ", \"cpu_ms_per_display_frame\": " << 1000 * cpu / std::max<int64_t>(1, v.frames_rendered() - frames0)
       << "}";
  std::cout << json.str() << std::endl;
  if (!out.empty()) std::ofstream(out) << json.str() << "\n";
  return 0;
}
