// aerie-map-bench: evaluation of the ground map (docs/results/map.md).
//   throughput  points/s inserted, single thread, robust update vs OctoMap insertPointCloud
//               (OctoMap example scan and simulated stereo depth)
//   quality     voxels wrongly occupied / wrongly free against the simulator's exact geometry,
//               robust update vs OctoMap, with realistic stereo noise (OpenCV SGBM or a model)
//   bandwidth   bytes per frame of VO_DEPTH vs raw 16-bit disparity at 376x240 and 752x480
// Each command prints a table and writes CSV (+ JSON) into --out; plot_map.py draws the PNGs.
#include <CLI/CLI.hpp>
#include <octomap/OcTree.h>
#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <random>
#include <sstream>

#include "bench/map/scan_io.hpp"
#include "common/sim/simulation.hpp"
#include "common/spherical/spherical_message.hpp"
#include "ground/map/occupancy.hpp"

namespace fs = std::filesystem;
namespace sim = aerie::sim;
namespace sp = aerie::spherical;
using aerie::map::OccupancyMap;
using aerie::map::OccupancyParams;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// CPU time of the calling thread (s): the machine is shared, so throughput is measured in
// thread CPU time rather than wall time (both are reported).
double thread_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// One frame for the map: points in the world frame and the sensor origin.
struct Frame {
  std::vector<Eigen::Vector3f> points;
  Eigen::Vector3f origin;
  sp::SphericalDepth depth;
  aerie::geometry::SE3 T_world_camera;
};

enum class Noise { Exact, Model, Sgbm };

// Simulated flight -> spherical depth frames (the VO_DEPTH the map receives).
struct SimFrames {
  sim::World world = sim::World::room(sim::WorldConfig{});
  std::vector<Frame> frames;
  double focal_px = 0, baseline = 0;
};

// Disparity noise model: Gaussian sigma_px on every pixel plus a fraction of gross
// mismatches (uniform disparity in [1, max_disparity]): a simple stand-in for SGBM errors.
cv::Mat model_noise_depth(const cv::Mat& depth, double fb, double sigma_px, double outliers, std::mt19937& rng) {
  std::normal_distribution<float> gauss(0.f, static_cast<float>(sigma_px));
  std::uniform_real_distribution<float> uni(0.f, 1.f);
  cv::Mat out(depth.size(), CV_32F);
  for (int v = 0; v < depth.rows; ++v)
    for (int u = 0; u < depth.cols; ++u) {
      const float z = depth.at<float>(v, u);
      float d = static_cast<float>(fb) / z + gauss(rng);
      if (uni(rng) < outliers) d = 1.f + 63.f * uni(rng);
      out.at<float>(v, u) = (std::isfinite(z) && d > 0.5f) ? static_cast<float>(fb) / d : 0.f;
    }
  return out;
}

Frame make_frame(const sp::SphericalDepth& depth, const aerie::geometry::SE3& T_world_camera) {
  Frame frame;
  frame.depth = depth;
  frame.T_world_camera = T_world_camera;
  const Eigen::Matrix3f R = T_world_camera.rotation_matrix().cast<float>();
  frame.origin = T_world_camera.translation().cast<float>();
  for (const auto& p : depth.decode()) frame.points.push_back(R * p + frame.origin);
  return frame;
}

