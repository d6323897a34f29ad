// aerie-ceopt: tunes the heading FLC by cross-entropy in simulation (thesis 5.1.4-5.1.5),
// prunes it, flies the avoidance experiment of 5.1.6 and writes the controllers (YAML,
// FLL) and a report with plots. Progress goes to the terminal and to CE_PROGRESS;
// the chosen controller can be sent to aerie-control on FLC_PARAMS.
// `aerie-ceopt landing` tunes aerie-pilot's landing controller the same way, each candidate
// flown in lock-step landings (ground/ceopt/landing_tuning.hpp), and writes a pilot.yaml.
// Started by mpirun/srun, `aerie-ceopt landing` spreads each CE iteration's landings over the
// ranks (the same elite and gains as one process); --resumable/--resume journal the landings
// in OUT/studies so that an interrupted tuning continues (ground/ceopt/landing_study.hpp).
#include <aerie/ce_progress_t.hpp>
#include <aerie/flc_params_t.hpp>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <memory>
#include <opencv2/core.hpp>
#include <sstream>

#include "common/bus/bus.hpp"
#include "common/bus/channels.hpp"
#include "common/bus/node.hpp"
#include "common/bus/status.hpp"
#include "common/flc/flc_io.hpp"
#include "common/util/cli.hpp"
#include "common/util/time.hpp"
#include "ground/ceopt/landing_study.hpp"
#include "ground/ceopt/landing_tuning.hpp"
#include "ground/ceopt/pipeline.hpp"
#include "ground/ceopt/report.hpp"
#include "ground/ceopt/thread_pool.hpp"

using namespace aerie;
using namespace aerie::ceopt;

namespace {

aerie::flc_params_t params_message(const flc::FlcSpec& spec, int64_t seq) {
  aerie::flc_params_t m;
  m.utime = util::wall_utime();
  m.seq = seq;
  m.controller_id = spec.id;
  m.names = spec.parameter_names();
  for (const auto& n : m.names) m.values.push_back(spec.parameter(n));
  m.nparams = static_cast<int32_t>(m.names.size());
  m.fll = flc::to_fll(spec);
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  study::Session session(argc, argv);  // MPI only when mpirun/srun started us (docs/scale.md)
  const bool writer = session.rank() == 0;
  CLI::App app{"aerie-ceopt: cross-entropy optimisation of the heading fuzzy controller in simulation (thesis 5.1.4-5.1.6)"};
  util::CommonOptions common;
  util::add_common_options(app, common);
  std::string out = "ceopt-out", plot_script = AERIE_CEOPT_PLOT_SCRIPT, publish = "none";
  std::string progress_channel = channels::kCeProgress, params_channel = channels::kFlcParams;
  int threads = -1, iterations = -1, samples = -1, runs = -1;
  int64_t seed = -1;
  bool no_plots = false, no_experiment = false, no_lcm = false;
  app.add_option("-o,--out", out, "output folder (controllers, CSV, report.md, PNG plots)");
  app.add_option("--seed", seed, "CE seed (overrides ce.seed); the run is reproducible from it whatever --threads");
  app.add_option("--threads", threads, "evaluation threads (0 = all cores; overrides threads)");
  app.add_option("--iterations", iterations, "CE iterations per stage (overrides ce.iterations)");
  app.add_option("--samples", samples, "CE candidates per iteration N (overrides ce.samples)");
  app.add_option("--runs", runs, "experiment runs per speed and controller (overrides evaluation.runs_per_speed)");
  app.add_flag("--no-experiment", no_experiment, "only optimise (no evaluation runs)");
  app.add_flag("--no-plots", no_plots, "do not draw the PNG plots");
  app.add_option("--plot-script", plot_script, "the plotting script (python3 + matplotlib)");
  app.add_flag("--no-lcm", no_lcm, "do not publish CE_PROGRESS / FLC_PARAMS / status");
  app.add_option("--progress-channel", progress_channel, "channel for aerie.ce_progress_t");
  app.add_option("--params-channel", params_channel, "channel for aerie.flc_params_t");
  app.add_option("--publish", publish, "controller to send on the params channel at the end")
      ->check(CLI::IsMember({"none", "sf", "sfmf", "pruned"}));
  int training = -1, validation = -1;
  CLI::App* landing = app.add_subcommand(
      "landing",
      "tune aerie-pilot's landing controller instead, in lock-step closed-loop landings (config/ceopt_landing.yaml; the "
      "options above before or after the word, --runs excepted); writes OUT/pilot.yaml, report.md and CSVs");
  landing->fallthrough();
  landing->add_option("--training", training, "training seeds per candidate (overrides training.count)")->check(CLI::PositiveNumber);
  landing->add_option("--validation", validation, "validation seeds (overrides validation.count; 0 = none)")
      ->check(CLI::NonNegativeNumber);
  std::string node_log_level = "warn";
  landing->add_option("--node-log-level", node_log_level, "the flown nodes' log level (info shows every pilot transition)")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  std::string resume_dir;
  bool resumable = false;
  double rank_timeout_s = 600;
  landing->add_flag("--resumable", resumable,
                    "journal every landing in OUT/studies (always so under mpirun), so that --resume can continue");
  landing->add_option("--resume", resume_dir,
                      "continue the tuning in this folder (started with --resumable or under mpirun, with the same options): "
                      "the landings in its journals are not flown again");
  landing->add_option("--rank-timeout", rank_timeout_s,
                      "under MPI: seconds a rank may take over one landing before the tuning stops, naming it")
      ->check(CLI::PositiveNumber);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return writer ? app.exit(e) : e.get_exit_code();  // the help or the error, once
  }
  if (!resume_dir.empty()) out = resume_dir;
  util::init_logging("ceopt", common.log_level);
  // The tuning's own progress; in landing mode the nodes flown log through the default
  // logger at --node-log-level (their transitions would flood the terminal).
  std::shared_ptr<spdlog::logger> log = spdlog::default_logger();
  if (landing->parsed()) {
    log = log->clone("ceopt");
    spdlog::default_logger()->set_level(spdlog::level::from_str(node_log_level));
  }

