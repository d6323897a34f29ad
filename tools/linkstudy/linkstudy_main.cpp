// aerie-linkstudy: what the air-ground link does to landing and avoidance, for a set of link
// conditions and placements of the nodes, in lock-step (docs/linkstudy.md).
//   aerie-linkstudy --config config/linkstudy/quick.yaml --out OUT
// Writes OUT/study.csv (one row per run and sweep), OUT/report.md (tables and the answers)
// and OUT/*.png (tools/linkstudy/plot_linkstudy.py). Ctrl-C stops launching runs; the runs
// under way finish and everything done is written. The flights are one study (tools/study):
// on --jobs threads, or over the ranks when started by mpirun/srun (the same CSV and report);
// --resume OUT continues an interrupted study from OUT/study.progress (docs/scale.md).
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/core.hpp>
#include <optional>
#include <sstream>

#include "common/bus/node.hpp"
#include "tools/linkstudy/report.hpp"
#include "tools/linkstudy/study.hpp"
#include "tools/study/study.hpp"

using namespace aerie;

namespace {

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

int main(int argc, char** argv) {
  study::Session session(argc, argv);  // MPI only when mpirun/srun started us (docs/scale.md)
  CLI::App app{
      "aerie-linkstudy: closed-loop landings and avoidance flights in lock-step with the nodes split\n"
      "between the air and the ground sides and the link between them in simulation time, over a\n"
      "set of link conditions (docs/linkstudy.md). Writes OUT/study.csv, OUT/report.md, OUT/*.png;\n"
      "spreads the flights over the ranks when started by mpirun."};
  std::string config_file, out_dir, resume_dir, base_dir = ".", log_level = "error";
  int jobs = 2;
  bool logs = false, plots = true;
  double rank_timeout_s = 600;
  app.add_option("-c,--config", config_file, "study YAML (config/linkstudy/quick.yaml documents every key)")
      ->required()->check(CLI::ExistingFile);
  auto* out_opt = app.add_option("-o,--out", out_dir, "output folder (or --resume)");
  app.add_option("--resume", resume_dir,
                 "continue the study in this folder (started with --out and the same study YAML): the flights already in "
                 "its study.progress are not flown again")
      ->excludes(out_opt);
  app.add_option("--jobs", jobs, "flights in parallel (threads; under MPI each rank flies one at a time); the figures do not "
                                 "depend on it")->check(CLI::Range(1, 64));
  app.add_option("--rank-timeout", rank_timeout_s,
                 "under MPI: seconds a rank may take over one flight before the study stops, naming it")
      ->check(CLI::PositiveNumber);
  app.add_option("--base-dir", base_dir, "folder the study's file names are relative to (the repository root)")
      ->check(CLI::ExistingDirectory);
  app.add_flag("--logs", logs, "write each run's air and ground logs (OUT/logs/*-air.lcm, *-ground.lcm; simulation time)");
  app.add_flag("!--no-plots", plots, "do not run tools/linkstudy/plot_linkstudy.py");
  app.add_option("--log-level", log_level, "the nodes' log level (their refusals and warnings are counted in the CSV)")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  const bool writer = session.rank() == 0;
  try {
    app.parse(argc, argv);
    if (out_dir.empty() && resume_dir.empty()) throw CLI::RequiredError("--out or --resume");
  } catch (const CLI::ParseError& e) {
    const int rc = writer ? app.exit(e) : e.get_exit_code();  // the help or the error, once
    return rc == 0 ? 0 : 2;
  }
  spdlog::set_level(spdlog::level::from_str(log_level));
  if (!resume_dir.empty()) out_dir = resume_dir;

  linkstudy::StudyConfig study;
  try {
    study = linkstudy::load_study(util::Config::load(config_file), base_dir);
  } catch (const std::exception& e) {
    if (writer) std::fprintf(stderr, "aerie-linkstudy: %s\n", e.what());
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
  std::vector<std::string> run_names;
  for (const auto& s : specs) {
    std::string run_name = std::string(linkstudy::workload_name(s.workload)) + "-" + s.placement->name + "-" + s.tracker +
                           "-" + s.condition->name() + "-seed" + std::to_string(s.seed);
    if (study.faults.size() > 1 || s.faults != "none") {  // the scenario's index: specs are not file names
      const auto f = std::find(study.faults.begin(), study.faults.end(), s.faults) - study.faults.begin();
      run_name += "-fault" + std::to_string(f);
    }
    run_names.push_back(std::move(run_name));
  }
  if (writer) std::filesystem::create_directories(out_dir);
  if (logs) std::filesystem::create_directories(out_dir + "/logs");  // every rank flying writes there
  if (writer) {
    std::printf(
        "aerie-linkstudy: %zu flights (%zu conditions x %zu placements x workloads/trackers x %zu fault scenarios x %d seeds) "
        "on %d %s\n",
        specs.size(), conditions.size(), study.placements.size(), study.faults.size(), study.seeds,
        session.distributed() ? session.size() : jobs, session.distributed() ? "MPI ranks" : "threads");
    std::fflush(stdout);
  }

  if (writer) bus::install_stop_handlers();  // Ctrl-C: rank 0 stops handing out flights (mpirun's SIGTERM: docs/scale.md)
  if (jobs > 1 || session.distributed()) cv::setNumThreads(1);  // one core per flight
  // One study run per flight, in the order of `specs`. Its rows are not the CSV's (study.csv
  // repeats a run under each sweep it belongs to, and report.md needs every field): the whole
  // RunRow travels as the run's note, and both files are written from them at the end.
  std::vector<std::optional<linkstudy::RunRow>> rows(specs.size());
  int done = 0, failures = 0;
  study::Study st;
  st.tool = "aerie-linkstudy";
  st.dir = out_dir;
  st.runs = static_cast<int>(specs.size());
  st.definition = "study YAML:\n" + read_file(config_file) + "\nflights:";
  for (const auto& n : run_names) st.definition += " " + n;
  st.run = [&](int i) {
    const auto k = static_cast<size_t>(i);
    const auto row = linkstudy::run(study, specs[k], logs ? out_dir + "/logs/" + run_names[k] : "");
    return study::Record{{}, linkstudy::row_note(row), ""};
  };
  st.describe = [&](int i) { return run_names[static_cast<size_t>(i)]; };
  st.stop = [] { return bus::stop_requested(); };
  st.on_written = [&](int i, const study::Record& r) {
    if (r.failed()) {
      ++failures;
      return;
    }
    const auto k = static_cast<size_t>(i);
    const auto row = linkstudy::row_from_note(r.note, "aerie-linkstudy: the note of " + run_names[k]);
    std::printf("[%d/%zu] %s: %s, %s %.3f\n", ++done, specs.size(), run_names[k].c_str(),
                row.success ? "success" : row.final_state.c_str(), row.metric.c_str(), row.value);
    std::fflush(stdout);
    rows[k] = row;
  };
  const study::Outcome outcome = study::run_or_exit(st, {jobs, !resume_dir.empty(), rank_timeout_s}, session);
  if (!outcome.writer) return 0;
  if (outcome.resumed)
    std::printf("aerie-linkstudy: %d flights resumed from %s/study.progress, %d flown now\n", outcome.resumed,
                out_dir.c_str(), outcome.flown);

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
  if (bus::stop_requested())
    std::fprintf(stderr, "aerie-linkstudy: interrupted; the flights done are written (continue with --resume %s)\n",
                 out_dir.c_str());
  return failures || bus::stop_requested() ? 1 : 0;
}
