#pragma once
// The optimisation's outputs in one folder: the controllers (YAML + FLL), the CE
// progress of each stage (CSV), the experiment's runs and summary (CSV), trajectories
// and membership functions for plotting, summary.json, report.md, and the PNG plots
// drawn by plot_report.py (/usr/bin/python3 + matplotlib).
#include <string>
#include <vector>

#include "ground/ceopt/pipeline.hpp"

namespace aerie::ceopt {

struct ReportInputs {
  const CeoptConfig* config = nullptr;
  const TuningResult* tuning = nullptr;
  std::vector<std::pair<std::string, flc::FlcSpec>> controllers;  // name -> controller, in report order
  std::vector<ExperimentRun> runs;
  int threads = 0;
  std::string load_before, load_after;  // /proc/loadavg around the optimisation
  std::string command_line;
};

// Writes everything except the plots; returns the paths written.
std::vector<std::string> write_report(const std::string& dir, const ReportInputs& in);

// Runs the plot script on dir; returns false (and the reason) if it failed.
bool draw_plots(const std::string& dir, const std::string& script, std::string* error);

std::string read_loadavg();
// "1.16 ± 0.16" (deg) over the settled runs, or "never settled" when none did (no NaN).
std::string rmse_text(const ExperimentSummary& s);

}  // namespace aerie::ceopt
