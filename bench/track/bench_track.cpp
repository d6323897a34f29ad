// aerie-bench-track: OTB one-pass evaluation of Aerie's trackers and OpenCV's references.
//
//   aerie-bench-track --data ../shared/data/tracking --trackers amcmr-ct,opencv-csrt --out out/track
//
// For every sequence under --data (<SEQ>/img/* + groundtruth.txt) every tracker is
// initialised on frame 1 from the ground truth and run over all frames, single-threaded.
// Writes <out>/<tracker>/<SEQ>.txt (one x,y,w,h per frame), <out>/results.csv (per tracker
// and sequence), <out>/summary.csv (means over sequences), <out>/curves.csv and the PNG
// success/precision plots (<out>/success.png, <out>/precision.png).
#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <chrono>
#include <ctime>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "air/track/eval/metrics.hpp"
#include "air/track/eval/sequence.hpp"
#include "air/track/factory.hpp"
#include "common/util/cli.hpp"
#include "common/util/config.hpp"

namespace fs = std::filesystem;
using namespace aerie::track;

namespace {

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

struct Run {
  std::string tracker, sequence;
  eval::Score score;
  int frames = 0;
  double update_seconds = 0;  // wall clock
  double update_cpu_seconds = 0;  // this thread's CPU time (robust against other load on the machine)
  double samples = 0;  // summed over updates
  int lost = 0, redetected = 0;
  std::string error;
  double fps() const { return update_seconds > 0 ? (frames - 1) / update_seconds : 0; }
  double cpu_fps() const { return update_cpu_seconds > 0 ? (frames - 1) / update_cpu_seconds : 0; }
};

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + t.tv_nsec * 1e-9;
}

