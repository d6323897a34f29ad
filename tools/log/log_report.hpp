#pragma once
// `aerie-log report`: one page per flight, as PX4's Flight Review gives its users. The log is
// read once (common/logio, any size: payloads are decoded one at a time) into tidy CSVs in the
// output folder, one per section, which tools/log/report_plots.py turns into PNG plots and
// DIR/index.html (docs/logs.md, "Flight report"). Times `t` are seconds of log time since the
// log's first event; message utimes are kept beside them.
//   trajectory.csv  channel,t,utime,x,y,z            VO_POSE, NAV_STATE, SIM_STATE, GT_POSE
//   map.csv         x,y,z,size                       occupied voxels of the last full MAP_OCTOMAP
//   pad.csv         x,y,z,yaw_deg                    the helipad (SIM_STATE target_position)
//   pilot.csv       t,utime,state,state_name,reason,height_m,losses,reacquisitions      PILOT_STATE
//   track.csv       t,utime,seq,tracker,status,confidence,x,y,width,height,frames_skipped,processing_ms
//   vo.csv          t,utime,seq,status,inliers,features_2d,features_3d,keyframe         VO_POSE
//   vo_status.csv   t,counter,value                  STATUS_VO counters (cumulative)
//   nav_error.csv   t,utime,status,nav_x..z,truth_x..z,error_m,aligned_error_m           NAV_STATE vs truth
//   latency.csv     aerie-latency's CSV (tools/latency): per channel and per hop (STATUS_<NODE>)
//   link.csv        t,direction,received,delivered,dropped_loss,dropped_queue,dropped_other,
//                   queue_depth,delay_p50_ms,delay_p99_ms,throughput_bps               LINK_STATS
//   rates.csv       channel,t,messages               messages per channel per second of log time
//   channels.csv    channel,type,messages,bytes,rate_hz
//   summary.csv     key,value                        the page's summary table
//   sections.csv    section,title,present,channels,missing,csv
// A section's CSV is written only when the log has its channels; sections.csv says which.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/logio/event_log.hpp"

namespace aerie::logtools {

struct ReportSection {
  std::string id;                     // "trajectory", "pilot", ...
  std::string title;                  // "Trajectory (top and side views)"
  std::vector<std::string> channels;  // the channels it draws on
  std::vector<std::string> missing;   // of those, the ones the log does not have
  bool present = false;               // the log has what the section needs
  std::vector<std::string> csv;       // the files written for it
};

struct ReportSummary {
  std::string log;
  int64_t events = 0;
  double duration_s = 0;                  // first to last event, log time
  std::optional<double> distance_m;       // path length of `distance_source`
  std::string distance_source;            // the most truthful trajectory: SIM_STATE, GT_POSE, NAV_STATE, VO_POSE
  std::string final_pilot_state;          // "" without PILOT_STATE
  std::optional<double> landing_error_m;  // horizontal, touchdown to pad centre (SIM_STATE, when landed)
  int64_t track_losses = 0;               // TRACK entering LOST
  int64_t pilot_losses = 0;               // PILOT_STATE losses at the end
  int64_t vo_lost = 0;                    // VO_POSE with status LOST
  int64_t vo_frames_skipped = 0;          // VO_POSE seq gaps (frames without a pose)
  std::optional<double> link_loss_pct;    // LINK_STATS, both directions, at the end: dropped / received
  int64_t undecodable = 0;                // messages of a report channel that did not decode as its type
};

struct ReportResult {
  ReportSummary summary;
  std::vector<ReportSection> sections;
  std::map<std::string, int64_t> rows;  // CSV file name -> data rows written
  std::vector<logio::Damage> damage;    // the log's damage (what came before it is reported)
};

// Reads `log_path` and writes the CSVs into `out_dir` (created; refused when it holds files,
// unless `force`). Throws std::runtime_error naming the log or the file that cannot be
// read or written. A damaged log is not an error: everything before the damage is reported,
// and the damage is in the result (and in summary.csv).
ReportResult write_report_data(const std::string& log_path, const std::string& out_dir, bool resync = false,
                               bool force = false);

// What running the plot script gave.
struct PlotRun {
  bool ok = false;
  std::string message;  // why not, in one line (python3 or matplotlib missing, the script failed)
};

// Runs `python` (e.g. /usr/bin/python3) on `script` (report_plots.py) over `out_dir`: the PNGs and
// index.html. First checks that python and matplotlib are there, so that the message says which is missing.
PlotRun run_report_plots(const std::string& python, const std::string& script, const std::string& out_dir);

// Where report_plots.py is: in the source tree aerie-log was built from (a compile definition), else
// <prefix>/share/aerie/ beside an installed <prefix>/bin/aerie-log; "" when neither exists.
std::string default_report_script();

}  // namespace aerie::logtools
