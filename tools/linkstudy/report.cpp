#include "tools/linkstudy/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <tuple>

namespace aerie::linkstudy {

namespace {

double factor_value(const Condition& c, const std::string& factor) {
  if (factor == "delay_ms") return c.delay_ms;
  if (factor == "jitter_ms") return c.jitter_ms;
  if (factor == "loss") return c.loss;
  if (factor == "bandwidth_mbit") return c.bandwidth_mbit;
  if (factor == "jpeg_quality") return c.jpeg_quality;
  return c.burst_length;
}

// Worse first for the factors where less is worse (0 = unlimited bandwidth / raw images: best).
double badness(const std::string& factor, double v) {
  if (factor == "bandwidth_mbit" || factor == "jpeg_quality") return v == 0 ? -1e18 : -v;
  return v;
}

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

}  // namespace

double Cell::metric_mean() const { return metric_n ? metric_sum / metric_n : std::nan(""); }

std::optional<double> breaking_point(const std::string& factor, const std::vector<std::pair<double, Cell>>& by_value,
                                     double rate) {
  auto sorted = by_value;
  std::sort(sorted.begin(), sorted.end(),
            [&](const auto& a, const auto& b) { return badness(factor, a.first) < badness(factor, b.first); });
  for (const auto& [v, cell] : sorted)
    if (cell.runs && cell.success_rate() < rate) return v;
  return std::nullopt;
}

void write_report(const StudyConfig& study, const std::vector<RunSpec>& specs,
                  const std::vector<std::optional<RunRow>>& rows, const std::string& out_dir) {
  // (workload, placement, tracker, condition, faults) -> cell
  using Key = std::tuple<int, std::string, std::string, std::string, std::string>;
  std::map<Key, Cell> cells;
  double wall = 0, sim_s = 0;
  size_t flown = 0;
  for (size_t i = 0; i < specs.size(); ++i) {
    if (!rows[i]) continue;
    const RunSpec& s = specs[i];
    const RunRow& r = *rows[i];
    Cell& c = cells[{static_cast<int>(s.workload), s.placement->name, s.tracker, s.condition->name(), s.faults}];
    ++c.runs;
    c.successes += r.success;
    c.collisions += r.collision;
    c.runs_fallback += r.pilot_stale_holds > 0 || r.control_fallbacks > 0;
    c.runs_offboard_hold += r.faults.command_timeouts > 0;
    c.malformed += static_cast<double>(r.faults.malformed);
    ++c.final_states[r.final_state];
    if (r.value >= 0 && std::isfinite(r.value)) {
      c.metric_sum += r.value;
      ++c.metric_n;
    }
    if (r.view_age_p50_ms >= 0) {
      c.age_p50_sum += r.view_age_p50_ms;
      c.age_p95_sum += r.view_age_p95_ms;
      ++c.age_n;
    }
    c.stale_holds += static_cast<double>(r.pilot_stale_holds);
    c.fallbacks += static_cast<double>(r.control_fallbacks);
    c.frames_lost += static_cast<double>(r.frames_lost);
    c.down_kbit_s += r.down_kbit_s;
    c.down_lost += static_cast<double>(r.down.dropped_loss);
    c.down_queue_dropped += static_cast<double>(r.down.dropped_queue);
    for (const auto& h : r.hops) {
      Cell::Hop& ch = c.hops[h.channel];
      ch.direction = h.direction;
      if (h.latency_ms.count) {
        ch.median_sum += h.latency_ms.median;
        ++ch.runs;
      }
      ch.sent += h.sent;
      ch.delivered += h.delivered;
    }
    wall += r.wall_s;
    sim_s += r.sim_s;
    ++flown;
  }

  std::ofstream md(out_dir + "/report.md");
  md << "# Link study\n\n" << flown << " of " << specs.size() << " flights, " << study.seeds << " seeds each (from "
     << study.first_seed << "), lock-step: " << fmt("%.0f", sim_s) << " simulated s in " << fmt("%.0f", wall)
     << " s of flight-thread time. Rows: `study.csv`. Each cell: success rate, then the mean of the metric "
        "(landing: touchdown error, cm, over the landed runs; avoidance: steady-state heading RMSE, deg, over the "
        "settled runs; replay: the AUC of the boxes that reached the operator).\n";
  for (Workload w : study.workloads) {
    const bool land = w == Workload::kLanding, replay = w == Workload::kReplay;
    md << "\n## " << (land ? "Landing" : replay ? "Replay (open loop)" : "Avoidance") << "\n";
    const std::vector<std::string> trackers = w != Workload::kAvoidance ? study.trackers : std::vector<std::string>{"-"};
    for (const Sweep& sw : study.sweeps) {
      md << "\n### Against " << sw.factor << "\n\n![success](" << workload_name(w) << "_success_vs_" << sw.factor
         << ".png) ![view age](" << workload_name(w) << "_view_age_vs_" << sw.factor << ".png)\n\n| placement | tracker |";
      for (const auto& c : sw.conditions) md << ' ' << sw.factor << ' ' << factor_value(c, sw.factor) << " |";
      md << " < 95 % from | < 50 % from |\n|---|---|";
      for (size_t k = 0; k < sw.conditions.size() + 2; ++k) md << "---|";
      md << '\n';
      auto cell_of = [&](const Placement& p, const std::string& t, const Condition& c) {
        const auto it = cells.find({static_cast<int>(w), p.name, t, c.name(), study.faults.front()});
        return it == cells.end() ? Cell{} : it->second;
      };
      for (const auto& p : study.placements)
        for (const auto& t : trackers) {
          md << "| " << p.name << " | " << t << " |";
          std::vector<std::pair<double, Cell>> by_value;
          for (const auto& c : sw.conditions) {
            const Cell cell = cell_of(p, t, c);
            by_value.emplace_back(factor_value(c, sw.factor), cell);
            if (!cell.runs) {
              md << " — |";
              continue;
            }
            md << ' ' << fmt("%.0f %%", 100 * cell.success_rate()) << ", "
               << (std::isfinite(cell.metric_mean()) ? fmt("%.2f", land ? 100 * cell.metric_mean() : cell.metric_mean()) : "—")
               << " |";
          }
          for (double rate : {0.95, 0.5}) {
            const auto b = breaking_point(sw.factor, by_value, rate);
            md << ' ' << (b ? fmt("%g", *b) : "not reached") << " |";
          }
          md << '\n';
        }
      // The operator's view and the fallbacks, per placement (first tracker).
      md << "\n| placement | " << sw.factor << " | view age p50 / p95 (ms) | "
         << (land ? "pilot stale HOLDs / run" : replay ? "frames lost / run" : "control fallback commands / run")
         << " | air->ground kbit/s | lost / queue-dropped per run (air->ground) |\n|---|---|---|---|---|---|\n";
      for (const auto& p : study.placements)
        for (const auto& c : sw.conditions) {
          const Cell cell = cell_of(p, trackers.front(), c);
          if (!cell.runs) continue;
          const double n = cell.runs;
          md << "| " << p.name << " | " << factor_value(c, sw.factor) << " | "
             << (cell.age_n ? fmt("%.0f", cell.age_p50_sum / cell.age_n) + " / " + fmt("%.0f", cell.age_p95_sum / cell.age_n)
                            : "—")
             << " | " << fmt("%.2f", (land ? cell.stale_holds : replay ? cell.frames_lost : cell.fallbacks) / n) << " | "
             << fmt("%.0f", cell.down_kbit_s / n) << " | " << fmt("%.1f", cell.down_lost / n) << " / "
             << fmt("%.1f", cell.down_queue_dropped / n) << " |\n";
        }
      // The link's hop per channel, from the two sides' logs joined (aerie-latency AIR GROUND).
      md << "\n| placement | " << sw.factor
         << " | the link's hop per channel: median (ms), delivered of sent (the air and ground logs joined) |\n|---|---|---|\n";
      for (const auto& p : study.placements)
        for (const auto& c : sw.conditions) {
          const Cell cell = cell_of(p, trackers.front(), c);
          if (!cell.runs) continue;
          md << "| " << p.name << " | " << factor_value(c, sw.factor) << " |";
          for (const auto& [channel, h] : cell.hops)
            md << ' ' << channel << (h.direction == "air->ground" ? " ↓ " : " ↑ ")
               << (h.runs ? fmt("%.0f", h.median_sum / h.runs) : std::string("—")) << ", "
               << fmt("%.1f %%", h.sent ? 100.0 * static_cast<double>(h.delivered) / static_cast<double>(h.sent) : 0.0) << ";";
          md << " |\n";
        }
    }
  }
  if (study.faults.size() == 1 && study.faults.front() == "none") return;

  // Faults (docs/faults.md): per placement and condition, each scenario's outcome.
  std::map<std::string, const Condition*> conditions;
  for (const Sweep& sw : study.sweeps)
    for (const auto& c : sw.conditions) conditions.emplace(c.name(), &c);
  for (Workload w : study.workloads) {
    if (w == Workload::kReplay) continue;
    const bool land = w == Workload::kLanding;
    md << "\n## Faults in flight (" << workload_name(w) << ")\n\nSafe: no collision. Completed: "
       << (land ? "landed on the pad (the landing's success)" : "turned along the wall without entering the danger zone")
       << ". Fallback: runs in which " << (land ? "the pilot held on stale inputs" : "aerie-control hovered on stale inputs")
       << "; offboard hold: runs in which the autopilot held because commands stopped (1 s). Malformed: decoder "
          "refusals (per subscription) of the nodes alive at the end, per run.\n";
    const std::vector<std::string> trackers = land ? study.trackers : std::vector<std::string>{"-"};
    for (const auto& t : trackers)
      for (const auto& p : study.placements)
        for (const auto& [cname, c] : conditions) {
          md << "\n### " << p.name << (land ? ", " + t : "") << ", link " << cname << "\n\n| faults | runs | safe | completed | "
             << (land ? "touchdown error (cm)" : "heading RMSE (deg)")
             << " | fallback | offboard hold | malformed / run | final states |\n|---|---|---|---|---|---|---|---|---|\n";
          for (const auto& f : study.faults) {
            const auto it = cells.find({static_cast<int>(w), p.name, t, cname, f});
            if (it == cells.end()) continue;
            const Cell& cell = it->second;
            std::string states;
            for (const auto& [s, n] : cell.final_states) states += (states.empty() ? "" : ", ") + s + " " + std::to_string(n);
            md << "| `" << f << "` | " << cell.runs << " | " << cell.runs - cell.collisions << " | " << cell.successes << " | "
               << (std::isfinite(cell.metric_mean()) ? fmt(land ? "%.1f" : "%.2f", (land ? 100 : 1) * cell.metric_mean()) : "—")
               << " | " << cell.runs_fallback << " | " << cell.runs_offboard_hold << " | "
               << fmt("%.0f", cell.malformed / cell.runs) << " | " << states << " |\n";
          }
        }
  }
}

}  // namespace aerie::linkstudy
