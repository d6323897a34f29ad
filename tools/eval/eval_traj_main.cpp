// aerie-eval-traj: scores an estimated trajectory against a reference (ATE, RPE,
// per-axis RMSE, end-point drift), evo-compatible, TUM, EuRoC CSV or KITTI files.
#include <CLI/CLI.hpp>
#include <fstream>
#include <iostream>

#include "tools/eval/report.hpp"

int main(int argc, char** argv) {
  CLI::App app{std::string("Trajectory evaluation: ATE after alignment, RPE per frame and over path segments, "
                           "per-axis RMSE, end-point drift (loop drift for loops only). Files, detected from the "
                           "content: ") +
               aerie::eval::kTrajectoryFormats + "."};
  std::string ref_path, est_path, ref_times, est_times, alignment = "se3", json_path;
  aerie::eval::ReportOptions opt;
  app.add_option("--ref", ref_path, "reference (ground-truth) trajectory")->required()->check(CLI::ExistingFile);
  app.add_option("--est", est_path, "estimated trajectory")->required()->check(CLI::ExistingFile);
  app.add_option("--ref-times", ref_times, "times.txt for a KITTI reference (default: pose index)")
      ->check(CLI::ExistingFile);
  app.add_option("--est-times", est_times, "times.txt for a KITTI estimate (default: pose index)")
      ->check(CLI::ExistingFile);
  app.add_option("--align", alignment, "none, se3 or sim3")->check(CLI::IsMember({"none", "se3", "sim3"}));
  app.add_option("--max-dt", opt.max_dt, "time association tolerance (s)");
  app.add_option("--delta-frames", opt.rpe_delta_frames, "RPE pair distance in frames")->check(CLI::PositiveNumber);
  app.add_option("--delta-m", opt.rpe_delta_m, "also RPE over path segments of this length (m), as evo's "
                                               "--delta_unit m");
  app.add_option("--json", json_path, "write the results as JSON");
  CLI11_PARSE(app, argc, argv);
  try {
    using namespace aerie::eval;
    const auto load = [](const std::string& p, const std::string& times) {
      return times.empty() ? read_trajectory(p) : read_kitti_poses(p, times);
    };
    opt.alignment = alignment_from_string(alignment);
    const Report r = evaluate(load(ref_path, ref_times), load(est_path, est_times), opt);
    print(std::cout, r, opt);
    if (!json_path.empty()) {
      std::ofstream out(json_path);
      out << to_json(r, opt) << '\n';
      if (!out) throw std::runtime_error(json_path + ": write failed");
    }
  } catch (const std::exception& e) {
    std::cerr << "aerie-eval-traj: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