// Renders the demo flight (every `stride`th frame at 20 Hz) and encodes each frame's depth
// as VO_DEPTH would. The frames are cached in `cache` (VO_DEPTH messages) when given:
// rendering and SGBM dominate the run time.
SimFrames simulate(const sim::RigConfig& rig, int stride, int max_frames, Noise noise, float bin_deg,
                   const fs::path& cache = {}, uint64_t world_seed = 1) {
  SimFrames out;
  sim::WorldConfig world_cfg;
  world_cfg.seed = world_seed;
  out.world = sim::World::room(world_cfg);
  sim::StereoSimulation simulation(out.world, rig, sim::Trajectory::demo_flight(out.world), 20.0);
  const auto k = simulation.intrinsics();
  out.focal_px = k.fx;
  out.baseline = k.baseline;
  if (!cache.empty() && fs::exists(cache)) {
    std::ifstream in(cache, std::ios::binary);
    uint32_t n = 0;
    std::vector<uint8_t> bytes;
    while (in.read(reinterpret_cast<char*>(&n), sizeof(n))) {
      bytes.resize(n);
      in.read(reinterpret_cast<char*>(bytes.data()), n);
      aerie::spherical_depth_t msg;
      if (msg.decode(bytes.data(), 0, static_cast<int>(n)) < 0) throw std::runtime_error("corrupt cache " + cache.string());
      out.frames.push_back(make_frame(sp::from_message(msg), *sp::pose_of(msg)));
    }
    std::cout << "(frames from cache " << cache.string() << ")\n";
    return out;
  }
  sp::EncoderConfig enc_cfg;
  enc_cfg.angular_resolution_rad = sp::deg_to_rad(bin_deg);
  const sp::SphericalEncoder encoder({k.fx, k.fy, k.cx, k.cy, k.baseline}, {rig.width, rig.height}, enc_cfg);
  const int n_disp = rig.width > 500 ? 128 : 64;
  auto sgbm = cv::StereoSGBM::create(0, n_disp, 5, 8 * 25, 32 * 25, 1, 0, 10, 100, 2, cv::StereoSGBM::MODE_SGBM);
  std::mt19937 rng(7);
  std::ofstream cache_out;
  if (!cache.empty()) cache_out.open(cache, std::ios::binary);
  for (int i = 0; i < simulation.frame_count() && static_cast<int>(out.frames.size()) < max_frames; i += stride) {
    const sim::StereoFrame f = simulation.frame(i);
    sp::SphericalDepth depth;
    if (noise == Noise::Sgbm) {
      cv::Mat disparity;
      sgbm->compute(f.left, f.right, disparity);
      depth = encoder.encode_disparity(disparity);
    } else {
      const cv::Mat z = noise == Noise::Exact ? f.depth : model_noise_depth(f.depth, k.fx * k.baseline, 0.5, 0.01, rng);
      depth = encoder.encode_depth(z);
    }
    if (cache_out) {
      const auto msg = sp::to_message(depth, f.utime, i, f.T_world_left);
      std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
      msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
      const auto n = static_cast<uint32_t>(bytes.size());
      cache_out.write(reinterpret_cast<const char*>(&n), sizeof(n));
      cache_out.write(reinterpret_cast<const char*>(bytes.data()), n);
    }
    out.frames.push_back(make_frame(depth, f.T_world_left));
  }
  return out;
}

OccupancyParams params_for(double res, double range, const SimFrames* sim_frames) {
  OccupancyParams p;
  p.resolution = res;
  p.sensor_model.max_range = range;
  if (sim_frames) {
    p.stereo.focal_px = sim_frames->focal_px;
    p.stereo.baseline_m = sim_frames->baseline;
  } else {
    p.stereo.disparity_sigma_px = 0;  // a laser scan: no stereo range error
  }
  return p;
}

std::unique_ptr<octomap::OcTree> plain_tree(const OccupancyParams& p) {
  auto t = std::make_unique<octomap::OcTree>(p.resolution);
  t->setProbHit(p.sensor_model.hit);
  t->setProbMiss(p.sensor_model.miss);
  t->setClampingThresMin(p.sensor_model.min);
  t->setClampingThresMax(p.sensor_model.max);
  return t;
}

octomap::Pointcloud to_octomap(const std::vector<Eigen::Vector3f>& pts) {
  octomap::Pointcloud pc;
  pc.reserve(pts.size());
  for (const auto& p : pts) pc.push_back(p.x(), p.y(), p.z());
  return pc;
}

// ------------------------------------------------------------------ throughput

struct Timing {
  double ours_s = 1e30, octomap_s = 1e30;            // thread CPU time, best of the repeats
  double ours_wall_s = 1e30, octomap_wall_s = 1e30;  // wall time, best of the repeats
  size_t points = 0;
};

