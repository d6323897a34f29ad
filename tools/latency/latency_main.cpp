// aerie-latency: end-to-end latency per channel (log receive time - message utime)
// and per hop (from the nodes' STATUS_* heartbeats) of any LCM log.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <iostream>

#include "common/logio/event_log.hpp"
#include "common/util/cli.hpp"
#include "tools/latency/latency.hpp"
#include "tools/latency/link_hops.hpp"

int main(int argc, char** argv) {
  using namespace aerie;
  CLI::App app{
      "aerie-latency: end-to-end latency of every channel of an LCM log (receive time in the log minus\n"
      "the message's source utime) as median/p90/p99/max, and per hop from the nodes' STATUS_* messages.\n"
      "Given a second log (a split deployment: the air side's log, then the ground side's), also the\n"
      "link's hop per channel: the receiving side's log time minus the sending side's.\n"
      "Recorded data: a utime more than 1 h from the log's receive time (a dataset's own clock, e.g.\n"
      "EuRoC's) is not on the log's clock; such a message's latency is its receive time minus the\n"
      "receive time of the first message of the same frame (same utime) in the log, normally the\n"
      "camera's, and per hop input and age are taken from that arrival (docs/viewer.md \"Latency\")."};
  std::string log_path, ground_log_path, csv, json, log_level = "info";
  latency::LatencyAnalysis::Options opts;
  app.add_option("log", log_path, "LCM log file (lcm-logger); the air side's in a split deployment")
      ->required()->check(CLI::ExistingFile);
  app.add_option("ground_log", ground_log_path, "the ground side's LCM log of the same flight (clocks synchronised)")
      ->check(CLI::ExistingFile);
  app.add_option("--channels", opts.channels, "regex of the channels to report (whole names)")->capture_default_str();
  app.add_flag("--unknown-types", opts.unknown_types,
               "also read utime from payloads of types outside Aerie's catalogue (assumes utime comes first)");
  app.add_option("--csv", csv, "write the figures as CSV");
  app.add_option("--json", json, "write the figures as JSON");
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error, critical or off");
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "%s: %s (see --help)\n", "aerie-latency", e.what());
    return 2;
  }
  util::init_logging("aerie-latency", log_level);
  try {
    latency::LatencyAnalysis analysis(opts);
    logio::Reader reader(log_path, logio::Reader::Options{.resync = true});
    logio::Event ev;
    while (reader.next(ev)) analysis.add(ev.channel, ev.utime, ev.data.data(), ev.data.size());
    for (const auto& d : reader.damage()) spdlog::warn("{}", d.message);
    const auto channels = analysis.channels();
    const auto hops = analysis.hops();
    std::cout << log_path << ": " << analysis.events() << " events\n\n" << latency::format_table(channels, hops);
    if (!ground_log_path.empty()) {
      latency::LinkJoin join;
      for (const auto& [path, side] : {std::pair{log_path, latency::LinkJoin::Log::kAir},
                                       std::pair{ground_log_path, latency::LinkJoin::Log::kGround}}) {
        logio::Reader r(path, logio::Reader::Options{.resync = true});
        logio::Event e;
        while (r.next(e)) join.add(side, e.channel, e.utime, e.data.data(), e.data.size());
        for (const auto& d : r.damage()) spdlog::warn("{}", d.message);
      }
      std::cout << '\n' << latency::format_link_table(join.hops());
    }
    auto write = [](const std::string& path, const std::string& text) {
      std::ofstream out(path);
      if (!(out << text)) throw std::runtime_error("cannot write '" + path + "'");
    };
    if (!csv.empty()) write(csv, latency::to_csv(channels, hops));
    if (!json.empty()) write(json, latency::to_json(channels, hops));
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
    return 1;
  }
  return 0;
}
