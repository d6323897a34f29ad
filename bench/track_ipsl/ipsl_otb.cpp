// Quick OTB one-pass evaluation of IPSL and hierarchical IPSL (the full comparison with the
// other trackers is aerie-bench-track): init on frame 1 from ground truth, single thread,
// per sequence success AUC (IoU thresholds 0..1 step 0.05), precision at 20 px, centre error,
// frames per second (update only) and samples per frame; plus the speed on a synthetic
// 376x240 sequence. Writes <out>/ipsl_otb.csv and prints a table.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "air/track/ipsl/ipsl.hpp"

namespace fs = std::filesystem;
using namespace aerie::track;

namespace {

struct Sequence {
  std::string name;
  std::vector<cv::Mat> frames;
  std::vector<cv::Rect2d> truth;
};

Sequence load(const fs::path& dir) {
  Sequence s;
  s.name = dir.filename().string();
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir / "img")) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  std::ifstream gt(dir / "groundtruth.txt");
  if (!gt) throw std::runtime_error((dir / "groundtruth.txt").string() + ": cannot open");
  std::string line;
  while (std::getline(gt, line)) {
    for (char& c : line)
      if (c == ',' || c == '\t') c = ' ';
    std::istringstream is(line);
    cv::Rect2d r;
    if (is >> r.x >> r.y >> r.width >> r.height) s.truth.push_back(r);
  }
  const size_t n = std::min(files.size(), s.truth.size());
  for (size_t i = 0; i < n; ++i) {
    cv::Mat img = cv::imread(files[i].string(), cv::IMREAD_GRAYSCALE);
    if (img.empty()) throw std::runtime_error(files[i].string() + ": cannot read");
    s.frames.push_back(img);
  }
  s.truth.resize(n);
  return s;
}

double iou(const cv::Rect2d& a, const cv::Rect2d& b) {
  const double inter = (a & b).area();
  const double uni = a.area() + b.area() - inter;
  return uni > 0 ? inter / uni : 0;
}

struct Result {
  double auc = 0, precision20 = 0, cle = 0, fps = 0, samples = 0;
  int lost_frames = 0;
};

std::unique_ptr<Tracker> make(const std::string& name, const aerie::util::Config& cfg, uint64_t seed) {
  if (name == "ipsl") return std::make_unique<IpslTracker>(ipsl_params_from_config(cfg.section("ipsl")), seed);
  if (name == "ipsl-mr")
    return std::make_unique<HierarchicalIpslTracker>(hierarchical_ipsl_params_from_config(cfg.section("ipsl_mr")),
                                                     seed);
  throw std::invalid_argument("unknown tracker '" + name + "' (ipsl, ipsl-mr)");
}

Result run(Tracker& t, const Sequence& s, const fs::path& boxes_out) {
  Result r;
  std::ofstream out(boxes_out);
  std::ofstream frames(fs::path(boxes_out).replace_extension(".frames.csv"));
  frames << "frame,iou,centre_error,confidence,lost,samples,scale,theta\n";
  t.init(s.frames[0], s.truth[0]);
  out << s.truth[0].x << "," << s.truth[0].y << "," << s.truth[0].width << "," << s.truth[0].height << "\n";
  std::vector<double> ious{1.0}, errs{0.0};
  double seconds = 0;
  for (size_t k = 1; k < s.frames.size(); ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    const TrackState st = t.update(s.frames[k]);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const cv::Rect2d b = st.box();
    out << b.x << "," << b.y << "," << b.width << "," << b.height << "\n";
    const cv::Rect2d& g = s.truth[k];
    ious.push_back(iou(b, g));
    errs.push_back(std::hypot(b.x + b.width / 2 - g.x - g.width / 2, b.y + b.height / 2 - g.y - g.height / 2));
    frames << k << "," << ious.back() << "," << errs.back() << "," << st.confidence << "," << st.lost << ","
           << st.samples_evaluated() << "," << st.pose.scale << "," << st.pose.theta << "\n";
    r.samples += st.samples_evaluated();
    r.lost_frames += st.lost;
  }
  const size_t n = ious.size();
  for (int i = 0; i <= 20; ++i) {
    const double th = i * 0.05;
    r.auc += std::count_if(ious.begin(), ious.end(), [&](double v) { return v > th; }) / double(n) / 21.0;
  }
  r.precision20 = std::count_if(errs.begin(), errs.end(), [](double e) { return e <= 20; }) / double(n);
  for (double e : errs) r.cle += e / n;
  r.fps = (n - 1) / seconds;
  r.samples /= double(n - 1);
  return r;
}

