// aerie-log: inspect, export, cut and compare LCM event logs (the lcm-logger format).
//   aerie-log info LOG [--json] [--resync]
//   aerie-log export LOG --channel C --out DIR [--camera CH] [--resync] [--force]
//   aerie-log cut LOG --from S --to S --out LOG2 [--exclude REGEX] [--resync] [--force]
//   aerie-log diff A B [--channels C1,C2,...] [--pair order|seq|utime]
//   aerie-log record LOG [--channels REGEX] [--queue N] [--lcm-url URL] [--duration S] [--force]
//   aerie-log report LOG --out DIR [--no-plots] [--script PY] [--python EXE] [--resync] [--force]
// Exit status: 0 ok, 1 error (bad arguments, missing file/channel), 2 the log is
// damaged (everything before the damage was still processed, and it is reported).
// diff, as cmp(1): 0 the logs hold the same messages, 1 they differ, 2 usage error or a log
// that cannot be read or is damaged.
#include <CLI/CLI.hpp>

#include <iostream>
#include <limits>

#include "tools/log/log_cut.hpp"
#include "tools/log/log_diff.hpp"
#include "tools/log/log_export.hpp"
#include "common/bus/node.hpp"
#include "common/util/time.hpp"
#include "tools/log/log_info.hpp"
#include "tools/log/log_record.hpp"
#include "tools/log/log_report.hpp"

