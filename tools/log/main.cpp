// aerie-log: inspect, export and cut LCM event logs (the lcm-logger format).
//   aerie-log info LOG [--json] [--resync]
//   aerie-log export LOG --channel C --out DIR [--resync] [--force]
//   aerie-log cut LOG --from S --to S --out LOG2 [--resync] [--force]
// Exit status: 0 ok, 1 error (bad arguments, missing file/channel), 2 the log is
// damaged (everything before the damage was still processed, and it is reported).
#include <CLI/CLI.hpp>

#include <iostream>
#include <limits>

#include "tools/log/log_cut.hpp"
#include "tools/log/log_export.hpp"
#include "tools/log/log_info.hpp"

namespace {

int report_damage(const std::vector<aerie::logio::Damage>& damage) {
  for (const auto& d : damage) std::cerr << "aerie-log: DAMAGE: " << d.message << "\n";
  return damage.empty() ? 0 : 2;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Inspect, export and cut LCM event logs (lcm-logger format)", "aerie-log"};
  app.require_subcommand(1);
  std::string log, channel, out;
  bool json = false, resync = false, force = false;
  double from_s = 0, to_s = std::numeric_limits<double>::infinity();

  auto* info = app.add_subcommand("info", "Channels, types, counts, rates, gaps, dropped messages, duration");
  info->add_option("log", log, "LCM log file")->required();
  info->add_flag("--json", json, "Print JSON instead of a table");

  auto* exp = app.add_subcommand("export", "Export a channel: images to PNG, stereo to left/right PNG folders, "
                                           "poses to TUM trajectories, boxes to CSV");
  exp->add_option("log", log, "LCM log file")->required();
  exp->add_option("--channel", channel, "Channel to export")->required();
  exp->add_option("--out", out, "Output folder")->required();

  auto* cut = app.add_subcommand("cut", "Copy a time range (seconds from the first event) into a new log");
  cut->add_option("log", log, "LCM log file")->required();
  cut->add_option("--from", from_s, "Start, seconds from the first event (inclusive)")->check(CLI::NonNegativeNumber);
  cut->add_option("--to", to_s, "End, seconds from the first event (exclusive; default: the end)");
  cut->add_option("--out", out, "Output log file")->required();

  for (auto* sub : {info, exp, cut})
    sub->add_flag("--resync", resync, "Skip damaged bytes to the next event header instead of stopping there");
  for (auto* sub : {exp, cut})
    sub->add_flag("--force", force, "Overwrite an existing output (refused otherwise)");

  CLI11_PARSE(app, argc, argv);
  try {
    if (*info) {
      const auto s = aerie::logtools::summarize(log, resync);
      if (json) {
        aerie::logtools::print_summary_json(s, std::cout);
      } else {
        aerie::logtools::print_summary(s, std::cout);
      }
      return s.damage.empty() ? 0 : 2;
    }
    if (*exp) {
      const auto r = aerie::logtools::export_channel(log, channel, out, resync, force);
      std::cout << "exported " << r.exported << " " << r.type << " messages of " << channel << " to:\n";
      for (const auto& o : r.outputs) std::cout << "  " << o << "\n";
      if (r.undecodable) std::cout << "skipped " << r.undecodable << " undecodable messages\n";
      if (r.other_type) std::cout << "skipped " << r.other_type << " messages of another type\n";
      return report_damage(r.damage);
    }
    const auto r = aerie::logtools::cut(log, from_s, to_s, out, resync, force);
    std::cout << "wrote " << r.events_written << " of " << r.events_read << " events to " << out << "\n";
    return report_damage(r.damage);
  } catch (const std::exception& e) {
    std::cerr << "aerie-log: " << e.what() << "\n";
    return 1;
  }
}