cv::Rect2d scaled(const cv::Rect2d& b, double sx, double sy) { return {b.x * sx, b.y * sy, b.width * sx, b.height * sy}; }

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"OTB one-pass evaluation of Aerie's trackers and OpenCV's reference trackers"};
  std::string data, out = "track-bench", trackers_arg, sequences_arg, config_path, resize_arg;
  uint64_t seed = 1;
  int max_frames = 0, repeats = 1;
  bool no_plots = false, states = false;
  std::string log_level = "info";
  app.add_option("--data", data, "folder of sequences: <SEQ>/img/* and <SEQ>/groundtruth.txt")->required();
  app.add_option("--out", out, "output folder")->capture_default_str();
  app.add_option("--trackers", trackers_arg,
                 "comma-separated tracker names (default: all of Aerie's and OpenCV's)");
  app.add_option("--sequences", sequences_arg, "comma-separated sequence names (default: all under --data)");
  app.add_option("-c,--config", config_path, "track.yaml (its trackers: sections) or a YAML of tracker sections")
      ->check(CLI::ExistingFile);
  app.add_option("--seed", seed, "seed of every tracker")->capture_default_str();
  app.add_option("--runs", repeats, "runs of each of Aerie's (randomised) trackers with seeds seed, seed+1, ...; "
                                    "the figures are their means, the box files those of the first run")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  app.add_option("--resize", resize_arg, "resize frames and boxes to WxH (e.g. 640x480) before tracking");
  app.add_option("--max-frames", max_frames, "use at most this many frames per sequence (0 = all)");
  app.add_flag("--no-plots", no_plots, "skip the PNG plots");
  app.add_flag("--states", states, "also write <out>/<tracker>/<SEQ>.states.csv (confidence, lost, IoU per frame)");
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error");
  CLI11_PARSE(app, argc, argv);
  aerie::util::init_logging("bench-track", log_level);
  cv::setNumThreads(1);  // single-thread measurements

  try {
    std::vector<std::string> trackers = split(trackers_arg);
    if (trackers.empty()) {
      trackers = aerie_tracker_names();
      for (const auto& n : opencv_tracker_names()) trackers.push_back(n);
    }
    for (const auto& t : trackers)
      if (!is_known_tracker(t)) throw std::invalid_argument("--trackers: unknown tracker '" + t + "'");
    // A full track.yaml has the tracker sections under "trackers:"; a bare file has them at the top.
    aerie::util::Config config = config_path.empty() ? aerie::util::Config() : aerie::util::Config::load(config_path);
    if (config.has("trackers")) config = config.section("trackers");
    cv::Size resize;
    if (!resize_arg.empty() && std::sscanf(resize_arg.c_str(), "%dx%d", &resize.width, &resize.height) != 2)
      throw std::invalid_argument("--resize: expected WxH, got '" + resize_arg + "'");

    auto sequences = eval::find_sequences(data);
    if (!sequences_arg.empty()) {
      const auto wanted = split(sequences_arg);
      std::vector<eval::Sequence> keep;
      for (const auto& w : wanted) {
        auto it = std::find_if(sequences.begin(), sequences.end(), [&](const auto& s) { return s.name == w; });
        if (it == sequences.end()) throw std::invalid_argument("--sequences: no sequence '" + w + "' under " + data);
        keep.push_back(*it);
      }
      sequences = keep;
    }
    if (sequences.empty()) throw std::runtime_error(data + ": no sequences (<SEQ>/img + groundtruth.txt)");
    fs::create_directories(out);
    for (const auto& t : trackers) fs::create_directories(fs::path(out) / t);

    std::vector<Run> runs;
    for (const auto& seq : sequences) {
      const size_t n = max_frames > 0 ? std::min<size_t>(max_frames, seq.frames.size()) : seq.frames.size();
      // One instance per tracker and run (seeds seed, seed + 1, ...; OpenCV's trackers run once).
      struct Instance {
        size_t tracker;
        std::unique_ptr<Tracker> t;
        Run run;
        std::vector<cv::Rect2d> boxes;
        std::vector<TrackState> states;
      };
      std::vector<Instance> inst;
      for (size_t k = 0; k < trackers.size(); ++k) {
        const int r_count = trackers[k].rfind("opencv-", 0) == 0 ? 1 : repeats;
        for (int r = 0; r < r_count; ++r) {
          Instance in{k, make_tracker(trackers[k], config.section(trackers[k]), seed + r), {}, {}, {}};
          in.run.tracker = trackers[k];
          in.run.sequence = seq.name;
          in.run.frames = static_cast<int>(n);
          inst.push_back(std::move(in));
        }
      }
      std::vector<cv::Rect2d> gt(seq.groundtruth.begin(), seq.groundtruth.begin() + n);
      double sx = 1, sy = 1;
      for (size_t i = 0; i < n; ++i) {
        cv::Mat frame = cv::imread(seq.frames[i].string(), cv::IMREAD_COLOR);
        if (frame.empty()) throw std::runtime_error(seq.frames[i].string() + ": cannot read image");
        if (!resize.empty()) {
          sx = static_cast<double>(resize.width) / frame.cols;
          sy = static_cast<double>(resize.height) / frame.rows;
          cv::resize(frame, frame, resize, 0, 0, cv::INTER_LINEAR);
        }
        if (i == 0)
          for (auto& b : gt) b = scaled(b, sx, sy);
        for (auto& in : inst) {
          Run& r = in.run;
          if (!r.error.empty()) {
            in.boxes.push_back(in.boxes.back());
            continue;
          }
          try {
            if (i == 0) {
              in.t->init(frame, gt[0]);
              in.boxes.push_back(gt[0]);
              continue;
            }
            const auto t0 = std::chrono::steady_clock::now();
            const double c0 = thread_cpu_seconds();
            const TrackState s = in.t->update(frame);
            r.update_cpu_seconds += thread_cpu_seconds() - c0;
            r.update_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            r.samples += s.samples_evaluated();
            r.lost += s.lost;
            r.redetected += s.redetected;
            in.boxes.push_back(s.box());
            if (states) in.states.push_back(s);
          } catch (const std::exception& e) {
            r.error = e.what();
            spdlog::warn("{} on {} frame {}: {}", r.tracker, seq.name, i + 1, e.what());
            in.boxes.push_back(in.boxes.empty() ? gt[0] : in.boxes.back());
          }
        }
      }
      for (size_t k = 0; k < trackers.size(); ++k) {
        // The mean over the runs of this tracker; the files are those of the first run.
        Run mean;
        int count = 0;
        for (auto& in : inst) {
          if (in.tracker != k) continue;
          in.run.score = eval::score(in.boxes, gt);
          if (count++ == 0) {
            mean = in.run;
            eval::write_boxes(fs::path(out) / trackers[k] / (seq.name + ".txt"), in.boxes);
            if (states && in.states.size() + 1 == n) {
              std::ofstream f(fs::path(out) / trackers[k] / (seq.name + ".states.csv"));
              f << "frame,x,y,scale,confidence,lost,redetected,samples,iou\n";
              for (size_t i = 1; i < n; ++i) {
                const TrackState& t = in.states[i - 1];
                f << i + 1 << ',' << t.pose.x << ',' << t.pose.y << ',' << t.pose.scale << ',' << t.confidence << ','
                  << t.lost << ',' << t.redetected << ',' << t.samples_evaluated() << ','
                  << eval::iou(in.boxes[i], gt[i]) << '\n';
              }
            }
            continue;
          }
          auto add = [](std::vector<double>& a, const std::vector<double>& b) {
            for (size_t i = 0; i < a.size(); ++i) a[i] += b[i];
          };
          add(mean.score.success, in.run.score.success);
          add(mean.score.precision, in.run.score.precision);
          mean.score.auc += in.run.score.auc;
          mean.score.precision20 += in.run.score.precision20;
          mean.score.mean_centre_error += in.run.score.mean_centre_error;
          mean.update_seconds += in.run.update_seconds;
          mean.update_cpu_seconds += in.run.update_cpu_seconds;
          mean.samples += in.run.samples;
          mean.lost += in.run.lost;
          mean.redetected += in.run.redetected;
          if (mean.error.empty()) mean.error = in.run.error;
        }
        if (count > 1) {
          for (auto& v : mean.score.success) v /= count;
          for (auto& v : mean.score.precision) v /= count;
          mean.score.auc /= count;
          mean.score.precision20 /= count;
          mean.score.mean_centre_error /= count;
          mean.update_seconds /= count;
          mean.update_cpu_seconds /= count;
          mean.samples /= count;
          mean.lost /= count;
          mean.redetected /= count;
        }
        const Run& r = mean;
        spdlog::info("{:>18} {:<26} AUC {:.3f}  P20 {:.3f}  CLE {:7.1f}  {:8.1f} fps ({:8.1f} cpu)  {:6.0f} samples/frame{}",
                     r.tracker, r.sequence, r.score.auc, r.score.precision20, r.score.mean_centre_error, r.fps(), r.cpu_fps(),
                     n > 1 ? r.samples / (n - 1) : 0.0, r.error.empty() ? "" : "  (failed: " + r.error + ")");
        runs.push_back(r);
      }
    }

    // results.csv, summary.csv, curves.csv
    std::ofstream res(fs::path(out) / "results.csv");
    res << "tracker,sequence,frames,success_auc,precision_20px,mean_centre_error_px,fps,cpu_fps,samples_per_frame,"
           "lost_frames,redetections,error\n";
    std::ofstream curves(fs::path(out) / "curves.csv");
    curves << "tracker,sequence,curve,threshold,value\n";
    struct Mean {
      double auc = 0, p20 = 0, cle = 0, fps = 0, cpu_fps = 0, samples = 0;
      int n = 0;
    };
    std::map<std::string, Mean> means;
    const auto st = eval::success_thresholds(), pt = eval::precision_thresholds();
    for (const auto& r : runs) {
      const double spf = r.frames > 1 ? r.samples / (r.frames - 1) : 0;
      res << r.tracker << ',' << r.sequence << ',' << r.frames << ',' << r.score.auc << ',' << r.score.precision20 << ','
          << r.score.mean_centre_error << ',' << r.fps() << ',' << r.cpu_fps() << ',' << spf << ',' << r.lost << ',' << r.redetected << ",\""
          << r.error << "\"\n";
      for (size_t k = 0; k < st.size(); ++k)
        curves << r.tracker << ',' << r.sequence << ",success," << st[k] << ',' << r.score.success[k] << '\n';
      for (size_t k = 0; k < pt.size(); ++k)
        curves << r.tracker << ',' << r.sequence << ",precision," << pt[k] << ',' << r.score.precision[k] << '\n';
      Mean& m = means[r.tracker];
      m.auc += r.score.auc;
      m.p20 += r.score.precision20;
      m.cle += r.score.mean_centre_error;
      m.fps += r.fps();
      m.cpu_fps += r.cpu_fps();
      m.samples += spf;
      ++m.n;
    }
    std::ofstream sum(fs::path(out) / "summary.csv");
    sum << "tracker,sequences,mean_success_auc,mean_precision_20px,mean_centre_error_px,mean_fps,mean_cpu_fps,"
           "mean_samples_per_frame\n";
    spdlog::info("mean over {} sequences:", sequences.size());
    for (const auto& t : trackers) {
      const Mean& m = means[t];
      sum << t << ',' << m.n << ',' << m.auc / m.n << ',' << m.p20 / m.n << ',' << m.cle / m.n << ',' << m.fps / m.n
          << ',' << m.cpu_fps / m.n << ',' << m.samples / m.n << '\n';
      spdlog::info("{:>18}  AUC {:.3f}  P20 {:.3f}  CLE {:7.1f}  {:8.1f} fps ({:8.1f} cpu)  {:6.0f} samples/frame", t,
                   m.auc / m.n, m.p20 / m.n, m.cle / m.n, m.fps / m.n, m.cpu_fps / m.n, m.samples / m.n);
    }
    res.close();
    curves.close();
    sum.close();
    if (!no_plots) {
      const std::string cmd = "/usr/bin/python3 " + std::string(AERIE_TRACK_PLOT_SCRIPT) + " '" + out + "'";
      if (std::system(cmd.c_str()) != 0) spdlog::warn("plotting failed: {}", cmd);
    }
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
  return 0;
}