// A textured target drifting over a textured 376x240 background (speed only).
Sequence synthetic_376x240(int frames) {
  Sequence s;
  s.name = "synthetic_376x240";
  cv::RNG rng(7);
  cv::Mat bg(240, 376, CV_8U), target(48, 48, CV_8U);
  rng.fill(bg, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(bg, bg, {0, 0}, 2);
  rng.fill(target, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(target, target, {0, 0}, 1.5);
  for (int k = 0; k < frames; ++k) {
    cv::Mat f = bg.clone();
    const int x = 150 + static_cast<int>(40 * std::sin(k * 0.05)), y = 90 + static_cast<int>(30 * std::cos(k * 0.04));
    target.copyTo(f(cv::Rect(x, y, 48, 48)));
    s.frames.push_back(f);
    s.truth.emplace_back(x, y, 48, 48);
  }
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"IPSL / hierarchical IPSL on OTB-layout sequences (one-pass, single thread)"};
  std::string data = "../shared/data/tracking", out = "ipsl_otb_results", config, trackers = "ipsl,ipsl-mr", only;
  uint64_t seed = 1;
  int seeds = 1;
  app.add_option("--data", data, "folder of <SEQ>/img + groundtruth.txt")->capture_default_str();
  app.add_option("--out", out, "output folder")->capture_default_str();
  app.add_option("--config", config, "YAML with sections ipsl: and ipsl_mr: (defaults when absent)");
  app.add_option("--trackers", trackers, "comma-separated: ipsl, ipsl-mr")->capture_default_str();
  app.add_option("--sequences", only, "comma-separated subset of sequences (default: all)");
  app.add_option("--seed", seed, "random seed (the first one with --seeds)")->capture_default_str();
  app.add_option("--seeds", seeds, "runs per tracker and sequence with seeds seed..seed+N-1; means over all")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    cv::setNumThreads(1);
    const auto cfg = config.empty() ? aerie::util::Config() : aerie::util::Config::load(config);
    std::vector<std::string> names, subset;
    for (auto [src, dst] : {std::pair{&trackers, &names}, {&only, &subset}}) {
      std::stringstream ss(*src);
      for (std::string t; std::getline(ss, t, ',');)
        if (!t.empty()) dst->push_back(t);
    }
    std::vector<fs::path> dirs;
    for (const auto& e : fs::directory_iterator(data))
      if (fs::exists(e.path() / "groundtruth.txt") &&
          (subset.empty() || std::count(subset.begin(), subset.end(), e.path().filename().string())))
        dirs.push_back(e.path());
    std::sort(dirs.begin(), dirs.end());
    if (dirs.empty()) throw std::runtime_error(data + ": no <SEQ>/groundtruth.txt found");
    fs::create_directories(out);
    std::ofstream csv(fs::path(out) / "ipsl_otb.csv");
    csv << "tracker,sequence,frames,auc,precision20,cle,fps,samples_per_frame,lost_frames\n";
    std::cout << std::fixed << std::setprecision(3);
    std::map<std::string, Result> mean;
    std::vector<Sequence> seqs;
    for (const auto& d : dirs) seqs.push_back(load(d));
    seqs.push_back(synthetic_376x240(300));
    const double runs = static_cast<double>(dirs.size()) * seeds;
    for (const auto& s : seqs) {
      for (const auto& n : names) {
        fs::create_directories(fs::path(out) / n);
        for (int i = 0; i < seeds; ++i) {
          auto t = make(n, cfg, seed + i);
          const std::string stem = seeds == 1 ? s.name : s.name + ".seed" + std::to_string(seed + i);
          const Result r = run(*t, s, fs::path(out) / n / (stem + ".txt"));
          csv << n << "," << stem << "," << s.frames.size() << "," << r.auc << "," << r.precision20 << "," << r.cle
              << "," << r.fps << "," << r.samples << "," << r.lost_frames << "\n";
          std::cout << std::left << std::setw(8) << n << std::setw(32) << stem << " AUC " << r.auc << "  P20 "
                    << r.precision20 << "  CLE " << std::setw(8) << r.cle << " fps " << std::setw(9) << r.fps
                    << " samples " << r.samples << "  lost " << r.lost_frames << std::endl;
          if (s.name == "synthetic_376x240") continue;  // speed only, not in the OTB mean
          auto& m = mean[n];
          m.auc += r.auc / runs;
          m.precision20 += r.precision20 / runs;
          m.cle += r.cle / runs;
          m.fps += r.fps / runs;
          m.samples += r.samples / runs;
        }
      }
    }
    for (const auto& [n, m] : mean) {
      csv << n << ",MEAN," << 0 << "," << m.auc << "," << m.precision20 << "," << m.cle << "," << m.fps << ","
          << m.samples << ",0\n";
      std::cout << "MEAN " << std::setw(8) << n << " AUC " << m.auc << "  P20 " << m.precision20 << "  CLE " << m.cle
                << "  fps " << m.fps << "  samples " << m.samples << "\n";
    }
  } catch (const std::exception& e) {
    std::cerr << "aerie-bench-ipsl: " << e.what() << "\n";
    return 1;
  }
  // Success and precision plots (matplotlib of the system Python, see NOTES.md).
  const std::string plot = "/usr/bin/python3 " AERIE_SOURCE_DIR "/bench/track_ipsl/plot_ipsl.py '" + out + "'";
  if (std::system(plot.c_str()) != 0) std::cerr << "aerie-bench-ipsl: plotting failed: " << plot << "\n";
  return 0;
}
