#pragma once
// The full evaluation of an estimate against a reference in one call, printed as text
// and written as JSON (used by aerie-eval-traj and the VO benchmark).
#include <iosfwd>
#include <string>

#include "tools/eval/metrics.hpp"

namespace aerie::eval {

struct ReportOptions {
  Alignment alignment = Alignment::SE3;
  double max_dt = 0.01;        // association tolerance (s)
  size_t rpe_delta_frames = 1;  // per-frame RPE
  double rpe_delta_m = 0;       // evo-style RPE over path segments (0 = off)
};

struct Report {
  size_t matched = 0;
  Similarity alignment;
  Stats ate;                        // metres
  Stats rpe_trans, rpe_rot;         // per delta_frames: metres, degrees
  double rpe_trans_percent = 0;     // 100 sum |t(E)| / sum |t(Q)|
  Stats rpe_path_trans;             // over path segments (if rpe_delta_m > 0)
  AxisRmse axes;
  Drift drift;
  double ref_length_m = 0;
};

Report evaluate(const Trajectory& ref, const Trajectory& est, const ReportOptions& opt);
void print(std::ostream& os, const Report& r, const ReportOptions& opt);
// JSON object text (no trailing newline).
std::string to_json(const Report& r, const ReportOptions& opt);

}  // namespace aerie::eval
