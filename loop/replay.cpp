#include "loop/replay.hpp"

#include <aerie/gt_box_t.hpp>
#include <aerie/track_t.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "air/track/eval/metrics.hpp"
#include "common/bus/wire.hpp"
#include "common/logio/event_log.hpp"
#include "common/util/config.hpp"

namespace aerie::loop::replay {

std::shared_ptr<const Recording> load_recording(const std::string& path, const std::string& camera_channel,
                                                const std::string& gt_channel) {
  logio::Reader reader(path, logio::Reader::Options{.resync = true});
  auto rec = std::make_shared<Recording>();
  for (logio::Event ev; reader.next(ev);) {
    if (ev.channel == gt_channel) {
      const auto g = bus::decode_bounded<aerie::gt_box_t>(ev.data.data(), ev.data.size());
      if (g.visible && g.width > 0 && g.height > 0) rec->truth[g.utime] = cv::Rect2d(g.x, g.y, g.width, g.height);
    }
    rec->frames += ev.channel == camera_channel;
    rec->events.push_back(std::move(ev));
  }
  if (rec->frames == 0) throw std::runtime_error(path + ": no frame on " + camera_channel + " to replay");
  std::stable_sort(rec->events.begin(), rec->events.end(), [](const auto& a, const auto& b) { return a.utime < b.utime; });
  return rec;
}

RunResult fly(const RunConfig& config) {
  const std::vector<logio::Event>& events = config.recording->events;
  const std::map<int64_t, cv::Rect2d>& truth = config.recording->truth;
  Harness harness(config, std::nullopt);
  link::SplitBus& buses = harness.buses();
  track::NodeOptions to = config.track;
  to.every_frame = true;  // lock-step: every frame delivered is tracked
  track::TrackNode track_node(harness.bus_of("track"), to);
  harness.wait_workers([&] { track_node.wait_idle(60000); });

  RunResult r;
  r.frames = config.recording->frames;
  std::map<int64_t, cv::Rect2d> seen;  // tracked boxes that reached the ground, by frame utime
  int64_t now = 0;
  buses.on(link::Side::kGround).subscribe<aerie::track_t>(to.track_channel, [&](const aerie::track_t& m, const bus::ReceiveInfo&) {
    if (m.status != aerie::track_t::TRACKING && m.status != aerie::track_t::REDETECTED) return;
    seen.emplace(m.utime, cv::Rect2d(m.x - m.width / 2, m.y - m.height / 2, m.width, m.height));
  }, 100000);
  // What is not the tracker's output is replayed as recorded (its own outputs are left out).
  for (size_t i = 0; i < events.size();) {
    now = events[i].utime;
    for (; i < events.size() && events[i].utime == now; ++i)
      if (events[i].channel != to.track_channel && events[i].channel != to.pose_channel)
        harness.air().publish_raw(events[i].channel, events[i].data.data(), static_cast<unsigned>(events[i].data.size()));
    harness.settle(now);
  }
  // What is still on the way arrives (one frame period at a time).
  for (int k = 0; k < 2000 && buses.link() && buses.link()->next_event_us() >= 0; ++k) {
    now = std::max(now + 50000, buses.link()->next_event_us());
    harness.settle(now);
  }

  // Scores over the frames the target is visible in (a box that never arrived: no box, IoU 0).
  std::vector<cv::Rect2d> predicted, groundtruth;
  double centre = 0, iou_sum = 0;
  int64_t centred = 0;
  for (const auto& [utime, g] : truth) {
    const auto it = seen.find(utime);
    groundtruth.push_back(g);
    predicted.push_back(it == seen.end() ? cv::Rect2d() : it->second);
    if (it == seen.end()) {
      ++r.frames_lost;
      continue;
    }
    iou_sum += track::eval::iou(it->second, g);
    centre += track::eval::centre_error(it->second, g);
    ++centred;
  }
  r.frames_visible = static_cast<int64_t>(truth.size());
  if (!truth.empty()) {
    r.auc = track::eval::score(predicted, groundtruth).auc;
    r.mean_iou = iou_sum / static_cast<double>(truth.size());
  }
  if (centred) r.centre_error_px = centre / static_cast<double>(centred);
  static_cast<RunStats&>(r) = harness.finish();
  r.sim_s = events.empty() ? 0 : static_cast<double>(events.back().utime - events.front().utime) * 1e-6;
  return r;
}

RunConfig load_replay_run(std::shared_ptr<const Recording> recording, const std::string& track_file,
                          const std::string& tracker, uint64_t seed) {
  RunConfig rc;
  rc.seed = seed;
  rc.recording = std::move(recording);
  rc.track = track::node_options(util::Config::load(track_file));
  if (!tracker.empty()) rc.track.tracker = tracker;
  rc.track.seed = seed;
  return rc;
}

}  // namespace aerie::loop::replay