// Best of `repeats` runs on fresh maps, all frames in each run, the two methods
// alternating in the same run.
Timing time_both(const std::vector<const std::vector<Eigen::Vector3f>*>& clouds, const std::vector<Eigen::Vector3f>& origins,
                 const OccupancyParams& params, int repeats) {
  Timing best;
  std::vector<octomap::Pointcloud> pcs;
  for (const auto* c : clouds) {
    pcs.push_back(to_octomap(*c));
    best.points += c->size();
  }
  for (int r = 0; r < repeats; ++r) {
    auto tree = plain_tree(params);
    auto w0 = std::chrono::steady_clock::now();
    double c0 = thread_cpu_s();
    for (size_t i = 0; i < pcs.size(); ++i)
      tree->insertPointCloud(pcs[i], octomap::point3d(origins[i].x(), origins[i].y(), origins[i].z()),
                             params.sensor_model.max_range);
    best.octomap_s = std::min(best.octomap_s, thread_cpu_s() - c0);
    best.octomap_wall_s = std::min(best.octomap_wall_s, seconds_since(w0));
    OccupancyMap map(params);
    w0 = std::chrono::steady_clock::now();
    c0 = thread_cpu_s();
    for (size_t i = 0; i < clouds.size(); ++i) map.insert_frame(*clouds[i], origins[i]);
    best.ours_s = std::min(best.ours_s, thread_cpu_s() - c0);
    best.ours_wall_s = std::min(best.ours_wall_s, seconds_since(w0));
  }
  return best;
}

struct ThroughputRuns {
  std::vector<double> resolutions{0.05, 0.1, 0.2}, ranges{5.0, 10.0};
  std::vector<std::string> inputs{"scan", "sim"};
  bool has(const std::string& input) const { return std::find(inputs.begin(), inputs.end(), input) != inputs.end(); }
};

int run_throughput(const std::string& scan_path, const fs::path& out, int sim_frames, int repeats,
                   const ThroughputRuns& runs) {
  std::ofstream csv(out / "throughput.csv");
  csv << "input,resolution_m,max_range_m,points,octomap_mpts_s,ours_mpts_s,speedup,octomap_wall_mpts_s,"
         "ours_wall_mpts_s,speedup_wall\n";
  auto report = [&](const std::string& input, double res, double range, const Timing& t) {
    const auto n = static_cast<double>(t.points);
    const double a = n / t.octomap_s / 1e6, b = n / t.ours_s / 1e6;
    const double aw = n / t.octomap_wall_s / 1e6, bw = n / t.ours_wall_s / 1e6;
    std::cout << std::left << std::setw(12) << input << " res " << std::setw(5) << res << " range " << std::setw(4)
              << range << " points " << std::setw(8) << t.points << " CPU: OctoMap " << std::setw(6)
              << std::setprecision(3) << a << " M/s robust " << std::setw(6) << b << " M/s x" << std::setw(5) << b / a
              << " | wall: OctoMap " << std::setw(6) << aw << " robust " << std::setw(6) << bw << " x" << bw / aw << "\n";
    csv << input << "," << res << "," << range << "," << t.points << "," << a << "," << b << "," << b / a << "," << aw
        << "," << bw << "," << bw / aw << "\n";
  };
  if (runs.has("scan")) {
    const auto scan = aerie::map::bench::read_bz2_xyz(scan_path);
    std::cout << "example scan: " << scan.size() << " points (origin 0,0,0)\n";
    for (double range : runs.ranges)
      for (double res : runs.resolutions)
        report("scan", res, range, time_both({&scan}, {Eigen::Vector3f::Zero()}, params_for(res, range, nullptr), repeats));
  }
  if (!runs.has("sim")) return 0;

  const auto s = simulate(sim::RigConfig{}, 4, sim_frames, Noise::Sgbm, 1.0f,
                          out / ("frames_sgbm_s4_n" + std::to_string(sim_frames) + "_b1.bin"));
  std::vector<const std::vector<Eigen::Vector3f>*> clouds;
  std::vector<Eigen::Vector3f> origins;
  for (const auto& f : s.frames) {
    clouds.push_back(&f.points);
    origins.push_back(f.origin);
  }
  std::cout << "simulated flight: " << s.frames.size() << " frames of SGBM depth, 376x240, 1 deg bins\n";
  for (double range : runs.ranges)
    for (double res : runs.resolutions)
      report("sim_sgbm", res, range, time_both(clouds, origins, params_for(res, range, &s), repeats));
  return 0;
}

// ------------------------------------------------------------------ quality

struct Quality {
  size_t occupied = 0, free = 0, artifacts = 0, wrongly_free = 0, solid_known = 0, surface_known = 0,
         surface_occupied = 0, memory = 0, nodes = 0;
};

