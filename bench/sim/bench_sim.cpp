// Simulator speed: stereo frames/s on one thread at 376x240 and 752x480 along the demo
// flight, world build time, intruder-scene frames/s. Prints a table and writes
// <out>/sim_bench.json, <out>/sim_bench.csv and <out>/sim_frames.png (example frames with
// their ground truth: left, right, depth; landing frame and intruder frame with their boxes).
#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "common/sim/intruder.hpp"
#include "common/sim/simulation.hpp"

namespace {

double process_cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);  // all threads of the process
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

struct Timing {
  std::string what;
  int frames = 0;
  double wall = 0, cpu = 0;
  double fps_wall() const { return frames / wall; }
  double fps_cpu() const { return frames / cpu; }
};

template <typename F>
Timing measure(const std::string& what, int frames, F&& body) {
  const auto w0 = std::chrono::steady_clock::now();
  const double c0 = process_cpu_seconds();
  body();
  Timing t{what, frames, std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count(),
           process_cpu_seconds() - c0};
  return t;
}

std::string load_average() {
  double l[3] = {0, 0, 0};
  if (getloadavg(l, 3) != 3) return "unknown";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.2f %.2f %.2f", l[0], l[1], l[2]);
  return buf;
}

cv::Mat to_bgr(const cv::Mat& gray) {
  cv::Mat bgr;
  cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
  return bgr;
}

// A mosaic of example frames (each scaled to 376x240) with their ground truth drawn.
cv::Mat example_frames(const aerie::sim::World& world) {
  using namespace aerie::sim;
  const cv::Size tile(376, 240);
  std::vector<cv::Mat> tiles;
  auto add = [&](const cv::Mat& img) {
    cv::Mat t;
    cv::resize(img, t, tile, 0, 0, cv::INTER_AREA);
    tiles.push_back(t);
  };
  const StereoSimulation demo(world, RigConfig{}, Trajectory::demo_flight(world));
  for (int k : {150, 500}) {
    const StereoFrame f = demo.frame(k);
    add(to_bgr(f.left));
    add(to_bgr(f.right));
    cv::Mat depth8, depth_color;
    f.depth.convertTo(depth8, CV_8U, 255.0 / 10.0);  // 0..10 m
    cv::applyColorMap(depth8, depth_color, cv::COLORMAP_TURBO);
    add(depth_color);
  }
  const StereoSimulation landing = landing_simulation(world);
  for (int k = 0; k < landing.frame_count(); ++k) {
    const StereoFrame f = landing.frame(k);
    if (!f.target_visible || f.target_box.width < 90) continue;
    cv::Mat img = to_bgr(f.left);
    for (int i = 0; i < 4; ++i) cv::line(img, f.target_corners[i], f.target_corners[(i + 1) % 4], {0, 0, 255}, 1, cv::LINE_AA);
    cv::rectangle(img, f.target_box, {0, 255, 0}, 1);
    add(img);
    break;
  }
  IntruderConfig ic;
  ic.frames = 200;
  const IntruderScene intruder(ic);
  for (int k : {0, 199}) {
    const MonoFrame f = intruder.frame(k);
    cv::Mat img = to_bgr(f.image);
    cv::rectangle(img, f.target_box, {0, 255, 0}, 2);
    add(img);
  }
  while (tiles.size() % 3) tiles.push_back(cv::Mat::zeros(tile, CV_8UC3));
  std::vector<cv::Mat> rows;
  for (size_t i = 0; i < tiles.size(); i += 3) {
    cv::Mat row;
    cv::hconcat(std::vector<cv::Mat>(tiles.begin() + i, tiles.begin() + i + 3), row);
    rows.push_back(row);
  }
  cv::Mat out;
  cv::vconcat(rows, out);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Simulator speed benchmark (single thread): stereo frames/s at 376x240 and 752x480."};
  std::string out = "bench-results/sim";
  int frames = 200;
  int threads = 1;
  app.add_option("--out", out, "folder for sim_bench.json and sim_bench.csv")->capture_default_str();
  app.add_option("--frames", frames, "frames rendered per resolution (spread over the demo flight)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--threads", threads, "OpenCV threads (the figure that matters is 1)")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  cv::setNumThreads(threads);

  std::vector<Timing> results;
  aerie::sim::World world;
  results.push_back(measure("world build (default room)", 1, [&] { world = aerie::sim::World::room({}); }));
  const auto demo = aerie::sim::Trajectory::demo_flight(world);

  for (const auto& rig : {aerie::sim::RigConfig::vga_half(), aerie::sim::RigConfig::wvga()}) {
    const aerie::sim::StereoSimulation sim(world, rig, demo);
    const int step = std::max(1, sim.frame_count() / frames);
    int n = 0;
    sim.frame(0);  // warm-up
    results.push_back(measure(
        "stereo " + std::to_string(rig.width) + "x" + std::to_string(rig.height), 0, [&] {
          for (int k = 0; k < sim.frame_count() && n < frames; k += step, ++n) {
            const auto f = sim.frame(k);
            if (f.left.empty()) std::abort();
          }
        }));
    results.back().frames = n;
  }
  {
    aerie::sim::IntruderConfig cfg;
    cfg.frames = frames;
    aerie::sim::IntruderScene scene(cfg);
    results.push_back(measure("intruder 640x480 mono", frames, [&] {
      for (int k = 0; k < frames; ++k) scene.frame(k);
    }));
  }

  const std::string load = load_average();
  std::printf("%-30s %7s %10s %10s %12s %12s\n", "what", "frames", "wall s", "cpu s", "fps (wall)", "fps (cpu)");
  for (const auto& t : results)
    std::printf("%-30s %7d %10.3f %10.3f %12.1f %12.1f\n", t.what.c_str(), t.frames, t.wall, t.cpu, t.fps_wall(),
                t.fps_cpu());
  std::printf("threads: %d, load average before writing: %s, cores: %ld\n", threads, load.c_str(),
              sysconf(_SC_NPROCESSORS_ONLN));

  std::filesystem::create_directories(out);
  std::ofstream csv(out + "/sim_bench.csv");
  csv << "what,frames,wall_s,cpu_s,fps_wall,fps_cpu\n";
  for (const auto& t : results)
    csv << t.what << ',' << t.frames << ',' << t.wall << ',' << t.cpu << ',' << t.fps_wall() << ',' << t.fps_cpu()
        << '\n';
  std::ofstream json(out + "/sim_bench.json");
  json << "{\n  \"threads\": " << threads << ",\n  \"load_average\": \"" << load << "\",\n  \"results\": [\n";
  for (size_t i = 0; i < results.size(); ++i) {
    const auto& t = results[i];
    json << "    {\"what\": \"" << t.what << "\", \"frames\": " << t.frames << ", \"wall_s\": " << t.wall
         << ", \"cpu_s\": " << t.cpu << ", \"fps_wall\": " << t.fps_wall() << ", \"fps_cpu\": " << t.fps_cpu()
         << "}" << (i + 1 < results.size() ? "," : "") << "\n";
  }
  json << "  ]\n}\n";
  cv::imwrite(out + "/sim_frames.png", example_frames(world));
  std::printf("wrote %s/sim_bench.json, sim_bench.csv and sim_frames.png\n", out.c_str());
  return 0;
}
