// aerie-bench-landing: seeded autonomous landings in lock-step, one row per run.
//   aerie-bench-landing --runs N --seed S --tracker NAME --wind M_S --vibration on|off
//                       --world room|field --out DIR
// Each run builds the flight simulator (config/sim/landing_<world>.yaml), the tracking node
// (config/track_landing.yaml) and the pilot (config/pilot.yaml) on one in-process LCM bus
// (memq://) and flies until the simulator reports the flight over: the same node code as
// aerie-flightsim, aerie-track and aerie-pilot, in lock-step, so a row depends on its seed
// alone. Lists (--tracker a,b --wind 0,1,2 ...) run every combination. Writes
// DIR/landings.csv, DIR/descent.csv (TARGET_POSE error per frame of the descent) and prints
// one summary line per configuration; DIR/*.png when bench/landing/plot_landing.py runs.
// The runs are one study (tools/study): on --jobs threads, or over the ranks when started by
// mpirun/srun (`mpirun -np N aerie-bench-landing ...`, the same rows); --resume DIR continues
// an interrupted study from its CSVs and DIR/study.progress (docs/scale.md).
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numeric>
#include <sstream>
#include <opencv2/core.hpp>

#include "air/track/factory.hpp"
#include "common/logio/event_log.hpp"
#include "bench/seeded_runs.hpp"
#include "loop/landing.hpp"
#include "tools/study/study.hpp"

using namespace aerie;

namespace {

struct Setup {
  std::string tracker, world, controller, via;
  double wind = 0;
  bool vibration = false;
};

struct Files {
  std::string sim_dir, track, pilot, log_dir;
};

// A setup's landing run (loop::landing::load_landing_run reads its files for each seed).
loop::landing::LandingSpec setup_spec(const Setup& setup, const Files& files) {
  loop::landing::LandingSpec spec;
  spec.sim = files.sim_dir + "/landing_" + setup.world + ".yaml";
  spec.track = files.track;
  spec.pilot = files.pilot;
  spec.tracker = setup.tracker;
  spec.controller = setup.controller;
  spec.wind_m_s = setup.wind;
  spec.vibration = setup.vibration;
  spec.via = loop::landing::via_from_string(setup.via);
  return spec;
}

loop::landing::RunResult fly(const Setup& setup, const loop::landing::LandingSpec& spec, uint64_t seed, const Files& files) {
  loop::landing::RunConfig rc = loop::landing::load_landing_run(spec, seed);
  const std::string& log_dir = files.log_dir;
  std::unique_ptr<logio::Writer> log;
  if (!log_dir.empty()) {
    // Every message of the run, stamped with its own (simulation) time: lcm-logplayer and
    // aerie-viewer replay it like a flight log.
    log = std::make_unique<logio::Writer>(log_dir + "/" + setup.tracker + "-" + setup.controller + "-" + setup.world +
                                          "-wind" + std::to_string(static_cast<int>(setup.wind)) + "-vib" +
                                          (setup.vibration ? "on" : "off") +
                                          (setup.via == "direct" ? "" : "-" + setup.via) + "-seed" + std::to_string(seed) +
                                          ".lcm");
    rc.on_message = [&log](link::Side, const std::string& channel, const uint8_t* data, size_t size, int64_t now_us) {
      log->write(now_us, channel, data, size);
    };
  }
  return loop::landing::fly(rc);
}

double mean(const std::vector<double>& v) {
  return v.empty() ? std::nan("") : std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}
double percentile(std::vector<double> v, double p) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(std::min<double>(static_cast<double>(v.size()) - 1, std::ceil(p * static_cast<double>(v.size())) - 1))];
}

// What a configuration's summary line needs of its runs. A run's share travels as its study
// note (text, %.17g: exact), so that a summary also covers runs flown on other ranks or
// before a --resume.
struct Tally {
  int runs = 0, ok = 0;
  std::vector<double> err, time, losses;
  double rm[4] = {0, 0, 0, 0}, fit[4] = {0, 0, 0, 0};
  double n_desc = 0, n_fit = 0, wall = 0, sim_s = 0;
};

std::string note_of(const loop::landing::RunResult& r) {
  double rm[4] = {0, 0, 0, 0}, fit[4] = {0, 0, 0, 0};
  size_t n_fit = 0;
  for (const auto& d : r.descent) {
    const double e2[4] = {d.ex * d.ex, d.ey * d.ey, d.ez * d.ez, d.eyaw_deg * d.eyaw_deg};
    for (int a = 0; a < 4; ++a) {
      rm[a] += e2[a];
      if (d.fitted) fit[a] += e2[a];
    }
    n_fit += d.fitted;
  }
  char note[512];
  std::snprintf(note, sizeof note, "%d %d %.17g %.17g %d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %zu %zu %.17g %.17g",
                static_cast<int>(r.score.success), static_cast<int>(r.outcome.landed), r.score.touchdown_error_m,
                r.score.time_s, r.losses, rm[0], rm[1], rm[2], rm[3], fit[0], fit[1], fit[2], fit[3], r.descent.size(), n_fit,
                r.wall_s, r.sim_s);
  return note;
}