// Every finest voxel of the map against the exact geometry: artifact = occupied although
// the voxel touches no solid (signed distance of its centre > half its diagonal); wrongly
// free = free although its centre is inside solid; surface voxel = centre within half a
// voxel of a surface.
Quality evaluate(const octomap::OcTree& tree, const sim::World& world) {
  Quality q;
  const double res = tree.getResolution(), half_diag = 0.5 * std::sqrt(3.0) * res;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const bool occ = tree.isNodeOccupied(*it);
    const int n = static_cast<int>(std::lround(it.getSize() / res));
    const double x0 = it.getX() - 0.5 * it.getSize(), y0 = it.getY() - 0.5 * it.getSize(),
                 z0 = it.getZ() - 0.5 * it.getSize();
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k) {
          const Eigen::Vector3d c(x0 + (i + 0.5) * res, y0 + (j + 0.5) * res, z0 + (k + 0.5) * res);
          const double sd = world.signed_distance(c);
          (occ ? q.occupied : q.free) += 1;
          if (occ && sd > half_diag) ++q.artifacts;
          if (sd < 0) {
            ++q.solid_known;
            if (!occ) ++q.wrongly_free;
          }
          if (std::abs(sd) <= 0.5 * res) {
            ++q.surface_known;
            if (occ) ++q.surface_occupied;
          }
        }
  }
  q.memory = tree.memoryUsage();
  q.nodes = tree.size();
  return q;
}

struct Overrides {
  double disparity_sigma = -1, free_margin = -1, visibility = -1;
  int weight_hits = -1;
  std::vector<double> resolutions{0.05, 0.1, 0.2};
  float bin_deg = 1.0f;
  uint64_t seed = 1;
  bool skip_octomap = false;  // parameter studies of the robust update only
  // A parameter study (robust update only or parameters changed): its CSV gets its own name.
  bool study() const {
    return skip_octomap || disparity_sigma >= 0 || free_margin >= 0 || visibility >= 0 || weight_hits >= 0;
  }
  void apply(OccupancyParams& p) const {
    if (disparity_sigma >= 0) p.stereo.disparity_sigma_px = disparity_sigma;
    if (free_margin >= 0) p.stereo.free_margin_sigmas = free_margin;
    if (visibility >= 0) p.visibility_if_occluded = visibility;
    if (weight_hits >= 0) p.stereo.weight_hits = weight_hits != 0;
  }
};

int run_quality(const fs::path& out, Noise noise, int stride, int max_frames, double range, const Overrides& ov) {
  const char* noise_name = noise == Noise::Sgbm ? "sgbm" : noise == Noise::Model ? "model" : "exact";
  std::ostringstream cache_name;
  cache_name << "frames_" << noise_name << "_s" << stride << "_n" << max_frames << "_b" << ov.bin_deg << "_w"
             << ov.seed << ".bin";
  const auto s = simulate(sim::RigConfig{}, stride, max_frames, noise, ov.bin_deg, out / cache_name.str(), ov.seed);
  std::cout << "simulated demo flight in room seed " << ov.seed << ": " << s.frames.size() << " frames (every " << stride
            << "th at 20 Hz), 376x240, noise " << noise_name << ", max range " << range << " m\n";
  std::ofstream csv(out / ("quality_" + std::string(noise_name) + "_w" + std::to_string(ov.seed) +
                           (ov.study() ? "_study" : "") + ".csv"));
  csv << "method,resolution_m,occupied_voxels,free_voxels,artifacts,artifacts_pct,wrongly_free,solid_known,"
         "wrongly_free_pct,surface_occupied_pct,memory_bytes,nodes,seconds\n";
  for (double res : ov.resolutions) {
    auto params = params_for(res, range, &s);
    ov.apply(params);
    auto tree = plain_tree(params);
    OccupancyMap map(params);
    double t_plain = 0, t_ours = 0;
    for (const auto& f : s.frames) {
      auto t0 = std::chrono::steady_clock::now();
      if (!ov.skip_octomap) {
        const auto pc = to_octomap(f.points);
        t0 = std::chrono::steady_clock::now();
        tree->insertPointCloud(pc, octomap::point3d(f.origin.x(), f.origin.y(), f.origin.z()), range);
        t_plain += seconds_since(t0);
      }
      t0 = std::chrono::steady_clock::now();
      map.insert_frame(f.points, f.origin);
      t_ours += seconds_since(t0);
    }
    std::vector<std::tuple<const char*, Quality, double>> results;
    if (!ov.skip_octomap) results.emplace_back("octomap", evaluate(*tree, s.world), t_plain);
    results.emplace_back("robust", evaluate(map.tree(), s.world), t_ours);
    for (const auto& [name, q, t] : results) {
      const double art = 100.0 * static_cast<double>(q.artifacts) / std::max<size_t>(1, q.occupied);
      const double wf = 100.0 * static_cast<double>(q.wrongly_free) / std::max<size_t>(1, q.solid_known);
      const double surf = 100.0 * static_cast<double>(q.surface_occupied) / std::max<size_t>(1, q.surface_known);
      std::cout << "res " << std::setw(5) << res << " " << std::setw(8) << name << " occupied " << std::setw(8)
                << q.occupied << " artifacts " << std::setw(6) << std::setprecision(3) << art << " %  wrongly free "
                << std::setw(6) << wf << " % of " << q.solid_known << " solid  surface occupied " << std::setw(5) << surf
                << " %  memory " << q.memory / 1024 << " KiB  " << t << " s\n";
      csv << name << "," << res << "," << q.occupied << "," << q.free << "," << q.artifacts << "," << art << ","
          << q.wrongly_free << "," << q.solid_known << "," << wf << "," << surf << "," << q.memory << "," << q.nodes
          << "," << t << "\n";
    }
  }
  return 0;
}

