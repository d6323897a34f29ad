// aerie-bench-track: OTB one-pass evaluation of Aerie's trackers and OpenCV's references.
//
//   aerie-bench-track --data ../shared/data/tracking --trackers amcmr-ct,opencv-csrt --out out/track
//   aerie-bench-track --data ../shared/data/tracking --trackers dcf,opencv-csrt --folds 2 --grid grid.yaml --out out/cv
//
// For every sequence under --data (<SEQ>/img/* + groundtruth.txt) every tracker is
// initialised on frame 1 from the ground truth and run over all frames, single-threaded.
// Writes <out>/<tracker>/<SEQ>.txt (one x,y,w,h per frame), <out>/results.csv (per tracker
// and sequence), <out>/summary.csv (means over sequences), <out>/curves.csv and the PNG
// success/precision plots (<out>/success.png, <out>/precision.png); also <out>/lost.csv (the
// LOST flag scored like a detector), <out>/attributes.csv and <out>/sequence_attributes.csv
// (per OTB attribute). With --folds K [--grid FILE] the settings of each tracker are chosen by
// k-fold cross-validation over the sequences: <out>/folds.csv, <out>/heldout_summary.csv and
// <out>/candidates.csv (docs/track.md). With --starts K every sequence is also tracked from K - 1
// later frames (OTB's temporal robustness evaluation): each segment is a row of its own, and the
// segments of a sequence share its fold.
#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <algorithm>
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

#include "air/track/eval/attributes.hpp"
#include "air/track/eval/folds.hpp"
#include "air/track/eval/grid.hpp"
#include "air/track/eval/lost.hpp"
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
  std::string tracker, sequence;  // tracker: the instance, "dcf" or "dcf#2" for the grid's candidate 2
  size_t tracker_index = 0, candidate = 0;
  eval::Score score;
  eval::LostScore lost_score;  // of the first run
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

// The instance name of a tracker's candidate: candidate 0 keeps the tracker's name (and today's file paths).
std::string instance_name(const std::string& tracker, size_t candidate) {
  return candidate == 0 ? tracker : tracker + "#" + std::to_string(candidate);
}