  try {
    const bool landing_mode = landing->parsed();
    if (session.distributed() && !landing_mode) {
      if (writer)
        spdlog::error("under mpirun only `aerie-ceopt landing` spreads over the ranks; run the FLC tuning in one process "
                      "(--threads)");
      return 2;
    }
    if (landing_mode && runs > 0) throw std::runtime_error("--runs is the avoidance experiment's; landing uses --training/--validation");
    CeoptConfig cfg;
    LandingTuningConfig landing_cfg;
    if (landing_mode) {
      landing_cfg = common.config.empty() ? default_landing_tuning_config()
                                          : landing_tuning_config_from(util::Config::load(common.config));
      if (training > 0) landing_cfg.training.count = training;
      if (validation >= 0) landing_cfg.validation.count = validation;
    } else {
      cfg = common.config.empty() ? default_ceopt_config() : ceopt_config_from(util::Config::load(common.config));
      if (runs > 0) cfg.evaluation.runs_per_speed = runs;
    }
    CeOptions& ce = landing_mode ? landing_cfg.ce : cfg.ce;
    int& pool_threads = landing_mode ? landing_cfg.threads : cfg.threads;
    if (seed >= 0) ce.seed = static_cast<uint64_t>(seed);
    if (threads >= 0) pool_threads = threads;
    if (iterations > 0) ce.max_iterations = iterations;
    if (samples > 0) ce.samples = samples;
    ce.validate();
    std::unique_ptr<const LandingTuning> problem_ptr;
    if (landing_mode) problem_ptr = std::make_unique<const LandingTuning>(landing_cfg);
    if (!writer) {  // the other ranks fly what rank 0 hands out, and write nothing
      cv::setNumThreads(1);
      serve_landing_studies(*problem_ptr, session);
      return 0;
    }

    std::unique_ptr<bus::Bus> lcm;
    std::unique_ptr<bus::StatusReporter> status;
    if (!no_lcm) {
      try {
        lcm = std::make_unique<bus::Bus>(common.lcm_url);
        status = std::make_unique<bus::StatusReporter>(*lcm, "ceopt");
      } catch (const std::exception& e) {
        spdlog::warn("LCM unavailable ({}): progress on the terminal only (use --lcm-url or --no-lcm)", e.what());
      }
    }
    bus::install_stop_handlers();
    ThreadPool pool(pool_threads);
    std::ostringstream cmdline;
    for (int i = 0; i < argc; ++i) cmdline << (i ? " " : "") << argv[i];
    log->info("{} threads; CE N = {}, N_elite = {}, {} iterations per stage, {} training runs per candidate; load {}",
                 pool.size(), ce.samples, ce.elite, ce.max_iterations,
                 landing_mode ? static_cast<size_t>(landing_cfg.training.count)
                              : cfg.training.speeds.size() * static_cast<size_t>(cfg.training.runs_per_speed),
                 read_loadavg());

    const std::string run_id = std::string(landing_mode ? "ceopt-landing-seed" : "ceopt-seed") + std::to_string(ce.seed);
    int64_t seq = 0;
    const util::Stopwatch watch;
    auto on_iteration = [&](int stage, const std::vector<std::string>& names, const CeIteration& it) {
      std::ostringstream sig;
      for (size_t j = 0; j < names.size(); ++j) sig << " " << names[j] << "=" << it.mean[j] << "±" << it.sigma[j];
      log->info("stage {} iter {:3d}/{}  best {:.4g}  iter-best {:.4g}  eta {:.3f} |{}  ({:.1f} s)", stage, it.iteration,
                   ce.max_iterations, it.best_cost, it.iteration_best_cost, it.eta, sig.str(), watch.ms() / 1000);
      if (lcm) {
        aerie::ce_progress_t m;
        m.utime = util::wall_utime();
        m.seq = seq++;
        m.run_id = run_id;
        m.stage = stage;
        m.iteration = it.iteration;
        m.evaluations = it.evaluations;
        m.nparams = static_cast<int32_t>(names.size());
        m.names = names;
        m.mean = it.mean;
        m.sigma = it.sigma;
        m.best_cost = it.best_cost;
        m.iteration_best_cost = it.iteration_best_cost;
        m.nelite = static_cast<int32_t>(it.elite_costs.size());
        m.elite_costs = it.elite_costs;
        lcm->publish(progress_channel, m);
        status->set("stage", stage);
        status->set("iteration", it.iteration);
        status->count("evaluations", ce.samples);
        status->ok("stage " + std::to_string(stage) + " iteration " + std::to_string(it.iteration));
        status->tick();
      }
      return !bus::stop_requested();
    };

    if (landing_mode) {
      const LandingTuning& problem = *problem_ptr;
      if (pool.size() > 1 || session.distributed()) cv::setNumThreads(1);  // one core per landing
      const auto names = problem.names();
      int candidates = 0;
      auto on_candidate = [&](const std::vector<double>& x, const std::vector<LandingRun>& runs, double cost) {
        std::ostringstream gains;
        for (size_t j = 0; j < names.size(); ++j) gains << " " << names[j] << "=" << x[j];
        const auto ok = std::count_if(runs.begin(), runs.end(), [](const LandingRun& r) { return r.success; });
        log->info("candidate {:3d}: cost {:.4f}, {}/{} landed in bounds |{}", ++candidates, cost, ok, runs.size(), gains.str());
      };
      LandingFlier flier;  // without mpirun, --resumable or --resume: the pool, as always
      if (session.distributed() || resumable || !resume_dir.empty())
        flier = landing_study_flier(problem, {out + "/studies", !resume_dir.empty(), pool.size(), rank_timeout_s}, session);
      const LandingTuningResult result =
          tune_landing(problem, pool, [&](const CeIteration& it) { return on_iteration(1, names, it); }, on_candidate, flier);
      end_landing_studies(session);
      const auto files = write_landing_report(out, problem, result, cmdline.str());
      log->info("best training cost {:.4f} (initial {:.4f}) after {} candidates in {:.0f} s ({:.0f} s CPU); wrote {} files to {}",
                   result.ce.best_cost, mean_cost(result.initial_training, landing_cfg), result.ce.evaluations, result.seconds,
                   result.cpu_seconds, files.size(), out);
      const bool interrupted = result.ce.stop_reason == "cancelled";
      if (interrupted) log->warn("interrupted after iteration {}: the best so far is written, not validated", result.ce.history.size());
      if (status) status->publish_now();
      return interrupted ? 130 : 0;
    }

    ReportInputs in;
    in.config = &cfg;
    in.threads = pool.size();
    in.command_line = cmdline.str();
    in.load_before = read_loadavg();
    const TuningResult tuning = run_tuning(cfg, pool, on_iteration);
    in.load_after = read_loadavg();
    in.tuning = &tuning;
    const bool complete = !tuning.stage2.ce.history.empty() && tuning.stage2.ce.stop_reason != "cancelled";
    spdlog::info("stage 1: {:.1f} s ({:.1f} s CPU), best cost {:.1f} (iteration {}); stage 2: {:.1f} s ({:.1f} s CPU), best cost {:.1f} "
                 "(iteration {})",
                 tuning.stage1.seconds, tuning.stage1.cpu_seconds, tuning.stage1.ce.best_cost, tuning.stage1.ce.best_iteration,
                 tuning.stage2.seconds, tuning.stage2.cpu_seconds, tuning.stage2.ce.best_cost, tuning.stage2.ce.best_iteration);
    in.controllers.emplace_back("initial", tuning.initial);
    if (!tuning.stage1.ce.best.empty()) in.controllers.emplace_back("sf", tuning.stage1.controller);
    if (!tuning.stage2.ce.best.empty()) in.controllers.emplace_back("sfmf", tuning.stage2.controller);
    if (complete) {
      in.controllers.emplace_back("pruned", tuning.pruned);
      spdlog::info("pruned: {} -> {} rules, {} -> {} sets", tuning.prune_report.rules_before, tuning.prune_report.rules_after,
                   tuning.prune_report.sets_before, tuning.prune_report.sets_after);
    } else {
      spdlog::warn("interrupted: writing what was optimised so far");
    }
    if (!no_experiment && !bus::stop_requested()) {
      spdlog::info("experiment: {} controllers x {} speeds x {} runs", in.controllers.size(), cfg.evaluation.speeds.size(),
                   cfg.evaluation.runs_per_speed);
      in.runs = run_experiment(in.controllers, cfg, pool);
      for (const auto& s : summarise(in.runs))
        spdlog::info("  {:8s} {:.1f} m/s: steady-state RMSE (deg) {} ({} of {} settled), min wall distance {:.2f} m, {} in dangerous area",
                     s.controller, s.speed, rmse_text(s), s.settled, s.runs, s.min_wall_distance, s.entered_dangerous);
    }
    const auto files = write_report(out, in);
    spdlog::info("wrote {} files to {}", files.size(), out);
    if (!no_plots) {
      std::string err;
      if (draw_plots(out, plot_script, &err))
        spdlog::info("plots in {}", out);
      else
        spdlog::warn("{}", err);
    }
    if (publish != "none" && lcm) {
      bool sent = false;
      for (const auto& [name, spec] : in.controllers)
        if (name == publish) {
          lcm->publish(params_channel, params_message(spec, 0));
          spdlog::info("sent controller '{}' ({}) on {}", name, spec.id, params_channel);
          sent = true;
        }
      if (!sent) spdlog::warn("controller '{}' was not produced (interrupted?), nothing sent", publish);
    }
    if (status) status->publish_now();
    return complete ? 0 : 130;
  } catch (const std::exception& e) {
    spdlog::error("{}{}", session.distributed() ? "rank " + std::to_string(session.rank()) + ": " : std::string(), e.what());
    if (session.distributed()) session.abort(1);  // the other ranks wait for rank 0's next batch
    return 1;
  }
}