// ------------------------------------------------------------------ bandwidth

int run_bandwidth(const fs::path& out, int frames) {
  std::ofstream csv(out / "bandwidth.csv");
  csv << "image,depth,bin_deg,frames,raw_disparity_bytes,vo_depth_bytes_mean,ratio,filled_bins_mean,dense_frames,"
         "encode_ms_mean,surface_error_mean_m,surface_error_p95_m\n";
  for (const bool wvga : {false, true})
    for (const Noise noise : {Noise::Exact, Noise::Sgbm})
    for (const float bin_deg : {0.25f, 0.5f, 1.0f, 2.0f}) {
      const auto rig = wvga ? sim::RigConfig::wvga() : sim::RigConfig::vga_half();
      const char* depth_name = noise == Noise::Sgbm ? "sgbm" : "exact";
      const auto s = simulate(rig, 10, frames, noise, bin_deg);
      // Encoding time alone (the air side's cost), on the exact depth of the first frame.
      sim::StereoSimulation simulation(s.world, rig, sim::Trajectory::demo_flight(s.world), 20.0);
      const auto k = simulation.intrinsics();
      sp::EncoderConfig enc_cfg;
      enc_cfg.angular_resolution_rad = sp::deg_to_rad(bin_deg);
      const sp::SphericalEncoder encoder({k.fx, k.fy, k.cx, k.cy, k.baseline}, {rig.width, rig.height}, enc_cfg);
      const auto f0 = simulation.frame(100);
      const auto te = std::chrono::steady_clock::now();
      constexpr int kEncodeRepeats = 20;
      for (int r = 0; r < kEncodeRepeats; ++r) (void)encoder.encode_depth(f0.depth);
      const double encode_ms = seconds_since(te) * 1e3 / kEncodeRepeats;

      double bytes = 0, bins = 0;
      int dense = 0;
      std::vector<double> errors;
      for (const auto& f : s.frames) {
        const auto msg = sp::to_message(f.depth, 0, 0, f.T_world_camera);
        bytes += msg.getEncodedSize();
        bins += static_cast<double>(f.depth.size());
        dense += msg.nbins == 0;
        for (size_t i = 0; i < f.points.size(); i += 7) errors.push_back(s.world.distance(f.points[i].cast<double>()));
      }
      std::sort(errors.begin(), errors.end());
      const double n = static_cast<double>(s.frames.size());
      const double raw = 2.0 * rig.width * rig.height;
      double mean_err = 0;
      for (double e : errors) mean_err += e;
      mean_err /= static_cast<double>(std::max<size_t>(1, errors.size()));
      const double p95 = errors.empty() ? 0 : errors[errors.size() * 95 / 100];
      const std::string image = std::to_string(rig.width) + "x" + std::to_string(rig.height);
      std::cout << image << " " << depth_name << " bins " << std::setw(4) << bin_deg << " deg: raw 16-bit disparity " << raw
                << " B, VO_DEPTH " << std::setprecision(4) << bytes / n << " B (x" << raw / (bytes / n)
                << " smaller), " << bins / n << " bins/frame, encode " << encode_ms
                << " ms, surface error mean " << mean_err * 100 << " cm p95 " << p95 * 100 << " cm\n";
      csv << image << "," << depth_name << "," << bin_deg << "," << s.frames.size() << "," << raw << "," << bytes / n << ","
          << raw / (bytes / n) << "," << bins / n << "," << dense << "," << encode_ms << "," << mean_err << "," << p95
          << "\n";
    }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"aerie-map-bench: throughput, quality and bandwidth of the ground map (docs/results/map.md)"};
  std::string out_dir = "build/bench-map";
  app.add_option("--out", out_dir, "folder for the CSV results")->capture_default_str();
  app.require_subcommand(1);
  auto* tp = app.add_subcommand("throughput", "points/s inserted: robust update vs OctoMap insertPointCloud");
  std::string scan = "../shared/data/scans/octomap_example_scan/scan.dat.bz2";
  int sim_frames = 60, repeats = 3;
  tp->add_option("--scan", scan, "OctoMap example scan (.bz2, x y z per line)")->capture_default_str();
  tp->add_option("--sim-frames", sim_frames, "simulated SGBM frames")->capture_default_str();
  tp->add_option("--repeats", repeats, "best of N runs")->capture_default_str();
  ThroughputRuns runs;
  tp->add_option("--resolutions", runs.resolutions, "map resolutions (m)")->capture_default_str();
  tp->add_option("--ranges", runs.ranges, "sensor_model/max_range values (m)")->capture_default_str();
  tp->add_option("--inputs", runs.inputs, "scan (OctoMap example scan) and/or sim (simulated SGBM depth)")
      ->check(CLI::IsMember({"scan", "sim"}))
      ->capture_default_str();
  auto* ql = app.add_subcommand("quality", "wrongly occupied / free voxels vs the simulator's exact geometry");
  std::string noise = "sgbm";
  int stride = 4, max_frames = 1000;
  double range = 5.0;
  ql->add_option("--noise", noise, "sgbm (OpenCV StereoSGBM on the rendered pair), model (0.5 px + 1% outliers), exact")
      ->check(CLI::IsMember({"sgbm", "model", "exact"}))
      ->capture_default_str();
  ql->add_option("--stride", stride, "use every Nth frame of the 20 Hz flight")->capture_default_str();
  ql->add_option("--max-frames", max_frames, "at most this many frames")->capture_default_str();
  ql->add_option("--max-range", range, "sensor_model/max_range (m)")->capture_default_str();
  Overrides ov;
  ql->add_option("--resolutions", ov.resolutions, "map resolutions (m)")->capture_default_str();
  ql->add_option("--bin-deg", ov.bin_deg, "spherical bin size of VO_DEPTH (deg)")->capture_default_str();
  ql->add_option("--world-seed", ov.seed, "WorldConfig::seed of the room (layout, textures)")->capture_default_str();
  ql->add_flag("--skip-octomap", ov.skip_octomap, "evaluate the robust update only (parameter studies)");
  ql->add_option("--disparity-sigma", ov.disparity_sigma, "override stereo/disparity_sigma_px");
  ql->add_option("--free-margin", ov.free_margin, "override stereo/free_margin_sigmas");
  ql->add_option("--visibility", ov.visibility, "override visibility_if_occluded");
  ql->add_option("--weight-hits", ov.weight_hits, "override stereo/weight_hits (0/1)");
  auto* bw = app.add_subcommand("bandwidth", "bytes per frame of VO_DEPTH vs raw 16-bit disparity");
  int bw_frames = 40;
  bw->add_option("--frames", bw_frames, "frames (every 10th of the flight)")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    fs::create_directories(out_dir);
    if (*tp) return run_throughput(scan, out_dir, sim_frames, repeats, runs);
    if (*ql)
      return run_quality(out_dir, noise == "sgbm" ? Noise::Sgbm : noise == "model" ? Noise::Model : Noise::Exact, stride,
                         max_frames, range, ov);
    if (*bw) return run_bandwidth(out_dir, bw_frames);
  } catch (const std::exception& e) {
    std::cerr << "aerie-map-bench: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
