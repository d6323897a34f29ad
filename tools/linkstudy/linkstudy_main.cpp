// aerie-linkstudy: what the air-ground link does to landing and avoidance, for a set of link
// conditions and placements of the nodes, in lock-step (docs/linkstudy.md).
//   aerie-linkstudy --config config/linkstudy/quick.yaml --out OUT
// Writes OUT/study.csv (one row per run and sweep), OUT/report.md (tables and the answers)
// and OUT/*.png (tools/linkstudy/plot_linkstudy.py). Ctrl-C stops launching runs; the runs
// under way finish and everything done is written.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <opencv2/core.hpp>
#include <optional>

#include "common/bus/node.hpp"
#include "common/util/parallel.hpp"
#include "tools/linkstudy/report.hpp"
#include "tools/linkstudy/study.hpp"

using namespace aerie;

int main(int argc, char** argv) {
  CLI::App app{
      "aerie-linkstudy: closed-loop landings and avoidance flights in lock-step with the nodes split\n"
      "between the air and the ground sides and the link between them in simulation time, over a\n"
      "set of link conditions (docs/linkstudy.md). Writes OUT/study.csv, OUT/report.md, OUT/*.png."};
  std::string config_file, out_dir, base_dir = ".", log_level = "error";
  int jobs = 2;
  bool logs = false, plots = true;
  app.add_option("-c,--config", config_file, "study YAML (config/linkstudy/quick.yaml documents every key)")
      ->required()->check(CLI::ExistingFile);
  app.add_option("-o,--out", out_dir, "output folder")->required();
  app.add_option("--jobs", jobs, "flights in parallel (threads); the figures do not depend on it")->check(CLI::Range(1, 64));
  app.add_option("--base-dir", base_dir, "folder the study's file names are relative to (the repository root)")
      ->check(CLI::ExistingDirectory);
  app.add_flag("--logs", logs, "write each run's air and ground logs (OUT/logs/*-air.lcm, *-ground.lcm; simulation time)");
  app.add_flag("!--no-plots", plots, "do not run tools/linkstudy/plot_linkstudy.py");
  app.add_option("--log-level", log_level, "the nodes' log level (their refusals and warnings are counted in the CSV)")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(spdlog::level::from_str(log_level));

  linkstudy::StudyConfig study;
  try {
    study = linkstudy::load_study(util::Config::load(config_file), base_dir);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "aerie-linkstudy: %s\n", e.what());
    return 2;
  }

  // Every distinct run once (a condition shared by sweeps, e.g. the baseline, is flown once).
  std::map<std::string, const linkstudy::Condition*> conditions;
  for (const auto& sw : study.sweeps)
    for (const auto& c : sw.conditions) conditions.emplace(c.name(), &c);
  std::vector<linkstudy::RunSpec> specs;
  for (auto w : study.workloads)
    for (const auto& p : study.placements)
      for (const auto& t : w != linkstudy::Workload::kAvoidance ? study.trackers : std::vector<std::string>{"-"})
        for (const auto& [name, c] : conditions)
          for (const auto& f : study.faults)
            for (int i = 0; i < study.seeds; ++i)
              specs.push_back({c, &p, w, t, study.first_seed + static_cast<uint64_t>(i), f});
  std::filesystem::create_directories(out_dir);
  if (logs) std::filesystem::create_directories(out_dir + "/logs");
  std::printf(
      "aerie-linkstudy: %zu flights (%zu conditions x %zu placements x workloads/trackers x %zu fault scenarios x %d seeds) "
      "on %d threads\n",
      specs.size(), conditions.size(), study.placements.size(), study.faults.size(), study.seeds, jobs);
  std::fflush(stdout);

  bus::install_stop_handlers();
  if (jobs > 1) cv::setNumThreads(1);  // one core per flight
  std::vector<std::optional<linkstudy::RunRow>> rows(specs.size());
  std::mutex out_mutex;
  int done = 0, failures = 0;
  util::parallel_for(static_cast<int>(specs.size()), jobs, [&](int i) {
    if (bus::stop_requested()) return;
    const auto& s = specs[static_cast<size_t>(i)];
    std::string run_name = std::string(linkstudy::workload_name(s.workload)) + "-" + s.placement->name + "-" + s.tracker +
                           "-" + s.condition->name() + "-seed" + std::to_string(s.seed);
    if (study.faults.size() > 1 || s.faults != "none") {  // the scenario's index: specs are not file names
      const auto f = std::find(study.faults.begin(), study.faults.end(), s.faults) - study.faults.begin();
      run_name += "-fault" + std::to_string(f);
    }
    try {
      auto row = linkstudy::run(study, s, logs ? out_dir + "/logs/" + run_name : "");
      std::lock_guard lk(out_mutex);
      std::printf("[%d/%zu] %s: %s, %s %.3f\n", ++done, specs.size(), run_name.c_str(),
                  row.success ? "success" : row.final_state.c_str(), row.metric.c_str(), row.value);
      std::fflush(stdout);
      rows[static_cast<size_t>(i)] = std::move(row);
    } catch (const std::exception& e) {
      std::lock_guard lk(out_mutex);
      std::fprintf(stderr, "aerie-linkstudy: %s failed: %s\n", run_name.c_str(), e.what());
      ++failures;
    }
  });

  std::ofstream csv(out_dir + "/study.csv");
  csv << linkstudy::csv_header() << '\n';
  for (const auto& sw : study.sweeps)
    for (const auto& c : sw.conditions)
      for (size_t i = 0; i < specs.size(); ++i)
        if (rows[i] && specs[i].condition->name() == c.name())
          csv << linkstudy::csv_row(sw.factor, specs[i], *rows[i]) << '\n';
  csv.close();
  linkstudy::write_report(study, specs, rows, out_dir);
  size_t flown = 0;
  for (const auto& r : rows) flown += r.has_value();
  std::printf("aerie-linkstudy: %zu of %zu flights done; %s/study.csv, %s/report.md\n", flown, specs.size(),
              out_dir.c_str(), out_dir.c_str());
  if (plots && std::filesystem::exists(base_dir + "/tools/linkstudy/plot_linkstudy.py")) {
    const std::string cmd = "/usr/bin/python3 " + base_dir + "/tools/linkstudy/plot_linkstudy.py " + out_dir;
    if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "aerie-linkstudy: plotting failed (%s)\n", cmd.c_str());
  }
  if (failures) std::fprintf(stderr, "aerie-linkstudy: %d flights failed (no row for them)\n", failures);
  if (bus::stop_requested()) std::fprintf(stderr, "aerie-linkstudy: interrupted; the flights done are written\n");
  return failures || bus::stop_requested() ? 1 : 0;
}
