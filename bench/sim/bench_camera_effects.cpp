// Camera-effects cost: CPU milliseconds per frame (one thread) of each effect of the stage and
// of all together, at 376x240 and 752x480, on landing frames, beside the ideal render's own
// cost. Prints a table and writes <out>/camera_effects_bench.csv and
// <out>/camera_effects_example.png (a 376x240 landing frame: ideal | every effect on).
#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <ctime>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "common/sim/camera/camera_effects.hpp"
#include "common/sim/camera/camera_effects_config.hpp"
#include "common/sim/simulation.hpp"

namespace {

using aerie::sim::CameraEffectsConfig;

struct Row {
  std::string size, effect;
  double ms = 0;
};

// CPU time of this thread (the stage runs on one): independent of what else loads the machine.
double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

std::vector<std::pair<std::string, CameraEffectsConfig>> effects() {
  std::vector<std::pair<std::string, CameraEffectsConfig>> e;
  CameraEffectsConfig c;
  c.lens.enabled = true;
  c.lens.model.distortion = aerie::camera::Distortion::RadTan;
  c.lens.model.coeffs = {-0.25, 0.06, 1e-3, -5e-4};
  e.emplace_back("lens radial-tangential", c);
  c.lens.model.distortion = aerie::camera::Distortion::Equidistant;
  c.lens.model.coeffs = {-0.013, 0.02, -0.01, 0.003};
  e.emplace_back("lens equidistant", c);
  c = {};
  c.motion.motion_blur = true;
  e.emplace_back("motion blur", c);
  c = {};
  c.motion.rolling_shutter = true;
  c.motion.readout_time_s = 1.0 / 56.03;
  e.emplace_back("rolling shutter", c);
  c = {};
  c.exposure.auto_exposure = true;
  e.emplace_back("auto-exposure", c);
  c = {};
  c.noise.enabled = true;
  e.emplace_back("shot + read noise", c);
  c = {};
  c.jpeg.enabled = true;
  e.emplace_back("jpeg q90", c);
  c = aerie::sim::camera_effects_preset("rpi-camera-module-3");
  c.lens = e[0].second.lens;
  c.jpeg.enabled = true;
  e.emplace_back("all (rpi-camera-module-3 + lens + jpeg)", c);
  return e;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Camera-effects cost per frame (one thread), each effect and all, at 376x240 and 752x480."};
  std::string out = "bench-results/sim";
  int frames = 40;
  double speed = 2.0, yaw_rate = 0.5;
  app.add_option("--out", out, "folder for camera_effects_bench.csv")->capture_default_str();
  app.add_option("--frames", frames, "frames per effect and size (spread over the landing sequence)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--speed", speed, "camera speed across the image during the exposure (m/s)")->capture_default_str();
  app.add_option("--yaw-rate", yaw_rate, "camera rotation about its optical axis (rad/s)")->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);  // prints the help or the error
    return rc == 0 ? 0 : 2;
  }
  cv::setNumThreads(1);

  const aerie::sim::World world = aerie::sim::World::room({});
  std::vector<Row> rows;
  cv::Mat example;
  aerie::sim::CameraMotion motion;
  motion.velocity = {speed, 0.3 * speed, -0.2 * speed};
  motion.angular_velocity = {0.0, 0.0, yaw_rate};
  for (const auto& [w, h] : {std::pair{376, 240}, std::pair{752, 480}}) {
    aerie::sim::RigConfig rig = aerie::sim::landing_rig();
    rig.width = w;
    rig.height = h;
    const auto sim = aerie::sim::landing_simulation(world, rig);
    const std::string size = std::to_string(w) + "x" + std::to_string(h);
    std::vector<aerie::sim::StereoFrame> input;
    double t0 = thread_seconds();
    for (int i = 0; i < frames; ++i) input.push_back(sim.frame(i * (sim.frame_count() - 1) / std::max(1, frames - 1)));
    rows.push_back({size, "ideal render, left + right (reference)", 1e3 * (thread_seconds() - t0) / frames});
    const aerie::camera::CameraModel ideal = sim.intrinsics().calibration().left;
    for (const auto& [name, cfg] : effects()) {
      aerie::sim::CameraEffects fx(cfg, ideal, name);
      t0 = thread_seconds();
      cv::Mat last;
      for (int i = 0; i < frames; ++i) last = fx.apply(input[i].left, input[i].depth, motion, i * 50000, i);
      rows.push_back({size, name, 1e3 * (thread_seconds() - t0) / frames});
      if (w == 376 && name.rfind("all", 0) == 0) cv::hconcat(input[frames - 1].left, last, example);
    }
  }
  std::filesystem::create_directories(out);
  std::ofstream csv(out + "/camera_effects_bench.csv");
  csv << "size,effect,ms_per_frame\n";
  cv::imwrite(out + "/camera_effects_example.png", example);
  std::printf("%-9s %-42s %10s\n", "size", "effect", "ms/frame");
  for (const auto& r : rows) {
    std::printf("%-9s %-42s %10.2f\n", r.size.c_str(), r.effect.c_str(), r.ms);
    csv << r.size << "," << r.effect << "," << r.ms << "\n";
  }
  std::printf("(thread CPU time; motion %.1f m/s, %.2f rad/s; %s/camera_effects_bench.csv)\n", speed, yaw_rate, out.c_str());
  return 0;
}
