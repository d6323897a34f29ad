#include "tools/eval/report.hpp"

#include <iomanip>
#include <ostream>
#include <sstream>

namespace aerie::eval {
namespace {

const char* name(Alignment a) {
  switch (a) {
    case Alignment::None: return "none";
    case Alignment::SE3: return "se3";
    case Alignment::Sim3: return "sim3";
  }
  return "?";
}

std::string json(const Stats& s) {
  std::ostringstream os;
  os << std::setprecision(10) << "{\"count\": " << s.count << ", \"rmse\": " << s.rmse << ", \"mean\": " << s.mean
     << ", \"median\": " << s.median << ", \"std\": " << s.std << ", \"min\": " << s.min << ", \"max\": " << s.max
     << "}";
  return os.str();
}

}  // namespace

Report evaluate(const Trajectory& ref_in, const Trajectory& est_in, const ReportOptions& opt) {
  const Associated a = associate(ref_in, est_in, opt.max_dt);
  Report r;
  r.matched = a.ref.size();
  r.ref_length_m = a.ref.path_length();
  const Trajectory aligned = align(a.est, a.ref, opt.alignment, &r.alignment);
  r.ate = statistics(ate_errors(a.ref, aligned));
  r.axes = per_axis_rmse(a.ref, aligned);
  if (a.ref.size() > opt.rpe_delta_frames) {
    const RelativeErrors rel = rpe_frames(a.ref, a.est, opt.rpe_delta_frames);
    r.rpe_trans = statistics(rel.translation);
    r.rpe_rot = statistics(rel.rotation_deg);
    r.rpe_trans_percent = rel.translation_percent();
  }
  if (opt.rpe_delta_m > 0) r.rpe_path_trans = statistics(rpe_path(a.ref, a.est, opt.rpe_delta_m).translation);
  r.drift = end_point_drift(a.ref, a.est);
  return r;
}

void print(std::ostream& os, const Report& r, const ReportOptions& opt) {
  os << std::fixed << std::setprecision(4);
  os << "matched poses            " << r.matched << " (reference path " << r.ref_length_m << " m)\n";
  os << "ATE (" << name(opt.alignment) << ")   rmse " << r.ate.rmse << " m  mean " << r.ate.mean << "  median "
     << r.ate.median << "  max " << r.ate.max;
  if (opt.alignment == Alignment::Sim3) os << "  scale " << r.alignment.scale;
  os << '\n';
  os << "RPE (" << opt.rpe_delta_frames << " frame)   trans rmse " << r.rpe_trans.rmse << " m  mean "
     << r.rpe_trans.mean << " m  = " << std::setprecision(3) << r.rpe_trans_percent << " %   rot rmse "
     << r.rpe_rot.rmse << " deg\n"
     << std::setprecision(4);
  if (opt.rpe_delta_m > 0)
    os << "RPE (" << opt.rpe_delta_m << " m)    trans rmse " << r.rpe_path_trans.rmse << " m  mean "
       << r.rpe_path_trans.mean << " m  over " << r.rpe_path_trans.count << " pairs\n";
  os << std::setprecision(1) << "per-axis RMSE            x " << r.axes.position.x() * 1e3 << " mm  y "
     << r.axes.position.y() * 1e3 << " mm  z " << r.axes.position.z() * 1e3 << " mm   roll " << std::setprecision(3)
     << r.axes.rpy_deg.x() << " deg  pitch " << r.axes.rpy_deg.y() << " deg  yaw " << r.axes.rpy_deg.z() << " deg\n";
  os << std::setprecision(4) << "end point                ";
  if (r.drift.loop) os << "loop drift " << r.drift.loop_closure_m << " m   ";
  os << "vs reference " << r.drift.vs_reference_m << " m = " << std::setprecision(3) << r.drift.percent() << " % of "
     << r.drift.distance_m << " m";
  if (!r.drift.loop) os << "   (not a loop: its end is far from its start)";
  os << '\n';
}

std::string to_json(const Report& r, const ReportOptions& opt) {
  std::ostringstream os;
  os << std::setprecision(10) << "{\"matched\": " << r.matched << ", \"reference_length_m\": " << r.ref_length_m
     << ", \"alignment\": \"" << name(opt.alignment) << "\", \"alignment_scale\": " << r.alignment.scale
     << ", \"ate_m\": " << json(r.ate) << ", \"rpe_delta_frames\": " << opt.rpe_delta_frames
     << ", \"rpe_trans_m\": " << json(r.rpe_trans) << ", \"rpe_rot_deg\": " << json(r.rpe_rot)
     << ", \"rpe_trans_percent\": " << r.rpe_trans_percent;
  if (opt.rpe_delta_m > 0)
    os << ", \"rpe_delta_m\": " << opt.rpe_delta_m << ", \"rpe_path_trans_m\": " << json(r.rpe_path_trans);
  os << ", \"rmse_xyz_m\": [" << r.axes.position.x() << ", " << r.axes.position.y() << ", " << r.axes.position.z()
     << "], \"rmse_rpy_deg\": [" << r.axes.rpy_deg.x() << ", " << r.axes.rpy_deg.y() << ", " << r.axes.rpy_deg.z()
     << "], \"loop\": " << (r.drift.loop ? "true" : "false");
  if (r.drift.loop) os << ", \"loop_drift_m\": " << r.drift.loop_closure_m;
  os << ", \"end_drift_m\": " << r.drift.vs_reference_m
     << ", \"end_drift_percent\": " << r.drift.percent() << "}";
  return os.str();
}

}  // namespace aerie::eval
