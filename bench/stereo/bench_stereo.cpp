// aerie-bench-stereo: accuracy and single-thread speed of SGBM_F (coarse-to-fine), our
// full-range SGM and OpenCV's StereoBM / StereoSGBM (MODE_SGBM, MODE_HH, MODE_SGBM_3WAY)
// on stereo pairs with ground-truth disparity (Middlebury, KITTI 2015).
#include <CLI/CLI.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <regex>
#include <sstream>

#include "air/stereo/sgbm_ctf/sgbm_ctf.hpp"
#include "air/stereo/cpu_time.hpp"

namespace fs = std::filesystem;
using aerie::stereo::kInvalidDisparity;

namespace {

struct Pair {
  std::string name;
  cv::Mat left, right;  // gray
  cv::Mat gt;           // CV_32F, <= 0 unknown
  int num_disparities = 64;
};

// Ground-truth scale from the folder's SOURCE.txt ("disparity = value / N").
double gt_scale(const fs::path& dir) {
  std::ifstream in(dir / "SOURCE.txt");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::smatch m;
  if (!std::regex_search(text, m, std::regex(R"(disparity\s*=\s*value\s*/\s*([0-9.]+))")))
    throw std::runtime_error((dir / "SOURCE.txt").string() + ": no 'disparity = value / N' scale found");
  return std::stod(m[1]);
}

cv::Mat read(const fs::path& p, int flags) {
  cv::Mat m = cv::imread(p.string(), flags);
  if (m.empty()) throw std::runtime_error(p.string() + ": cannot read image");
  return m;
}

Pair load_pair(const fs::path& dir) {
  Pair p;
  p.name = dir.filename().string();
  fs::path l, r, g;
  if (fs::exists(dir / "training")) {  // KITTI 2015 layout
    for (const auto& e : fs::directory_iterator(dir / "training/image_2")) l = e.path();
    r = dir / "training/image_3" / l.filename();
    g = dir / "training/disp_occ_0" / l.filename();
  } else {  // Middlebury: im<L>.png, im<R>.png (L < R), disp<L>.{png,pgm}
    std::vector<fs::path> ims;
    for (const auto& e : fs::directory_iterator(dir)) {
      const auto n = e.path().filename().string();
      if (n.rfind("im", 0) == 0) ims.push_back(e.path());
      if (n.rfind("disp", 0) == 0) g = e.path();
    }
    std::sort(ims.begin(), ims.end());
    if (ims.size() != 2 || g.empty()) throw std::runtime_error(dir.string() + ": expected im*.png x2 and disp*");
    l = ims[0];
    r = ims[1];
  }
  p.left = read(l, cv::IMREAD_GRAYSCALE);
  p.right = read(r, cv::IMREAD_GRAYSCALE);
  cv::Mat raw = read(g, cv::IMREAD_ANYDEPTH | cv::IMREAD_GRAYSCALE);
  raw.convertTo(p.gt, CV_32F, 1.0 / gt_scale(dir));
  double mx;
  cv::minMaxLoc(p.gt, nullptr, &mx);
  p.num_disparities = std::max(16, static_cast<int>(std::ceil((mx + 1) / 16.0)) * 16);
  return p;
}

struct Score {
  double bad[3] = {0, 0, 0};      // % of GT pixels with an estimate whose error exceeds 1/2/3 px
  double bad_all[3] = {0, 0, 0};  // same, missing estimates counted as bad
  double density = 0;             // % of GT pixels with an estimate
  double image_density = 0;       // % of all pixels with an estimate (eta)
};

Score score(const cv::Mat& disp, const cv::Mat& gt) {
  Score s;
  long n_gt = 0, n_est = 0, n_any = 0, bad[3] = {0, 0, 0};
  for (int y = 0; y < gt.rows; ++y)
    for (int x = 0; x < gt.cols; ++x) {
      const float d = disp.at<float>(y, x);
      if (d >= 0) ++n_any;
      const float g = gt.at<float>(y, x);
      if (g <= 0) continue;
      ++n_gt;
      if (d < 0) continue;
      ++n_est;
      for (int k = 0; k < 3; ++k)
        if (std::abs(d - g) > k + 1) ++bad[k];
    }
  for (int k = 0; k < 3; ++k) {
    s.bad[k] = n_est ? 100.0 * bad[k] / n_est : 100.0;
    s.bad_all[k] = n_gt ? 100.0 * (bad[k] + n_gt - n_est) / n_gt : 100.0;
  }
  s.density = n_gt ? 100.0 * n_est / n_gt : 0;
  s.image_density = 100.0 * n_any / static_cast<double>(gt.total());
  return s;
}

cv::Mat from_opencv(const cv::Mat& d16) {  // CV_16S x16 -> CV_32F, invalid -1
  cv::Mat d;
  d16.convertTo(d, CV_32F, 1.0 / 16);
  d.setTo(kInvalidDisparity, d16 < 0);
  return d;
}

// Thread CPU time (cpu_time.hpp) of each method, the fastest of `repeats` rounds. The
// methods run in turn within every round, so that a change of the machine's load (it is
// shared with other jobs) affects them all alike; the minimum is the figure least disturbed.
template <class Method>
std::vector<double> best_ms(int repeats, const std::vector<Method>& methods) {
  std::vector<double> best(methods.size(), 1e30);
  for (int round = 0; round < repeats; ++round)
    for (size_t i = 0; i < methods.size(); ++i) {
      aerie::stereo::CpuStopwatch sw;
      methods[i].run();
      best[i] = std::min(best[i], sw.ms());
    }
  return best;
}

void write_colour(const cv::Mat& disp, int D, const fs::path& path) {
  cv::Mat u8, colour;
  disp.convertTo(u8, CV_8U, 255.0 / D);
  cv::applyColorMap(u8, colour, cv::COLORMAP_JET);
  colour.setTo(cv::Scalar::all(0), disp < 0);
  cv::imwrite(path.string(), colour);
}

}  // namespace