void add(Tally& t, const std::string& note) {
  std::istringstream in(note);
  int success = 0, landed = 0, losses = 0;
  double err = 0, time = 0, rm[4], fit[4], n_desc = 0, n_fit = 0, wall = 0, sim_s = 0;
  in >> success >> landed >> err >> time >> losses;
  for (double& v : rm) in >> v;
  for (double& v : fit) in >> v;
  in >> n_desc >> n_fit >> wall >> sim_s;
  if (!in) throw std::runtime_error("aerie-bench-landing: a run's summary note is malformed: '" + note + "'");
  ++t.runs;
  t.ok += success;
  if (landed) {
    t.err.push_back(err);
    t.time.push_back(time);
  }
  t.losses.push_back(losses);
  for (int a = 0; a < 4; ++a) {
    t.rm[a] += rm[a];
    t.fit[a] += fit[a];
  }
  t.n_desc += n_desc;
  t.n_fit += n_fit;
  t.wall += wall;
  t.sim_s += sim_s;
}

std::string summary(const Setup& s, const Tally& t) {
  double rm[4], fit[4];
  for (int a = 0; a < 4; ++a) {
    rm[a] = t.n_desc > 0 ? std::sqrt(t.rm[a] / t.n_desc) : std::nan("");
    fit[a] = t.n_fit > 0 ? std::sqrt(t.fit[a] / t.n_fit) : std::nan("");
  }
  char line[640];
  std::snprintf(line, sizeof line,
                "%-11s %-5s %-5s %s wind %.0f vib %-3s: %d/%d landed in bounds (%.1f %%), touchdown error mean %.3f m p95 "
                "%.3f m, time %.1f s, losses %.2f/run, TARGET_POSE RMSE x %.1f y %.1f z %.1f cm yaw %.2f deg (fitted "
                "poses: x %.1f y %.1f z %.1f cm yaw %.2f deg, box-only %.1f %%), %.2f s wall per simulated s",
                s.tracker.c_str(), s.controller.c_str(), s.world.c_str(), s.via.c_str(), s.wind, s.vibration ? "on" : "off", t.ok,
                t.runs, 100.0 * t.ok / static_cast<double>(t.runs), mean(t.err), percentile(t.err, 0.95),
                mean(t.time), mean(t.losses), 100 * rm[0], 100 * rm[1], 100 * rm[2], rm[3], 100 * fit[0], 100 * fit[1],
                100 * fit[2], fit[3], t.n_desc > 0 ? 100.0 * (t.n_desc - t.n_fit) / t.n_desc : 0.0, t.wall / t.sim_s);
  return line;
}

// One run's rows of landings.csv and descent.csv.
study::Record rows_of(const Setup& s, uint64_t run_seed, const loop::landing::RunResult& r) {
  std::ostringstream csv, desc;
  const char* vib = s.vibration ? "on" : "off";
  csv << run_seed << ',' << s.tracker << ',' << s.world << ',' << s.wind << ',' << vib << ',' << r.score.success << ','
      << r.score.touchdown_error_m << ',' << r.score.yaw_error_deg << ',' << r.score.time_s << ','
      << r.outcome.collided << ',' << r.losses << ',' << r.reacquisitions << ',' << s.controller << ','
      << r.outcome.landed << ',' << r.outcome.timed_out
      << ',' << r.final_state << ',' << r.lockstep_timeouts << ',' << r.rmse(0) << ',' << r.rmse(1) << ','
      << r.rmse(2) << ',' << r.rmse(3) << ',' << r.rmse(0, true) << ',' << r.rmse(1, true) << ',' << r.rmse(2, true)
      << ',' << r.rmse(3, true) << ',' << r.box_poses() << ',' << r.pad_refined << ',' << r.pad_not_found << ','
      << r.tracker_reseeded << ',' << r.pad_misses << ',' << r.sim_s << ',' << r.wall_s << ',' << s.via << '\n';
  for (const auto& d : r.descent)
    desc << run_seed << ',' << s.tracker << ',' << s.world << ',' << s.wind << ',' << vib << ',' << s.controller << ','
         << d.t << ',' << d.height << ',' << d.ex << ',' << d.ey << ',' << d.ez << ',' << d.eyaw_deg << ',' << d.fitted
         << '\n';
  return study::Record{{csv.str(), desc.str()}, note_of(r), ""};
}

}  // namespace