std::string csv_quoted(const std::string& s) {
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

struct Setup {
  std::vector<std::string> trackers;
  std::vector<std::vector<eval::Candidate>> candidates;  // [tracker][candidate]
  uint64_t seed = 1;
  int repeats = 1, max_frames = 0;
  cv::Size resize;
  fs::path out;
  bool states = false;
};

// Runs every candidate of every tracker (and run) over one sequence, decoding each frame once.
// Returns one Run per tracker and candidate (the mean over the runs) and writes their box files.
std::vector<Run> track_sequence(const eval::Sequence& seq, const Setup& setup) {
  const auto& trackers = setup.trackers;
  const size_t n = setup.max_frames > 0 ? std::min<size_t>(setup.max_frames, seq.frames.size()) : seq.frames.size();
  // One instance per tracker, candidate and run (seeds seed, seed + 1, ...; OpenCV's trackers run once).
  struct Instance {
    size_t tracker, candidate;
    std::unique_ptr<Tracker> t;
    Run run;
    std::vector<cv::Rect2d> boxes;
    std::vector<TrackState> states;
    std::vector<bool> lost;  // state.lost per frame (false on the init frame)
  };
  std::vector<Instance> inst;
  for (size_t k = 0; k < trackers.size(); ++k) {
    const int r_count = trackers[k].rfind("opencv-", 0) == 0 ? 1 : setup.repeats;
    for (size_t c = 0; c < setup.candidates[k].size(); ++c)
      for (int r = 0; r < r_count; ++r) {
        Instance in{k, c, make_tracker(trackers[k], setup.candidates[k][c].params, setup.seed + r), {}, {}, {}, {}};
        in.run.tracker = instance_name(trackers[k], c);
        in.run.tracker_index = k;
        in.run.candidate = c;
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
    if (!setup.resize.empty()) {
      sx = static_cast<double>(setup.resize.width) / frame.cols;
      sy = static_cast<double>(setup.resize.height) / frame.rows;
      cv::resize(frame, frame, setup.resize, 0, 0, cv::INTER_LINEAR);
    }
    if (i == 0)
      for (auto& b : gt) b = scaled(b, sx, sy);
    for (auto& in : inst) {
      Run& r = in.run;
      if (!r.error.empty()) {
        in.boxes.push_back(in.boxes.back());
        in.lost.push_back(false);
        continue;
      }
      try {
        if (i == 0) {
          in.t->init(frame, gt[0]);
          in.boxes.push_back(gt[0]);
          in.lost.push_back(false);
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
        in.lost.push_back(s.lost);
        if (setup.states) in.states.push_back(s);
      } catch (const std::exception& e) {
        r.error = e.what();
        spdlog::warn("{} on {} frame {}: {}", r.tracker, seq.name, i + 1, e.what());
        in.boxes.push_back(in.boxes.empty() ? gt[0] : in.boxes.back());
        in.lost.push_back(false);
      }
    }
  }
  std::vector<Run> out;
  for (size_t k = 0; k < trackers.size(); ++k)
    for (size_t c = 0; c < setup.candidates[k].size(); ++c) {
      // The mean over the runs of this tracker and candidate; the files are those of the first run.
      Run mean;
      int count = 0;
      for (auto& in : inst) {
        if (in.tracker != k || in.candidate != c) continue;
        in.run.score = eval::score(in.boxes, gt);
        if (count++ == 0) {
          in.run.lost_score = eval::lost_detection(in.lost, in.boxes, gt);
          mean = in.run;
          const fs::path dir = setup.out / in.run.tracker;
          eval::write_boxes(dir / (seq.name + ".txt"), in.boxes);
          if (setup.states && in.states.size() + 1 == n) {
            std::ofstream f(dir / (seq.name + ".states.csv"));
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
      out.push_back(r);
    }
  return out;
}

// <out>/lost.csv: the LOST flag per tracker and sequence and pooled over the sequences (counts added).
void write_lost(const fs::path& out, const std::vector<std::string>& trackers, const std::vector<Run>& runs) {
  std::ofstream f(out / "lost.csv");
  f << "tracker,sequence,episodes,flagged,recall,frames_iou_gt_05,false_alarms,false_alarm_rate\n";
  auto row = [&f](const std::string& tracker, const std::string& sequence, const eval::LostScore& l) {
    f << tracker << ',' << sequence << ',' << l.episodes << ',' << l.flagged << ',' << l.recall() << ','
      << l.frames_iou_gt_05 << ',' << l.false_alarms << ',' << l.false_alarm_rate() << '\n';
  };
  for (const auto& t : trackers) {
    eval::LostScore pooled;
    for (const auto& r : runs)
      if (r.tracker == t) {
        row(t, r.sequence, r.lost_score);
        pooled += r.lost_score;
      }
    row(t, "ALL", pooled);
    spdlog::info("{:>18}  LOST flag: {}/{} episodes flagged within 5 frames, {}/{} false alarms at IoU > 0.5", t,
                 pooled.flagged, pooled.episodes, pooled.false_alarms, pooled.frames_iou_gt_05);
  }
}

// <out>/sequence_attributes.csv (the flags and the statistics behind them) and <out>/attributes.csv
// (per tracker and attribute the means over the sequences that have it).
void write_attributes(const fs::path& out, const std::vector<std::string>& trackers,
                      const std::vector<eval::Sequence>& sequences, const std::vector<eval::Attributes>& attrs,
                      const std::vector<Run>& runs) {
  const auto& names = eval::attribute_names();
  std::ofstream sa(out / "sequence_attributes.csv");
  sa << "sequence,frames,absent_frames";
  for (const auto& a : names) sa << ',' << a;
  sa << ",max_centre_shift_px,fast_steps,steps,min_area_px,small_frames,min_scale,max_scale,scale_frames,"
        "benchmark_tags\n";
  for (size_t s = 0; s < sequences.size(); ++s) {
    const eval::Attributes& a = attrs[s];
    sa << sequences[s].name << ',' << a.frames << ',' << a.absent;
    for (const auto& name : names) sa << ',' << eval::has_attribute(a, name);
    std::string tags;
    for (const auto& t : a.tags) tags += (tags.empty() ? "" : " ") + t;
    sa << ',' << a.max_centre_shift << ',' << a.fast_steps << ',' << a.steps << ',' << a.min_area << ','
       << a.small_frames << ',' << a.min_scale << ',' << a.max_scale << ',' << a.scale_frames << ',' << tags << '\n';
  }
  std::ofstream f(out / "attributes.csv");
  f << "tracker,attribute,sequences,mean_success_auc,mean_precision_20px,mean_centre_error_px\n";
  for (const auto& t : trackers)
    for (const auto& name : names) {
      std::vector<eval::Figures> with;
      for (const auto& r : runs)
        for (size_t s = 0; s < sequences.size(); ++s)
          if (r.tracker == t && r.sequence == sequences[s].name && eval::has_attribute(attrs[s], name))
            with.push_back(eval::figures(r.score));
      const eval::Figures m = eval::mean(with);
      f << t << ',' << name << ',' << with.size() << ',' << m.auc << ',' << m.precision20 << ','
        << m.mean_centre_error << '\n';
    }
}

// <out>/candidates.csv (scores[tracker][candidate][sequence]), <out>/folds.csv and
// <out>/heldout_summary.csv, and the side-by-side table in the log.
void write_folds(const fs::path& out, const Setup& setup, const std::vector<eval::Sequence>& sequences,
                 const std::vector<int>& fold, const std::vector<std::vector<std::vector<eval::Figures>>>& scores) {
  std::ofstream cand(out / "candidates.csv");
  cand << "tracker,candidate,settings,sequence,fold,success_auc,precision_20px,mean_centre_error_px\n";
  for (size_t t = 0; t < setup.trackers.size(); ++t)
    for (size_t c = 0; c < scores[t].size(); ++c)
      for (size_t s = 0; s < sequences.size(); ++s)
        cand << setup.trackers[t] << ',' << c << ',' << csv_quoted(setup.candidates[t][c].settings) << ','
             << sequences[s].name << ',' << fold[s] << ',' << scores[t][c][s].auc << ','
             << scores[t][c][s].precision20 << ',' << scores[t][c][s].mean_centre_error << '\n';
  std::ofstream f(out / "folds.csv");
  f << "tracker,fold,candidate,settings,tuned_sequences,tuned_auc,tuned_p20,tuned_cle,heldout_sequences,heldout_auc,"
       "heldout_p20,heldout_cle\n";
  std::ofstream sum(out / "heldout_summary.csv");
  sum << "tracker,sequences,tuned_auc,tuned_p20,tuned_cle,heldout_auc,heldout_p20,heldout_cle\n";
  const int k = *std::max_element(fold.begin(), fold.end()) + 1;
  std::vector<std::string> names;
  for (const auto& seq : sequences) names.push_back(seq.name);
  const bool loo = k == static_cast<int>(eval::distinct_sequences(names).size());
  spdlog::info("{}-fold cross-validation ({}): settings chosen on the other folds, scored on the fold held out", k,
               loo ? "leave one sequence out" : "sequence i in fold i mod k");
  spdlog::info("{:>18} {:>4} {:>9}  {:>27}  {:>27}", "tracker", "fold", "candidate", "tuned-on  AUC   P20    CLE",
               "held-out  AUC   P20    CLE");
  for (size_t t = 0; t < setup.trackers.size(); ++t) {
    const auto folds = eval::cross_validate(scores[t], fold);
    for (const auto& r : folds) {
      const auto& tu = r.tuned_figures;
      const auto& ho = r.heldout_figures;
      f << setup.trackers[t] << ',' << r.fold << ',' << r.candidate << ','
        << csv_quoted(setup.candidates[t][r.candidate].settings) << ',' << r.tuned.size() << ',' << tu.auc << ','
        << tu.precision20 << ',' << tu.mean_centre_error << ',' << r.heldout.size() << ',' << ho.auc << ','
        << ho.precision20 << ',' << ho.mean_centre_error << '\n';
      spdlog::info("{:>18} {:>4} {:>9}  {:>2} seq {:.3f} {:.3f} {:6.1f}  {:>2} seq {:.3f} {:.3f} {:6.1f}  {}",
                   setup.trackers[t], r.fold, r.candidate, r.tuned.size(), tu.auc, tu.precision20, tu.mean_centre_error,
                   r.heldout.size(), ho.auc, ho.precision20, ho.mean_centre_error,
                   setup.candidates[t][r.candidate].settings);
    }
    const auto h = eval::summarise(folds, scores[t]);
    sum << setup.trackers[t] << ',' << h.sequences << ',' << h.tuned.auc << ',' << h.tuned.precision20 << ','
        << h.tuned.mean_centre_error << ',' << h.heldout.auc << ',' << h.heldout.precision20 << ','
        << h.heldout.mean_centre_error << '\n';
    spdlog::info("{:>18} {:>4} {:>9}  {:>2} fld {:.3f} {:.3f} {:6.1f}  {:>2} seq {:.3f} {:.3f} {:6.1f}",
                 setup.trackers[t], "all", "", folds.size(), h.tuned.auc, h.tuned.precision20,
                 h.tuned.mean_centre_error, h.sequences, h.heldout.auc, h.heldout.precision20,
                 h.heldout.mean_centre_error);
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"OTB one-pass evaluation of Aerie's trackers and OpenCV's reference trackers"};
  std::string data, out = "track-bench", trackers_arg, sequences_arg, config_path, resize_arg, grid_path;
  uint64_t seed = 1;
  int max_frames = 0, repeats = 1, folds = 0, starts = 1;
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
  app.add_option("--starts", starts,
                 "OTB's temporal robustness evaluation: also track every sequence from frames floor(j n / K), "
                 "j = 1 .. K-1 (the next frame with a visible target), each to the end, as the segment <SEQ>@<frame>; "
                 "1 = one pass from frame 1. A sequence's segments share its fold")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  app.add_flag("--no-plots", no_plots, "skip the PNG plots");
  app.add_flag("--states", states, "also write <out>/<tracker>/<SEQ>.states.csv (confidence, lost, IoU per frame)");
  auto* folds_opt = app.add_option(
      "--folds", folds,
      "choose each tracker's settings by K-fold cross-validation over the sequences (2 <= K <= sequences; "
      "K = sequences is leave-one-sequence-out): sequence i of the names sorted goes to fold i mod K; per fold the "
      "candidate with the best mean AUC on the other folds is scored on the fold; writes <out>/folds.csv and "
      "<out>/heldout_summary.csv (tuned-on and held-out figures side by side) and <out>/candidates.csv (every "
      "candidate's figures per sequence)");
  app.add_option("--grid", grid_path,
                 "with --folds: YAML of tracker name -> list of candidate settings, each a map of parameters merged "
                 "over the tracker's section of -c ({} = those base settings); a tracker not named has one candidate. "
                 "Candidate c > 0 writes its boxes to <out>/<tracker>#c/; the other tables show candidate 0")
      ->check(CLI::ExistingFile)
      ->needs(folds_opt);
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error");
  app.footer(
      "Also written: <out>/lost.csv (the LOST flag per tracker and sequence and pooled as ALL: lost episodes = runs of "
      "frames with the target absent or IoU 0, recall = episodes flagged within 5 frames, false alarms = lost on "
      "frames with IoU > 0.5), <out>/attributes.csv (mean AUC/P20/CLE over the sequences with each OTB attribute FM, "
      "LR, OCC, SV) and <out>/sequence_attributes.csv (the flags from the ground truth, in original pixels, and "
      "SOURCE.txt). docs/track.md has the definitions.");
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
    if (starts > 1) {
      std::vector<eval::Sequence> segments;
      for (const auto& seq : sequences)
        for (auto& seg : eval::temporal_segments(seq, starts)) segments.push_back(std::move(seg));
      spdlog::info("temporal robustness: {} segments of {} sequences ({} starts each)", segments.size(),
                   sequences.size(), starts);
      sequences = std::move(segments);
    }
    // Every check before any tracking: the fold count and every candidate of the grid.
    std::vector<int> fold;
    if (folds != 0) {
      std::vector<std::string> names;
      for (const auto& seq : sequences) names.push_back(seq.name);
      try {
        fold = eval::assign_folds(names, folds);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument("--folds: " + std::string(e.what()));
      }
    }
    Setup setup{trackers, {}, seed, repeats, max_frames, resize, out, states};
    setup.candidates = eval::load_grid(grid_path.empty() ? aerie::util::Config() : aerie::util::Config::load(grid_path),
                                       config, trackers);
    fs::create_directories(out);
    for (size_t k = 0; k < trackers.size(); ++k)
      for (size_t c = 0; c < setup.candidates[k].size(); ++c)
        fs::create_directories(fs::path(out) / instance_name(trackers[k], c));

    std::vector<Run> runs;  // candidate 0 of every tracker: results.csv, summary.csv, curves.csv, lost, attributes
    std::vector<std::vector<std::vector<eval::Figures>>> scores(trackers.size());  // [tracker][candidate][sequence]
    for (size_t k = 0; k < trackers.size(); ++k) scores[k].assign(setup.candidates[k].size(), {});
    std::vector<eval::Attributes> attrs;  // from the ground truth in original pixels (before --resize)
    for (const auto& seq : sequences) {
      attrs.push_back(eval::attributes(seq, max_frames > 0 ? static_cast<size_t>(max_frames) : 0));
      for (const Run& r : track_sequence(seq, setup)) {
        scores[r.tracker_index][r.candidate].push_back(eval::figures(r.score));
        if (r.candidate == 0) runs.push_back(r);
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
    write_lost(out, trackers, runs);
    write_attributes(out, trackers, sequences, attrs, runs);
    if (!fold.empty()) write_folds(out, setup, sequences, fold, scores);
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
