#pragma once
// The link study's open-loop workload: a recorded flight log replayed through the link in
// simulation time, the tracker on the side its placement names, scored on what reaches the
// operator on the ground. Each frame's TRACK box that arrives on the ground is compared with
// the log's GT_TRACK box of the same frame (the truth never crosses the link):
//   AUC            mean over IoU thresholds 0, 0.05, ..., 1 of the share of frames above it
//                  (the OTB success plot's area); a frame whose box never arrives counts as IoU 0;
//   centre error   mean pixel distance of the boxes that arrived;
//   frames lost    frames with the target visible for which no tracked box arrived.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "air/track/node/track_node.hpp"
#include "common/logio/event_log.hpp"
#include "tools/link/sim_link.hpp"

namespace aerie::linkstudy {

struct Box {
  double x0, y0, x1, y1;
};

// A recorded log, read once and shared (read-only) by the runs that replay it.
struct Recording {
  std::vector<logio::Event> events;  // by log time
  std::map<int64_t, Box> truth;      // visible GT_TRACK boxes by frame utime
  int64_t frames = 0;                // on the camera channel
};

// Reads an LCM log with the camera channel and GT_TRACK (e.g. aerie-bench-landing --log-dir);
// throws std::runtime_error naming the log when it cannot be read or has no camera frame.
std::shared_ptr<const Recording> load_recording(const std::string& path, const std::string& camera_channel,
                                                const std::string& gt_channel);

struct ReplayConfig {
  std::shared_ptr<const Recording> recording;
  track::NodeOptions track;        // its camera channel is replayed; init_from_gt initialises it on GT_TRACK
  std::optional<link::Split> split;
  link::SplitBus::Tap on_message;  // every message on each side, with its simulation time
};

struct ReplayResult {
  int64_t frames = 0, frames_visible = 0, frames_lost = 0;
  double auc = 0, mean_iou = 0, centre_error_px = -1;
  link::DirectionCounters down, up;
  double sim_s = 0;
};

ReplayResult replay(const ReplayConfig& config);

}  // namespace aerie::linkstudy