int main(int argc, char** argv) {
  study::Session session(argc, argv);  // MPI only when mpirun/srun started us (docs/scale.md)
  CLI::App app{"aerie-bench-landing: seeded autonomous landings in lock-step (CSV, summary, plots); "
               "spreads them over the ranks when started by mpirun"};
  int runs = 50, jobs = 1;
  uint64_t seed = 1;
  std::vector<std::string> trackers{"amcmr-ct"}, worlds{"room"}, vibrations{"on"}, controllers{"fuzzy"}, vias{"direct"};
  std::string autopilot = "px4";
  std::vector<double> winds{0.0};
  std::string out_dir = "bench-landing", resume_dir;
  Files files{"config/sim", "config/track_landing.yaml", "config/pilot.yaml", ""};
  bool plots = true;
  std::string log_level = "warn";
  double rank_timeout_s = 600;
  app.add_option("--runs", runs, "landings per configuration")->check(CLI::PositiveNumber);
  app.add_option("--seed", seed, "seed of the first run (run i uses seed + i)");
  app.add_option("--tracker", trackers, "trackers (comma-separated): ipsl-mr, amcmr-ct, am3, dcf, opencv-csrt, ...")
      ->delimiter(',');
  app.add_option("--wind", winds, "mean wind speeds in m/s (comma-separated; gusts 0.3 x that)")->delimiter(',');
  app.add_option("--vibration", vibrations, "camera vibration: on, off or on,off")->delimiter(',')
      ->check(CLI::IsMember({"on", "off"}));
  app.add_option("--world", worlds, "room, field or room,field")->delimiter(',')->check(CLI::IsMember({"room", "field"}));
  app.add_option("--controller", controllers, "landing controller: fuzzy, pid or fuzzy,pid")->delimiter(',')
      ->check(CLI::IsMember({"fuzzy", "pid"}));
  app.add_option("--via", vias, "how the pilot's commands reach the vehicle: direct (CTRL_CMD to the simulator), "
                               "mavlink-offboard (through aerie-mavlink, Aerie flies in offboard/GUIDED), "
                               "mavlink-precland (the autopilot's precision landing on LANDING_TARGET); comma-separated")
      ->delimiter(',')->check(CLI::IsMember({"direct", "mavlink-offboard", "mavlink-precland"}));
  app.add_option("--autopilot", autopilot, "the simulator's autopilot behind MAVLink: px4 or ardupilot (ArduCopter)")
      ->check(CLI::IsMember({"px4", "ardupilot"}));
  auto* out_opt = app.add_option("--out", out_dir, "output folder (landings.csv, descent.csv, study.progress, plots)");
  app.add_option("--resume", resume_dir,
                 "continue the study in this folder (started with --out and the same options): the runs already in its "
                 "CSVs are skipped")
      ->excludes(out_opt);
  app.add_option("--jobs", jobs, "landings flown in parallel (threads; under MPI each rank flies one at a time)")
      ->check(CLI::Range(1, 64));
  app.add_option("--rank-timeout", rank_timeout_s,
                 "under MPI: seconds a rank may take over one landing before the study stops, naming it")
      ->check(CLI::PositiveNumber);
  app.add_option("--sim-config-dir", files.sim_dir, "folder of landing_room.yaml and landing_field.yaml");
  app.add_option("--track-config", files.track, "aerie-track configuration");
  app.add_option("--pilot-config", files.pilot, "aerie-pilot configuration");
  app.add_flag("!--no-plots", plots, "do not run bench/landing/plot_landing.py");
  app.add_option("--log-dir", files.log_dir, "write each run's messages as an LCM log into this folder");
  app.add_option("--log-level", log_level, "the nodes' log level (info shows every pilot transition)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = session.rank() == 0 ? app.exit(e) : e.get_exit_code();  // the help or the error, once
    return rc == 0 ? 0 : 2;
  }
  spdlog::set_level(spdlog::level::from_str(log_level));  // warn: the nodes' transitions would flood the output
  const bool writer = session.rank() == 0;
  for (const auto& t : trackers)
    if (!track::is_known_tracker(t)) {
      if (writer) std::fprintf(stderr, "aerie-bench-landing: unknown tracker '%s'\n", t.c_str());
      return 2;
    }
  if (!resume_dir.empty()) out_dir = resume_dir;
  std::vector<Setup> setups;
  for (const auto& w : worlds)
    for (const auto& t : trackers)
      for (const auto& c : controllers)
        for (const auto& via : vias)
          for (double wind : winds)
            for (const auto& v : vibrations) setups.push_back({t, w, c, via, wind, v == "on"});
  if (jobs > 1 || session.distributed()) cv::setNumThreads(1);  // one core per landing
  if (session.distributed() && jobs > 1 && writer)
    std::fprintf(stderr, "aerie-bench-landing: --jobs %d ignored under MPI (%d ranks, one landing each at a time)\n", jobs,
                 session.size());
  if (!files.log_dir.empty()) std::filesystem::create_directories(files.log_dir);
  std::vector<loop::landing::LandingSpec> configs;
  for (const auto& s : setups) {
    configs.push_back(setup_spec(s, files));
    if (autopilot == "ardupilot") configs.back().autopilot = sim::autopilot::Personality::ArduCopter;
  }
  try {
    for (const auto& spec : configs) loop::landing::load_landing_run(spec, seed);  // a bad file refused now, not per run
  } catch (const std::exception& e) {
    if (writer) std::fprintf(stderr, "aerie-bench-landing: %s\n", e.what());
    return 2;
  }

  // One study over every configuration x seed (index = setup * runs + i), so that the ranks share
  // the whole matrix; rows in that order, as the per-configuration loop wrote them.
  std::ostringstream definition;
  definition << "runs=" << runs << " seed=" << seed << " autopilot=" << autopilot << " sim-config-dir=" << files.sim_dir
             << " track-config=" << files.track << " pilot-config=" << files.pilot << " configurations:";
  for (const auto& s : setups)
    definition << ' ' << s.tracker << '/' << s.world << '/' << s.controller << '/' << s.via << "/wind" << s.wind << "/vib"
               << (s.vibration ? "on" : "off");
  std::vector<Tally> tallies(setups.size());
  std::vector<int> written(setups.size(), 0);
  int failures = 0;
  auto seed_of = [&](int index) { return seed + static_cast<uint64_t>(index % runs); };
  study::Study st;
  st.tool = "aerie-bench-landing";
  st.dir = out_dir;
  st.runs = runs * static_cast<int>(setups.size());
  st.outputs = {{"landings.csv",
                 "seed,tracker,world,wind_m_s,vibration,success,touchdown_error_m,yaw_error_deg,time_s,collision,losses,"
                 "reacquisitions,controller,landed,timed_out,final_state,lockstep_timeouts,pose_rmse_x_m,pose_rmse_y_m,"
                 "pose_rmse_z_m,pose_rmse_yaw_deg,fit_rmse_x_m,fit_rmse_y_m,fit_rmse_z_m,fit_rmse_yaw_deg,box_poses,"
                 "pad_refined,pad_not_found,tracker_reseeded,pad_misses,sim_s,wall_s,via\n"},
                {"descent.csv", "seed,tracker,world,wind_m_s,vibration,controller,t_s,height_m,err_x_m,err_y_m,err_z_m,"
                                "err_yaw_deg,fitted\n"}};
  st.definition = definition.str();
  st.run = [&](int index) {
    const auto k = static_cast<size_t>(index / runs);
    const loop::landing::RunResult r = fly(setups[k], configs[k], seed_of(index), files);
    if (r.sim_s <= 0) throw std::runtime_error("the flight simulated no time");
    return rows_of(setups[k], seed_of(index), r);
  };
  st.describe = [&](int index) {  // the configuration too when there are several
    const Setup& s = setups[static_cast<size_t>(index / runs)];
    char conf[200] = "";
    if (setups.size() > 1)
      std::snprintf(conf, sizeof conf, " (%s %s %s %s wind %g vib %s)", s.tracker.c_str(), s.controller.c_str(),
                    s.world.c_str(), s.via.c_str(), s.wind, s.vibration ? "on" : "off");
    return "run with seed " + std::to_string(seed_of(index)) + conf;
  };
  st.on_written = [&](int index, const study::Record& r) {
    const auto k = static_cast<size_t>(index / runs);
    if (r.failed())
      ++failures;
    else
      add(tallies[k], r.note);
    if (++written[k] == runs && tallies[k].runs > 0) {
      std::printf("%s\n", summary(setups[k], tallies[k]).c_str());
      std::fflush(stdout);
    }
  };
  study::Options options;
  options.jobs = jobs;
  options.resume = !resume_dir.empty();
  options.rank_timeout_s = rank_timeout_s;
  try {
    if (!study::run(st, options, session).writer) return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    session.abort(1);
  }
  return bench::finish("aerie-bench-landing", "bench/landing/plot_landing.py", out_dir, plots, failures);
}