namespace {

// Records until SIGINT/SIGTERM or `duration_s`; what liblcm still holds is written before the
// file is closed, so a Ctrl-C loses nothing that was received.
int record(aerie::logtools::RecordOptions options, const std::string& url, double duration_s) {
  aerie::bus::install_stop_handlers();
  aerie::bus::Bus bus(url);
  const int queue = options.queue;
  aerie::logtools::Recorder recorder(bus, std::move(options));
  std::cerr << "aerie-log record: recording " << recorder.path() << " (queue " << queue << " messages)\n";
  const int64_t t0 = aerie::util::wall_utime();
  const auto elapsed_s = [&] { return (aerie::util::wall_utime() - t0) * 1e-6; };
  while (!aerie::bus::stop_requested() && (duration_s <= 0 || elapsed_s() < duration_s)) {
    bus.handle(50);
    recorder.tick(aerie::util::wall_utime());
  }
  while (bus.handle(0) > 0) {
  }
  recorder.close();
  std::cerr << "aerie-log record: " << recorder.events() << " events, " << recorder.bytes() / 1e6 << " MB in "
            << elapsed_s() << " s to " << recorder.path() << "\n";
  return 0;
}

int report_damage(const std::vector<aerie::logio::Damage>& damage) {
  for (const auto& d : damage) std::cerr << "aerie-log: DAMAGE: " << d.message << "\n";
  return damage.empty() ? 0 : 2;
}

// The flight report: the CSVs, then the plots and the page when asked and possible.
int report(const std::string& log, const std::string& out, bool resync, bool force, bool plots,
           const std::string& script, const std::string& python) {
  const auto r = aerie::logtools::write_report_data(log, out, resync, force);
  std::cout << "report of " << log << " (" << r.summary.events << " events, " << r.summary.duration_s << " s) in "
            << out << "\n";
  for (const auto& s : r.sections) {
    std::string missing;
    for (const auto& m : s.missing) missing += (missing.empty() ? "" : ", ") + m;
    std::cout << "  " << (s.present ? "+ " : "- ") << s.title;
    if (!missing.empty()) std::cout << (s.present ? " (not in the log: " : " (missing: ") << missing << ")";
    std::cout << "\n";
  }
  const auto& m = r.summary;
  std::cout << "  final pilot state " << (m.final_pilot_state.empty() ? "-" : m.final_pilot_state) << ", distance ";
  if (m.distance_m) std::cout << *m.distance_m << " m (" << m.distance_source << ")";
  else std::cout << "-";
  if (m.landing_error_m) std::cout << ", landing error " << *m.landing_error_m << " m";
  std::cout << ", tracker losses " << m.track_losses << "\n";
  if (plots) {
    const auto plot = aerie::logtools::run_report_plots(python, script, out);
    if (plot.ok)
      std::cout << "page: " << out << "/index.html\n";
    else
      std::cerr << "aerie-log report: " << plot.message << "\n";
  }
  return report_damage(r.damage);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Inspect, export, cut and compare LCM event logs (lcm-logger format)", "aerie-log"};
  app.require_subcommand(1);
  std::string log, log_b, channel, out, exclude, pair = "order", camera;
  std::vector<std::string> channels;
  bool json = false, resync = false, force = false;
  double from_s = 0, to_s = std::numeric_limits<double>::infinity();

  auto* info = app.add_subcommand("info", "Channels, types, counts, rates, gaps, duration; messages the logger "
                                           "lost and frames producers skipped by design, told apart");
  info->add_option("log", log, "LCM log file")->required();
  info->add_flag("--json", json, "Print JSON instead of a table");

  auto* exp = app.add_subcommand("export", "Export a channel: images to PNG, stereo to left/right PNG folders, "
                                           "poses to TUM trajectories, boxes to CSV, tracks to OTB boxes");
  exp->add_option("log", log, "LCM log file")->required();
  exp->add_option("--channel", channel, "Channel to export")->required();
  exp->add_option("--out", out, "Output folder")->required();
  exp->add_option("--camera", camera, "Tracks: the channel of the source frames (default: the tracks' camera field)");
  exp->footer("Tracks (aerie.track_t) go to <CHANNEL>.csv (t,seq,x,y,w,h,status,confidence) and "
              "<CHANNEL>.txt (x,y,w,h, the OTB groundtruth_rect layout): x,y the box's top-left corner, w,h its size, "
              "in pixels, 0-based image coordinates; NaN while the tracker is IDLE. One row per frame of the source "
              "camera channel in the log, paired by utime: a frame the tracker skipped is a NaN row (status "
              "SKIPPED), so row i is frame i as in the sequence's groundtruth.txt.");

  auto* cut = app.add_subcommand("cut", "Copy a time range (seconds from the first event) into a new log");
  cut->add_option("log", log, "LCM log file")->required();
  cut->add_option("--from", from_s, "Start, seconds from the first event (inclusive)")->check(CLI::NonNegativeNumber);
  cut->add_option("--to", to_s, "End, seconds from the first event (exclusive; default: the end)");
  cut->add_option("--out", out, "Output log file")->required();
  cut->add_option("--exclude", exclude, "Leave out the channels matching this regular expression (whole name, ECMAScript)");

  auto* diff = app.add_subcommand("diff", "Compare two logs channel by channel: counts, identical messages, the "
                                           "largest numeric field difference");
  diff->add_option("A", log, "First LCM log file")->required();
  diff->add_option("B", log_b, "Second LCM log file")->required();
  diff->add_option("--channels", channels, "Channels to compare, comma-separated (default: every channel of A or B)")
      ->delimiter(',')
      ->allow_extra_args(false);  // one argument per --channels: `--channels X A B` leaves A and B positional
  diff->add_option("--pair", pair, "How messages are paired: order (the i-th with the i-th), seq (by the message's "
                                   "frame number) or utime (by its time)")
      ->check(CLI::IsMember({"order", "seq", "utime"}))
      ->capture_default_str();
  diff->footer("By default messages are paired by their order within the channel: the i-th message of a channel in A "
               "with the i-th in B (message 0 is the first), whatever their times. --pair seq pairs them by the "
               "message's own frame number (the seq field of lcmtypes/, an image's metadata \"seq\"), --pair utime by "
               "its utime field, so that a frame one log skipped is counted as missing instead of shifting every "
               "pair after it; the table then gives per channel the frames matched, missing in A, missing in B, "
               "identical and differing. A channel whose type has no such field is paired by order (column "
               "\"paired\"). A pair is identical when the payloads are "
               "equal byte for byte; for the catalogue types (lcmtypes/) the numeric fields of differing pairs are "
               "compared too, and the largest absolute difference is shown with its field.\n"
               "Exit status: 0 every compared channel is identical (same counts, every message identical), "
               "1 they differ, 2 usage error or a log that cannot be read or is damaged.");

  aerie::logtools::RecordOptions rec_opt;
  std::string url;
  double duration_s = 0;
  auto* rec = app.add_subcommand("record", "Record the LCM network into a log (lcm-logger's format) with a receive "
                                           "queue deep enough for a loaded machine; Ctrl-C closes it");
  rec->add_option("log", rec_opt.path, "LCM log file to write")->required();
  rec->add_option("--channels", rec_opt.channels, "LCM channel regular expression")->capture_default_str();
  rec->add_option("--queue", rec_opt.queue,
                  "messages liblcm keeps for the recorder while it writes (lcm-logger: 30); 0 = no limit")
      ->capture_default_str()
      ->check(CLI::Range(0, 10'000'000));
  rec->add_option("--lcm-url", url, "LCM URL (default: LCM_DEFAULT_URL or LCM's default)");
  rec->add_option("--duration", duration_s, "stop after this many seconds (default: until SIGINT/SIGTERM)")
      ->check(CLI::NonNegativeNumber);
  rec->add_flag("--force", rec_opt.force, "Overwrite an existing log (refused otherwise)");
  rec->footer("Event times are the receive times, as lcm-logger writes them; lcm-logplayer replays the log. "
              "The file is flushed every 0.1 s.");

  bool plots = true;
  std::string script = aerie::logtools::default_report_script(), python = "/usr/bin/python3";
  auto* rep = app.add_subcommand("report", "One page per flight: tidy CSVs of the trajectory, pilot states, tracker, "
                                           "VO, NAV_STATE error, latency, link and rates, PNG plots and index.html");
  rep->add_option("log", log, "LCM log file")->required();
  rep->add_option("--out", out, "Output folder (CSVs, PNGs, index.html)")->required();
  rep->add_flag("!--no-plots", plots, "Write the CSVs only (no PNGs, no index.html)");
  rep->add_option("--script", script, "The plot script")->capture_default_str();
  rep->add_option("--python", python, "The Python with numpy and matplotlib")->capture_default_str();
  rep->footer("A section appears only when the log has its channels; the page names the missing ones "
              "(docs/logs.md, \"Flight report\"). Without python3 or matplotlib the CSVs are still written "
              "and the command says so (exit status 0). Exit status 2: the log is damaged (what was read "
              "before the damage is reported).");

  for (auto* sub : {info, exp, cut, rep})
    sub->add_flag("--resync", resync, "Skip damaged bytes to the next event header instead of stopping there");
  for (auto* sub : {exp, cut, rep})
    sub->add_flag("--force", force, "Overwrite an existing output (refused otherwise)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);  // prints the help or the error
    return rc != 0 && (diff->parsed() || rep->parsed()) ? 2 : rc;
  }
  if (*diff) {
    try {
      const auto d =
          aerie::logtools::diff_logs(log, log_b, channels, aerie::logtools::pair_by_from_string(pair));
      aerie::logtools::print_diff(d, std::cout);
      return d.same() ? 0 : 1;
    } catch (const std::exception& e) {
      std::cerr << "aerie-log diff: " << e.what() << "\n";
      return 2;
    }
  }
  try {
    if (*rec) return record(rec_opt, url, duration_s);
    if (*info) {
      const auto s = aerie::logtools::summarize(log, resync);
      if (json) {
        aerie::logtools::print_summary_json(s, std::cout);
      } else {
        aerie::logtools::print_summary(s, std::cout);
      }
      return s.damage.empty() ? 0 : 2;
    }
    if (*rep) return report(log, out, resync, force, plots, script, python);
    if (*exp) {
      const auto r = aerie::logtools::export_channel(log, channel, out, resync, force, camera);
      std::cout << "exported " << r.exported << " " << r.type << " messages of " << channel << " to:\n";
      for (const auto& o : r.outputs) std::cout << "  " << o << "\n";
      if (r.frames)
        std::cout << "one row per frame of " << r.camera << ": " << r.frames << " rows, " << r.skipped_frames
                  << " frames the tracker skipped (NaN rows)\n";
      for (const auto& n : r.notes) std::cout << "note: " << n << "\n";
      if (r.undecodable) std::cout << "skipped " << r.undecodable << " undecodable messages\n";
      if (r.other_type) std::cout << "skipped " << r.other_type << " messages of another type\n";
      return report_damage(r.damage);
    }
    const auto r = aerie::logtools::cut(log, from_s, to_s, out, resync, force, exclude);
    std::cout << "wrote " << r.events_written << " of " << r.events_read << " events to " << out << "\n";
    return report_damage(r.damage);
  } catch (const std::exception& e) {
    std::cerr << "aerie-log: " << e.what() << "\n";
    return 1;
  }
}
