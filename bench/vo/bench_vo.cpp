// aerie-bench-vo: runs the stereo VO on a KITTI odometry folder, an EuRoC ASL folder or a
// simulated flight, writes the trajectory (TUM) and scores it against the ground truth
// (ATE after SE3 alignment, RPE per frame and over segments, per-axis RMSE, end-point
// drift, printed only for a loop: eval::is_loop), with the thread CPU time of every stage.
// Ground truth comes from the dataset's own layout (eval::kGroundTruthLayouts) or --groundtruth.
// --mono also runs the monocular VO (air/mono) on the left images of the same frames, scored
// after Sim(3) alignment (its scale is arbitrary) from the frame its first map was made, and
// prints both in one table (docs/results/stereo.md, "Monocular VO").
#include <CLI/CLI.hpp>
#include <opencv2/core/utility.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "air/mono/mono_config.hpp"
#include "air/stereo/cpu_time.hpp"
#include "air/stereo/vo/vo_config.hpp"
#include "common/sim/simulation.hpp"
#include "common/util/time.hpp"
#include "tools/eval/report.hpp"
#include "tools/eval/stereo_dataset.hpp"

namespace fs = std::filesystem;
using namespace aerie;

namespace {

// A frame source: a dataset folder or the simulator.
struct Source {
  std::string name;
  stereo::StereoCamera cam;
  std::shared_ptr<eval::Trajectory> gt = std::make_shared<eval::Trajectory>();  // sim: filled as frames come
  std::function<bool(size_t, cv::Mat&, cv::Mat&, int64_t&)> next;
  std::shared_ptr<cv::Mat> exact = std::make_shared<cv::Mat>();  // sim: the exact disparity of the last frame
  size_t frames = 0;
  double path_m = 0;  // ground-truth path length known in advance (sim), else 0
};

Source open_dataset(const std::string& spec, const std::string& groundtruth, bool exact_depth) {
  Source s;
  const auto colon = spec.find(':');
  const std::string kind = spec.substr(0, colon), arg = colon == std::string::npos ? "" : spec.substr(colon + 1);
  if (kind == "sim") {
    if (!groundtruth.empty()) throw std::invalid_argument("--groundtruth: a sim: dataset has its own ground truth");
    const util::Config cfg = arg.empty() ? util::Config() : util::Config::load(arg);
    sim::WorldConfig wc;
    wc.seed = cfg.get<uint64_t>("world.seed", wc.seed);
    sim::RigConfig rig;
    rig.width = cfg.get<int>("rig.width", rig.width);
    rig.height = cfg.get<int>("rig.height", rig.height);
    rig.noise_sigma = cfg.get<double>("rig.noise_sigma", 1.0);
    rig.pitch_deg = cfg.get<double>("rig.pitch_deg", rig.pitch_deg);
    rig.illumination_amplitude = cfg.get<double>("rig.illumination_amplitude", rig.illumination_amplitude);
    rig.disparity = exact_depth;
    const std::string traj = cfg.get<std::string>("trajectory.kind", "survey_loops");
    const double speed = cfg.get<double>("trajectory.speed", 1.0);
    const double rate = cfg.get<double>("rate_hz", 20.0);
    auto world = std::make_shared<sim::World>(sim::World::room(wc));
    sim::Trajectory t = traj == "demo_flight" ? sim::Trajectory::demo_flight(*world, speed)
                        : traj == "survey_loops"
                            ? sim::Trajectory::survey_loops(*world, cfg.get<int>("trajectory.loops", 1), speed)
                            : throw std::runtime_error(arg + ": trajectory.kind must be survey_loops or demo_flight");
    auto simulation = std::make_shared<sim::StereoSimulation>(*world, rig, t, rate);
    const auto K = simulation->intrinsics();
    s.cam = {K.fx, K.fy, K.cx, K.cy, K.baseline, K.width, K.height};
    s.frames = static_cast<size_t>(simulation->frame_count());
    s.path_m = t.length();
    s.name = "sim " + traj + " " + std::to_string(rig.width) + "x" + std::to_string(rig.height);
    s.next = [simulation, gt = s.gt, exact = s.exact](size_t, cv::Mat& l, cv::Mat& r, int64_t& utime) {
      sim::StereoFrame f;
      if (!simulation->next(f)) return false;
      l = f.left;
      r = f.right;
      utime = f.utime;
      gt->push_back(static_cast<double>(f.utime) * 1e-6, f.T_world_left);
      if (!f.disparity.empty()) {
        *exact = f.disparity;
        exact->setTo(-1.0f, f.disparity != f.disparity);  // NaN: nothing hit
      }
      return true;
    };
    return s;
  }
  std::shared_ptr<eval::StereoSequence> seq = eval::open_sequence(spec, groundtruth);
  const auto& rig = seq->rig();
  s.cam = {rig.fx, rig.fy, rig.cx, rig.cy, rig.baseline, rig.size.width, rig.size.height};
  s.frames = seq->size();
  *s.gt = seq->ground_truth();
  s.name = kind + " " + seq->name();
  s.next = [seq](size_t i, cv::Mat& l, cv::Mat& r, int64_t& utime) {
    if (i >= seq->size()) return false;
    seq->load(i, l, r);
    utime = seq->utime(i);
    return true;
  };
  return s;
}

struct Mean {
  double sum = 0;
  int n = 0;
  void add(double v) {
    sum += v;
    ++n;
  }
  double value() const { return n ? sum / n : 0; }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Stereo VO evaluation on KITTI / EuRoC folders or a simulated flight"};
  app.footer(std::string("Ground truth found by itself: ") + eval::kGroundTruthLayouts +
             "; any other file with --groundtruth.");
  std::string dataset, groundtruth, config, out = "vo_trajectory.txt", json_path, plot;
  size_t max_frames = 0;
  double rpe_delta_m = 0;
  bool ba_sync = true, exact_depth = false, with_mono = false;
  std::string mono_config, mono_out = "mono_trajectory.txt";
  app.add_option("--dataset", dataset, "kitti:DIR, euroc:DIR or sim:CONFIG.yaml")->required();
  app.add_option("--groundtruth", groundtruth,
                 std::string("ground truth instead of the folder's own, format detected from the content: ") +
                     eval::kTrajectoryFormats + "; kitti: the left camera's poses (KITTI poses stamped by "
                     "times.txt), euroc: the body's (TUM or EuRoC CSV)")
      ->check(CLI::ExistingFile);
  app.add_option("-c,--config", config, "VO configuration (config/vo.yaml format)")->check(CLI::ExistingFile);
  app.add_option("--out", out, "trajectory output (TUM: t x y z qx qy qz qw)");
  app.add_option("--json", json_path, "results as JSON");
  app.add_option("--plot", plot, "PNG of the trajectory and its errors (needs /usr/bin/python3 + matplotlib)");
  app.add_option("--max-frames", max_frames, "stop after this many frames (0 = all)");
  app.add_option("--rpe-delta-m", rpe_delta_m, "also RPE over path segments of this length (m)");
  app.add_option("--ba-sync", ba_sync, "wait for each bundle adjustment (reproducible figures; false = as flown)");
  app.add_flag("--exact-depth", exact_depth, "sim only: use the renderer's exact disparity instead of SGBM_F "
                                          "(separates depth errors from tracking errors)");
  app.add_flag("--mono", with_mono, "also run the monocular VO on the left images (scored after Sim(3) alignment)");
  app.add_option("--mono-config", mono_config, "monocular VO configuration (config/mono.yaml format)")
      ->check(CLI::ExistingFile);
  app.add_option("--mono-out", mono_out, "monocular trajectory output (TUM), from its first map on");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);  // prints the help or the error
    return rc == 0 ? 0 : 2;
  }
  // Single thread: the stage timings are thread CPU time, which would miss work that OpenCV
  // hands to its pool. The bundle adjuster keeps its own thread.
  cv::setNumThreads(1);
  try {
    stereo::VoParams params =
        config.empty() ? stereo::VoParams{} : stereo::vo_params_from_config(util::Config::load(config), stereo::kNodeSections);
    params.ba_synchronous = ba_sync;
    Source src = open_dataset(dataset, groundtruth, exact_depth);
    if (exact_depth && dataset.rfind("sim:", 0) != 0) throw std::runtime_error("--exact-depth needs a sim: dataset");
    stereo::StereoOdometry vo(src.cam, params);
    mono::MonoParams mono_params = mono_config.empty() ? mono::MonoParams{}
                                                       : mono::mono_params_from_config(util::Config::load(mono_config),
                                                                                       mono::kMonoNodeSections);
    mono_params.ba_synchronous = ba_sync;
    std::unique_ptr<mono::MonoOdometry> mvo;
    if (with_mono)
      mvo = std::make_unique<mono::MonoOdometry>(
          mono::PinholeCamera{src.cam.fx, src.cam.fy, src.cam.cx, src.cam.cy, src.cam.width, src.cam.height}, mono_params);
    eval::Trajectory mono_est;
    int mono_first = -1, mono_lost = 0, mono_resets = 0, mono_keyframes = 0;
    double mono_front_ms = 0, mono_process_ms = 0;
    std::string mono_init;
    std::cout << src.name << ": " << src.frames << " frames " << src.cam.width << "x" << src.cam.height
              << ", f " << src.cam.fx << " px, baseline " << src.cam.baseline << " m, SGM SIMD "
              << stereo::SemiGlobalMatcher::simd_target() << "\n";

    eval::Trajectory est;
    Mean depth, features, matching, motion, book, total, total_nodepth, wall;
    int lost = 0, keyframes = 0, ba_applied = 0;
    double inlier_ratio = 0;
    int64_t utime = 0;
    cv::Mat l, r;
    // The whole cost: the process's CPU (front end + the bundle adjuster's thread) inside the
    // VO's calls (not the image loading), and the front end's own thread; their difference is
    // the bundle adjuster's (with --ba-sync it runs within the calls).
    double process_ms = 0, thread_ms = 0;
    for (size_t i = 0; (max_frames == 0 || i < max_frames) && src.next(i, l, r, utime); ++i) {
      util::Stopwatch sw;
      const double p0 = stereo::process_cpu_ms(), t0 = stereo::cpu_ms();
      const stereo::VoResult res = exact_depth ? vo.process_with_disparity(l, r, utime, *src.exact)
                                               : vo.process(l, r, utime);
      process_ms += stereo::process_cpu_ms() - p0;
      thread_ms += stereo::cpu_ms() - t0;
      wall.add(sw.ms());
      est.push_back(static_cast<double>(utime) * 1e-6, res.T_world_cam);
      const auto& t = res.timings;
      depth.add(t.depth);
      features.add(t.features);
      matching.add(t.matching);
      motion.add(t.motion);
      book.add(t.bookkeeping);
      total.add(t.total());
      if (!res.depth_computed) total_nodepth.add(t.total());
      lost += res.status == stereo::VoStatus::Lost;
      keyframes += res.keyframe;
      ba_applied += res.ba_applied;
      inlier_ratio += res.inlier_ratio;
      if (res.status == stereo::VoStatus::Lost || res.status == stereo::VoStatus::Reset)
        std::cout << "frame " << res.frame << ": " << stereo::to_string(res.status) << " - " << res.message << "\n";
      if (mvo) {
        // The monocular VO on the left image; with --ba-sync its BA runs inside the call, so
        // the process CPU of the call is the whole node's.
        const double mp0 = stereo::process_cpu_ms(), mt0 = stereo::cpu_ms();
        const mono::MonoResult mr = mvo->process(l, utime);
        mono_process_ms += stereo::process_cpu_ms() - mp0;
        mono_front_ms += stereo::cpu_ms() - mt0;
        if (mono_first < 0 && mr.status != mono::MonoStatus::Initialising && mr.status != mono::MonoStatus::Lost) {
          mono_first = static_cast<int>(i);
          mono_init = mr.message;
        }
        if (mono_first >= 0) mono_est.push_back(static_cast<double>(utime) * 1e-6, mr.T_world_cam);
        mono_lost += mr.status == mono::MonoStatus::Lost;
        mono_resets += mr.status == mono::MonoStatus::Reset;
        mono_keyframes += mr.keyframe;
        if (mr.status == mono::MonoStatus::Lost || mr.status == mono::MonoStatus::Reset)
          std::cout << "mono frame " << mr.frame << ": " << mono::to_string(mr.status) << " - " << mr.message << "\n";
        if (i + 1 == src.frames && mono_first < 0) mono_init = mr.message;
      }
    }
    if (mvo) mvo->flush();
    const double p0 = stereo::process_cpu_ms(), t0 = stereo::cpu_ms();
    vo.flush();
    process_ms += stereo::process_cpu_ms() - p0;
    thread_ms += stereo::cpu_ms() - t0;
    eval::write_tum(est, out);
    const int n = static_cast<int>(est.size());
    const double ba_ms = process_ms - thread_ms;
    std::cout << std::fixed << std::setprecision(2) << n << " frames, " << keyframes << " keyframes, " << lost
              << " lost, mean inlier ratio " << inlier_ratio / std::max(1, n) << "\n"
              << "CPU ms per frame: depth " << depth.value() << "  features " << features.value() << "  matching "
              << matching.value() << "  motion " << motion.value() << "  other " << book.value() << "  = total "
              << total.value() << " (" << 1000.0 / total.value() << " fps; frames without depth "
              << total_nodepth.value() << " ms); wall " << wall.value() << " ms\n"
              << "CPU ms per frame with the bundle adjuster's thread: " << process_ms / std::max(1, n)
              << " (front end " << thread_ms / std::max(1, n) << ", bundle adjustment " << ba_ms / std::max(1, n)
              << " = " << ba_ms / std::max(1, keyframes) << " per keyframe, " << ba_applied << " results applied)\n";

    std::ostringstream js;
    js << std::setprecision(8) << "{\"dataset\": \"" << src.name << "\", \"frames\": " << n
       << ", \"width\": " << src.cam.width << ", \"height\": " << src.cam.height << ", \"keyframes\": " << keyframes
       << ", \"lost\": " << lost << ", \"ba_synchronous\": " << (ba_sync ? "true" : "false")
       << ", \"ms\": {\"depth\": " << depth.value() << ", \"features\": " << features.value()
       << ", \"matching\": " << matching.value() << ", \"motion\": " << motion.value()
       << ", \"other\": " << book.value() << ", \"total\": " << total.value()
       << ", \"total_without_depth\": " << total_nodepth.value() << ", \"wall\": " << wall.value()
       << ", \"process_per_frame\": " << process_ms / std::max(1, n) << ", \"ba_per_keyframe\": "
       << ba_ms / std::max(1, keyframes)
       << "}, \"fps\": " << 1000.0 / total.value();
    if (!src.gt->empty()) {
      eval::ReportOptions ro;
      ro.max_dt = 0.002;
      ro.rpe_delta_m = rpe_delta_m;
      const eval::Report rep = eval::evaluate(*src.gt, est, ro);
      eval::print(std::cout, rep, ro);
      js << ", \"metrics\": " << eval::to_json(rep, ro);
      if (mvo) {
        // One table: the stereo VO (SE3 alignment) and the monocular one (Sim(3), from its first map).
        std::cout << "\n| sequence | VO | frames scored | ATE RMSE m | RPE % | RPE deg/frame | front end ms/frame | "
                     "with BA ms/frame |\n|---|---|---|---|---|---|---|---|\n"
                  << "| " << src.name << " | stereo (SE3) | " << rep.matched << " | " << std::setprecision(3)
                  << rep.ate.rmse << " | " << rep.rpe_trans_percent << " | " << rep.rpe_rot.rmse << " | "
                  << thread_ms / std::max(1, n) << " | " << process_ms / std::max(1, n) << " |\n";
        js << ", \"mono\": {\"first_frame\": " << mono_first << ", \"lost\": " << mono_lost
           << ", \"resets\": " << mono_resets << ", \"keyframes\": " << mono_keyframes
           << ", \"ms_front_end\": " << mono_front_ms / std::max(1, n)
           << ", \"ms_with_ba\": " << mono_process_ms / std::max(1, n);
        if (mono_est.size() >= 3) {
          // Sim(3) first (Umeyama with scale), then every metric on the scaled estimate: the
          // RPE of an unscaled monocular trajectory would measure its arbitrary scale.
          const auto a = eval::associate(*src.gt, mono_est, ro.max_dt);
          eval::Similarity sim3;
          const eval::Trajectory scaled = eval::align(a.est, a.ref, eval::Alignment::Sim3, &sim3);
          const eval::Report mrep = eval::evaluate(a.ref, scaled, ro);  // SE3 on top: the identity
          js << ", \"sim3_scale\": " << sim3.scale;
          std::cout << "| " << src.name << " | mono (Sim3, scale " << sim3.scale << ") | " << mrep.matched
                    << " | " << mrep.ate.rmse << " | " << mrep.rpe_trans_percent << " | " << mrep.rpe_rot.rmse << " | "
                    << mono_front_ms / std::max(1, n) << " | " << mono_process_ms / std::max(1, n) << " |\n";
          js << ", \"metrics\": " << eval::to_json(mrep, ro);
        } else {
          std::cout << "| " << src.name << " | mono | 0 (not initialised) | - | - | - | " << mono_front_ms / std::max(1, n)
                    << " | " << mono_process_ms / std::max(1, n) << " |\n";
        }
        js << "}";
        std::cout << std::setprecision(2) << "mono: first map at frame " << mono_first << " (" << mono_init << "), "
                  << mono_keyframes << " keyframes, " << mono_lost << " lost, " << mono_resets << " resets\n";
        eval::write_tum(mono_est, mono_out);
      }
      if (!plot.empty()) {
        // Aligned estimate and ground truth for the plot script.
        const auto a = eval::associate(*src.gt, est, ro.max_dt);
        const auto aligned = eval::align(a.est, a.ref, eval::Alignment::SE3);
        const fs::path csv = fs::path(plot).replace_extension(".csv");
        std::ofstream c(csv);
        c << "t,gx,gy,gz,ex,ey,ez\n" << std::fixed << std::setprecision(6);  // absolute stamps (EuRoC: 1.4e9 s)
        for (size_t i = 0; i < a.ref.size(); ++i) {
          const auto& g = a.ref.poses[i].translation();
          const auto& e = aligned.poses[i].translation();
          c << a.ref.stamps[i] << ',' << g.x() << ',' << g.y() << ',' << g.z() << ',' << e.x() << ',' << e.y() << ','
            << e.z() << '\n';
        }
        c.close();
        const fs::path script = fs::path(AERIE_BENCH_VO_DIR) / "plot_vo.py";
        const std::string cmd = "/usr/bin/python3 '" + script.string() + "' '" + csv.string() + "' '" + plot +
                                "' '" + src.name + "'";
        if (std::system(cmd.c_str()) != 0) std::cerr << "plot failed: " << cmd << "\n";
      }
    } else {
      const eval::Drift d = eval::end_point_drift({}, est);
      std::cout << "no ground truth (" << eval::kGroundTruthLayouts
                << "; or give --groundtruth FILE); end point " << d.loop_closure_m << " m from the start\n";
      js << ", \"end_point_m\": " << d.loop_closure_m;
    }
    js << "}\n";
    if (!json_path.empty()) std::ofstream(json_path) << js.str();
    std::cout << "trajectory: " << out << "\n";
  } catch (const std::exception& e) {
    std::cerr << "aerie-bench-vo: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
