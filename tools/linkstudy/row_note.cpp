// A RunRow as a study note (tools/study/note.hpp): every field, exactly, so that the rank that
// writes study.csv and report.md has the rows of runs flown elsewhere or before a --resume.
#include "tools/study/note.hpp"
#include "tools/linkstudy/study.hpp"

namespace aerie::linkstudy {

namespace {

void put(study::NoteWriter& n, const link::DirectionCounters& c) {
  n.integer(c.received).integer(c.delivered).integer(c.bytes_delivered).integer(c.dropped_loss).integer(c.dropped_queue);
  n.integer(c.dropped_other).integer(c.dropped_outage).integer(c.reencoded);
}

link::DirectionCounters get_counters(study::NoteReader& in) {
  link::DirectionCounters c;
  for (int64_t* v : {&c.received, &c.delivered, &c.bytes_delivered, &c.dropped_loss, &c.dropped_queue, &c.dropped_other,
                     &c.dropped_outage, &c.reencoded})
    *v = in.integer();
  return c;
}

}  // namespace

std::string row_note(const RunRow& r) {
  study::NoteWriter n;
  n.integer(r.success).integer(r.collision).text(r.metric).real(r.value);
  n.real(r.touchdown_error_m).real(r.yaw_error_deg).real(r.time_s).integer(r.losses).real(r.target_rmse_xy_m);
  n.real(r.heading_rmse_deg).real(r.auc).real(r.mean_iou).real(r.centre_error_px);
  n.integer(r.frames_visible).integer(r.frames_lost).integer(r.entered_danger);
  n.real(r.view_age_p50_ms).real(r.view_age_p95_ms).integer(r.view_messages);
  n.integer(r.pilot_stale_holds).integer(r.control_fallbacks);
  put(n, r.down);
  put(n, r.up);
  n.integer(static_cast<int64_t>(r.hops.size()));
  for (const auto& h : r.hops) {
    n.text(h.channel).text(h.direction).integer(h.latency_ms.count);
    for (double v : {h.latency_ms.min, h.latency_ms.mean, h.latency_ms.median, h.latency_ms.p90, h.latency_ms.p99, h.latency_ms.max})
      n.real(v);
    n.integer(h.sent).integer(h.delivered);
  }
  n.real(r.down_kbit_s).real(r.up_kbit_s).text(r.final_state);
  const auto& f = r.faults;
  n.integer(f.counters.kills).integer(f.counters.respawns).integer(f.counters.burst_messages).integer(f.counters.nan_messages);
  n.text(f.applied).integer(f.stalled_frames).integer(f.command_timeouts).integer(f.malformed);
  n.real(r.sim_s).real(r.wall_s);
  return n.str();
}

RunRow row_from_note(const std::string& note, const std::string& what) {
  study::NoteReader in(note, what);
  RunRow r;
  r.success = in.integer() != 0;
  r.collision = in.integer() != 0;
  r.metric = in.text();
  r.value = in.real();
  r.touchdown_error_m = in.real();
  r.yaw_error_deg = in.real();
  r.time_s = in.real();
  r.losses = static_cast<int>(in.integer());
  r.target_rmse_xy_m = in.real();
  r.heading_rmse_deg = in.real();
  r.auc = in.real();
  r.mean_iou = in.real();
  r.centre_error_px = in.real();
  r.frames_visible = in.integer();
  r.frames_lost = in.integer();
  r.entered_danger = in.integer() != 0;
  r.view_age_p50_ms = in.real();
  r.view_age_p95_ms = in.real();
  r.view_messages = in.integer();
  r.pilot_stale_holds = in.integer();
  r.control_fallbacks = in.integer();
  r.down = get_counters(in);
  r.up = get_counters(in);
  const int64_t hops = in.integer();
  for (int64_t k = 0; k < hops; ++k) {
    latency::LinkHop h;
    h.channel = in.text();
    h.direction = in.text();
    h.latency_ms.count = in.integer();
    for (double* v : {&h.latency_ms.min, &h.latency_ms.mean, &h.latency_ms.median, &h.latency_ms.p90, &h.latency_ms.p99,
                      &h.latency_ms.max})
      *v = in.real();
    h.sent = in.integer();
    h.delivered = in.integer();
    r.hops.push_back(std::move(h));
  }
  r.down_kbit_s = in.real();
  r.up_kbit_s = in.real();
  r.final_state = in.text();
  auto& f = r.faults;
  f.counters.kills = in.integer();
  f.counters.respawns = in.integer();
  f.counters.burst_messages = in.integer();
  f.counters.nan_messages = in.integer();
  f.applied = in.text();
  f.stalled_frames = in.integer();
  f.command_timeouts = in.integer();
  f.malformed = in.integer();
  r.sim_s = in.real();
  r.wall_s = in.real();
  in.end();
  return r;
}

}  // namespace aerie::linkstudy
