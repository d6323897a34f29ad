#pragma once
// The replay scenario of the harness (loop/harness.hpp, without a simulator): the link
// study's open-loop workload, a recorded flight log replayed through the link in simulation
// time, the tracker on the side its placement names, scored on what reaches the operator on
// the ground with the OTB metrics of air/track/eval. Each frame's TRACK box that arrives on
// the ground is compared with the log's GT_TRACK box of the same frame (the truth never
// crosses the link):
//   AUC            the OTB success plot's area (eval::score); a frame whose box never arrives counts as IoU 0;
//   centre error   mean pixel distance of the boxes that arrived;
//   frames lost    frames with the target visible for which no tracked box arrived.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/types.hpp>

#include "air/track/node/track_node.hpp"
#include "common/logio/event_log.hpp"
#include "loop/harness.hpp"

namespace aerie::loop::replay {

// A recorded log, read once and shared (read-only) by the runs that replay it.
struct Recording {
  std::vector<logio::Event> events;  // by log time
  std::map<int64_t, cv::Rect2d> truth;  // visible GT_TRACK boxes by frame utime
  int64_t frames = 0;                // on the camera channel
};

// Reads an LCM log with the camera channel and GT_TRACK (e.g. aerie-bench-landing --log-dir);
// throws std::runtime_error naming the log when it cannot be read or has no camera frame.
std::shared_ptr<const Recording> load_recording(const std::string& path, const std::string& camera_channel,
                                                const std::string& gt_channel);

// Wiring: the seed (load_replay_run gives it to the tracker), the split ("track" on the ground side) and the tap; no
// fault (a replay is open loop).
struct RunConfig : Wiring {
  std::shared_ptr<const Recording> recording;
  track::NodeOptions track;        // its camera channel is replayed; init_from_gt initialises it on GT_TRACK
};

// RunStats: the link's counters; sim_s the log's span.
struct RunResult : RunStats {
  int64_t frames = 0, frames_visible = 0, frames_lost = 0;
  double auc = 0, mean_iou = 0, centre_error_px = -1;
};

RunResult fly(const RunConfig& config);

// The replay of `recording` by the tracker `tracker` ("": the file's) of the aerie-track
// configuration `track_file`, with `seed`. Throws naming the file that cannot be read.
RunConfig load_replay_run(std::shared_ptr<const Recording> recording, const std::string& track_file,
                          const std::string& tracker, uint64_t seed);

}  // namespace aerie::loop::replay
