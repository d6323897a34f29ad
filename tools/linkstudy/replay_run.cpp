#include "tools/linkstudy/replay_run.hpp"

#include <aerie/gt_box_t.hpp>
#include <aerie/track_t.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "common/bus/wire.hpp"
#include "common/logio/event_log.hpp"

namespace aerie::linkstudy {

namespace {

double iou(const Box& a, const Box& b) {
  const double w = std::max(0.0, std::min(a.x1, b.x1) - std::max(a.x0, b.x0));
  const double h = std::max(0.0, std::min(a.y1, b.y1) - std::max(a.y0, b.y0));
  const double inter = w * h, uni = (a.x1 - a.x0) * (a.y1 - a.y0) + (b.x1 - b.x0) * (b.y1 - b.y0) - inter;
  return uni > 0 ? inter / uni : 0;
}

}  // namespace

std::shared_ptr<const Recording> load_recording(const std::string& path, const std::string& camera_channel,
                                                const std::string& gt_channel) {
  logio::Reader reader(path, logio::Reader::Options{.resync = true});
  auto rec = std::make_shared<Recording>();
  for (logio::Event ev; reader.next(ev);) {
    if (ev.channel == gt_channel) {
      const auto g = bus::decode_bounded<aerie::gt_box_t>(ev.data.data(), ev.data.size());
      if (g.visible && g.width > 0 && g.height > 0) rec->truth[g.utime] = {g.x, g.y, g.x + g.width, g.y + g.height};
    }
    rec->frames += ev.channel == camera_channel;
    rec->events.push_back(std::move(ev));
  }
  if (rec->frames == 0) throw std::runtime_error(path + ": no frame on " + camera_channel + " to replay");
  std::stable_sort(rec->events.begin(), rec->events.end(), [](const auto& a, const auto& b) { return a.utime < b.utime; });
  return rec;
}

ReplayResult replay(const ReplayConfig& config) {
  const std::vector<logio::Event>& events = config.recording->events;
  const std::map<int64_t, Box>& truth = config.recording->truth;
  link::SplitBus buses(config.split);
  buses.tap(config.on_message);
  track::NodeOptions to = config.track;
  to.every_frame = true;  // lock-step: every frame delivered is tracked
  track::TrackNode track_node(buses.of("track"), to);

  ReplayResult r;
  r.frames = config.recording->frames;
  std::map<int64_t, Box> seen;  // tracked boxes that reached the ground, by frame utime
  int64_t now = 0;
  buses.on(link::Side::kGround).subscribe<aerie::track_t>(to.track_channel, [&](const aerie::track_t& m, const bus::ReceiveInfo&) {
    if (m.status != aerie::track_t::TRACKING && m.status != aerie::track_t::REDETECTED) return;
    seen.emplace(m.utime, Box{m.x - m.width / 2, m.y - m.height / 2, m.x + m.width / 2, m.y + m.height / 2});
  }, 100000);
  // What is not the tracker's output is replayed as recorded (its own outputs are left out).
  for (size_t i = 0; i < events.size();) {
    now = events[i].utime;
    for (; i < events.size() && events[i].utime == now; ++i)
      if (events[i].channel != to.track_channel && events[i].channel != to.pose_channel)
        buses.on(link::Side::kAir).publish_raw(events[i].channel, events[i].data.data(),
                                                 static_cast<unsigned>(events[i].data.size()));
    buses.settle(now, [&] { track_node.wait_idle(60000); });
  }
  // What is still on the way arrives (one frame period at a time).
  for (int k = 0; k < 2000 && buses.link() && buses.link()->next_event_us() >= 0; ++k) {
    now = std::max(now + 50000, buses.link()->next_event_us());
    buses.settle(now, [&] { track_node.wait_idle(60000); });
  }

  // Scores over the frames the target is visible in.
  std::vector<double> ious;
  double centre = 0;
  int64_t centred = 0;
  for (const auto& [utime, g] : truth) {
    const auto it = seen.find(utime);
    if (it == seen.end()) {
      ++r.frames_lost;
      ious.push_back(0);
      continue;
    }
    const Box& b = it->second;
    ious.push_back(iou(b, g));
    centre += std::hypot((b.x0 + b.x1 - g.x0 - g.x1) / 2, (b.y0 + b.y1 - g.y0 - g.y1) / 2);
    ++centred;
  }
  r.frames_visible = static_cast<int64_t>(truth.size());
  if (!ious.empty()) {
    for (int t = 0; t <= 20; ++t) {
      const double thr = t / 20.0;
      r.auc += static_cast<double>(std::count_if(ious.begin(), ious.end(), [&](double v) { return v > thr; })) /
               static_cast<double>(ious.size()) / 21.0;
    }
    for (double v : ious) r.mean_iou += v / static_cast<double>(ious.size());
  }
  if (centred) r.centre_error_px = centre / static_cast<double>(centred);
  r.down = buses.down_counters();
  r.up = buses.up_counters();
  r.sim_s = events.empty() ? 0 : static_cast<double>(events.back().utime - events.front().utime) * 1e-6;
  return r;
}

}  // namespace aerie::linkstudy