int main(int argc, char** argv) try {
  CLI::App app{"Stereo matching benchmark: SGBM_F vs full-range SGM vs OpenCV BM/SGBM, single thread"};
  std::string pairs_dir = "../shared/data/stereo_pairs", out_dir = "bench-stereo-out";
  int repeats = 9, block = 5, fine_window = 16;
  aerie::stereo::SgmParams sgm;
  app.add_option("--pairs", pairs_dir, "folder of stereo pairs with GT disparity (one subfolder each)")
      ->check(CLI::ExistingDirectory);
  app.add_option("--out", out_dir, "folder for results.csv, results.json and disparity PNGs");
  app.add_option("--repeats", repeats, "timed rounds over all methods (the fastest run of each is reported)")->check(CLI::PositiveNumber);
  app.add_option("--block", block, "OpenCV block size (P1 = 8 b^2, P2 = 32 b^2 as OpenCV recommends)");
  app.add_option("--fine-window", fine_window, "SGBM_F disparities searched per pixel at full resolution");
  app.add_option("--p1", sgm.p1, "our P1 (census costs)");
  app.add_option("--p2", sgm.p2, "our P2 (census costs)");
  app.add_option("--paths", sgm.paths, "our SGM paths (4 or 8)");
  app.add_option("--census-width", sgm.census_width, "census window width");
  app.add_option("--census-height", sgm.census_height, "census window height");
  app.add_option("--speckle", sgm.speckle_window, "speckle filter window (all methods; 0 = off)");
  CLI11_PARSE(app, argc, argv);
  cv::setNumThreads(1);
  fs::create_directories(out_dir);

  std::vector<fs::path> dirs;
  for (const auto& e : fs::directory_iterator(pairs_dir))
    if (e.is_directory()) dirs.push_back(e.path());
  std::sort(dirs.begin(), dirs.end());

  std::ofstream csv(fs::path(out_dir) / "results.csv");
  csv << "pair,method,width,height,num_disparities,ms,bad1,bad2,bad3,bad1_all,bad2_all,bad3_all,density_gt,density\n";
  std::ostringstream json;
  json << "{\"simd\": \"" << aerie::stereo::SemiGlobalMatcher::simd_target() << "\", \"pairs\": [";
  std::cout << "SIMD target: " << aerie::stereo::SemiGlobalMatcher::simd_target() << ", single thread, CPU ms, best of "
            << repeats << " interleaved rounds\n";
  bool first_pair = true;
  for (const auto& dir : dirs) {
    Pair p;
    try {
      p = load_pair(dir);
    } catch (const std::exception& e) {
      std::cerr << "skipping " << dir << ": " << e.what() << '\n';
      continue;
    }
    const int D = p.num_disparities;
    std::cout << "\n== " << p.name << " " << p.left.cols << "x" << p.left.rows << ", " << D << " disparities\n";
    std::cout << std::left << std::setw(16) << "method" << std::right << std::setw(9) << "ms" << std::setw(8)
              << "bad1" << std::setw(8) << "bad2" << std::setw(8) << "bad3" << std::setw(10) << "bad2all"
              << std::setw(9) << "dens%\n";

    aerie::stereo::SgmParams sp = sgm;
    sp.num_disparities = D;
    aerie::stereo::SgbmCtfParams cp{sp, std::min(fine_window, D)};
    aerie::stereo::CoarseToFineSgbm ctf(cp);
    aerie::stereo::SemiGlobalMatcher full(sp);
    const int P1 = 8 * block * block, P2 = 32 * block * block;
    auto sgbm = [&](int mode) {
      return cv::StereoSGBM::create(0, D, block, P1, P2, 1, 0, 10, sgm.speckle_window, 16 * sgm.speckle_range, mode);
    };
    auto bm = cv::StereoBM::create(D, std::max(5, block | 1) + 4);  // BM needs a larger block
    bm->setUniquenessRatio(10);
    bm->setDisp12MaxDiff(1);
    bm->setSpeckleWindowSize(sgm.speckle_window);
    bm->setSpeckleRange(16 * sgm.speckle_range);

    struct Method {
      std::string name;
      std::function<cv::Mat()> run;
    };
    std::vector<Method> methods = {
        {"SGBM_F", [&] { return ctf.compute(p.left, p.right); }},
        {"SGM_full", [&] { return full.compute(p.left, p.right); }},
        {"CV_BM",
         [&] {
           cv::Mat d;
           bm->compute(p.left, p.right, d);
           return from_opencv(d);
         }},
    };
    for (auto [name, mode] : {std::pair{"CV_SGBM", int(cv::StereoSGBM::MODE_SGBM)},
                              std::pair{"CV_HH", int(cv::StereoSGBM::MODE_HH)},
                              std::pair{"CV_SGBM_3WAY", int(cv::StereoSGBM::MODE_SGBM_3WAY)}}) {
      auto m = sgbm(mode);
      methods.push_back({name, [m, &p] {
                           cv::Mat d;
                           m->compute(p.left, p.right, d);
                           return from_opencv(d);
                         }});
    }
    std::map<std::string, double> ms;
    json << (first_pair ? "" : ", ") << "{\"name\": \"" << p.name << "\", \"width\": " << p.left.cols
         << ", \"height\": " << p.left.rows << ", \"num_disparities\": " << D << ", \"methods\": {";
    first_pair = false;
    std::vector<cv::Mat> disps;
    for (const auto& m : methods) disps.push_back(m.run());  // also the warm-up (allocation, caches)
    const std::vector<double> best = best_ms(repeats, methods);
    for (size_t i = 0; i < methods.size(); ++i) {
      const cv::Mat& disp = disps[i];
      ms[methods[i].name] = best[i];
      const Score s = score(disp, p.gt);
      std::cout << std::left << std::setw(16) << methods[i].name << std::right << std::fixed << std::setprecision(1)
                << std::setw(9) << ms[methods[i].name] << std::setw(8) << s.bad[0] << std::setw(8) << s.bad[1]
                << std::setw(8) << s.bad[2] << std::setw(10) << s.bad_all[1] << std::setw(8) << s.density << '\n';
      csv << p.name << ',' << methods[i].name << ',' << p.left.cols << ',' << p.left.rows << ',' << D << ','
          << ms[methods[i].name] << ',' << s.bad[0] << ',' << s.bad[1] << ',' << s.bad[2] << ',' << s.bad_all[0]
          << ',' << s.bad_all[1] << ',' << s.bad_all[2] << ',' << s.density << ',' << s.image_density << '\n';
      json << (i ? ", " : "") << "\"" << methods[i].name << "\": {\"ms\": " << ms[methods[i].name]
           << ", \"bad1\": " << s.bad[0] << ", \"bad2\": " << s.bad[1] << ", \"bad3\": " << s.bad[2]
           << ", \"bad2_all\": " << s.bad_all[1] << ", \"density_gt\": " << s.density << "}";
      write_colour(disp, D, fs::path(out_dir) / (p.name + "_" + methods[i].name + ".png"));
    }
    write_colour(p.gt, D, fs::path(out_dir) / (p.name + "_GT.png"));
    // Eq. 4.3: predicted saving from the density of the coarse prior vs the measured one.
    ctf.compute(p.left, p.right);
    const double eta = ctf.coarse_density();
    const double predicted = aerie::stereo::CoarseToFineSgbm::predicted_saving(eta, D);
    const double measured = 1.0 - ms["SGBM_F"] / ms["SGM_full"];
    const double ours_model = 1.0 - (1.0 / 8 + double(cp.fine_window) / D);
    const auto& t = ctf.timings();
    auto stages = [](const aerie::stereo::SgmTimings& s) {
      std::ostringstream o;
      o << std::setprecision(3) << "census " << s.census_ms << ", cost " << s.cost_ms << ", aggregate "
        << s.aggregate_ms << ", select " << s.select_ms;
      return o.str();
    };
    full.compute(p.left, p.right);
    std::cout << "SGM stages ms: SGBM_F coarse [" << stages(ctf.coarse_sgm_timings()) << "], fine ["
              << stages(ctf.fine_sgm_timings()) << "]; SGM_full [" << stages(full.timings()) << "]\n";
    std::cout << std::setprecision(3) << "SGBM_F stages ms: pyramid " << t.pyramid_ms << ", coarse " << t.coarse_ms
              << ", prior " << t.prior_ms << ", fine " << t.fine_ms << "\n"
              << "saving vs full SGM: measured " << measured << ", eq. 4.3 (eta " << eta << ") " << predicted
              << ", fixed-window model 1 - (1/8 + W/D) " << ours_model << "\n"
              << "speed-up of SGBM_F over CV_SGBM_3WAY " << ms["CV_SGBM_3WAY"] / ms["SGBM_F"] << "x\n";
    json << "}, \"eta\": " << eta << ", \"saving_measured\": " << measured << ", \"saving_eq_4_3\": " << predicted
         << ", \"saving_window_model\": " << ours_model
         << ", \"speedup_vs_3way\": " << ms["CV_SGBM_3WAY"] / ms["SGBM_F"] << "}";
  }
  json << "]}\n";
  std::ofstream(fs::path(out_dir) / "results.json") << json.str();
  csv.close();
  // Bar charts of time and bad-2px (matplotlib).
  const fs::path script = fs::path(AERIE_BENCH_STEREO_DIR) / "plot_stereo.py";
  const std::string cmd = "/usr/bin/python3 '" + script.string() + "' '" + (fs::path(out_dir) / "results.csv").string() +
                          "' '" + (fs::path(out_dir) / "stereo.png").string() + "'";
  if (std::system(cmd.c_str()) != 0) std::cerr << "plot failed: " << cmd << "\n";
  std::cout << "\nwrote " << (fs::path(out_dir) / "results.csv").string() << ", results.json, stereo.png and the "
            << "disparity PNGs\n";
  return 0;
} catch (const std::exception& e) {  // bad parameters, unreadable files
  std::cerr << "aerie-bench-stereo: " << e.what() << '\n';
  return 1;
}
