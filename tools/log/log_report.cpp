#include "tools/log/log_report.hpp"

#include <aerie/gt_pose_t.hpp>
#include <aerie/link_stats_t.hpp>
#include <aerie/nav_state_t.hpp>
#include <aerie/octomap_t.hpp>
#include <aerie/pilot_state_t.hpp>
#include <aerie/pose_t.hpp>
#include <aerie/process_status_t.hpp>
#include <aerie/sim_state_t.hpp>
#include <aerie/track_t.hpp>
#include <sys/wait.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>

#include "common/bus/wire.hpp"
#ifdef AERIE_REPORT_MAP
#include "ground/map/octomap_message.hpp"  // the ground side only: the air-only build has no OctoMap
#endif
#include "tools/eval/metrics.hpp"
#include "tools/latency/latency.hpp"
#include "tools/log/type_registry.hpp"

namespace aerie::logtools {
namespace fs = std::filesystem;
namespace {

constexpr const char* kVoPose = "VO_POSE";
constexpr const char* kNavState = "NAV_STATE";
constexpr const char* kSimState = "SIM_STATE";
constexpr const char* kGtPose = "GT_POSE";
constexpr const char* kPilotState = "PILOT_STATE";
constexpr const char* kTrack = "TRACK";
constexpr const char* kStatusVo = "STATUS_VO";
constexpr const char* kLinkStats = "LINK_STATS";
constexpr const char* kMapOctomap = "MAP_OCTOMAP";
// NAV_STATE runs at the IMU rate, truth at the frame rate: a pair is at most this far apart.
constexpr int64_t kNavPairUs = 50'000;

// RFC 4180: a field with a comma, quote or line break is quoted, quotes doubled.
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string num(double v) {
  if (!std::isfinite(v)) return "nan";
  char b[32];
  std::snprintf(b, sizeof b, "%.9g", v);
  return b;
}

// One CSV file: the header at creation, rows counted.
class Csv {
 public:
  Csv(const fs::path& path, const std::string& header) : path_(path), out_(path) {
    if (!out_) throw std::runtime_error(path.string() + ": cannot create file");
    out_ << header << "\n";
  }
  template <typename... T>
  void row(const T&... fields) {
    bool first = true;
    ((out_ << (first ? "" : ",") << fields, first = false), ...);
    out_ << "\n";
    ++rows_;
  }
  int64_t rows() const { return rows_; }
  void close() {
    out_.close();
    if (!out_) throw std::runtime_error(path_.string() + ": write failed");
  }
  std::string name() const { return path_.filename().string(); }

 private:
  fs::path path_;
  std::ofstream out_;
  int64_t rows_ = 0;
};

struct Sample {
  int64_t utime;
  Eigen::Vector3d p;
  int status = 0;
  double t = 0;
};

struct ChannelStats {
  std::string type;
  int64_t messages = 0, bytes = 0;
  double first_t = 0, last_t = 0;
  std::map<int64_t, int64_t> per_second;
};

double path_length(const std::vector<Sample>& s) {
  double d = 0;
  for (size_t i = 1; i < s.size(); ++i) d += (s[i].p - s[i - 1].p).norm();
  return d;
}

// Everything gathered in the one pass over the log; the CSVs that need the whole log (the
// trajectories, the NAV pairing, the map) are written at the end.
class Collector {
 public:
  explicit Collector(const fs::path& dir) : dir_(dir) {}

  void add(const logio::Event& ev) {
    if (events_ == 0) first_utime_ = ev.utime;
    last_utime_ = ev.utime;
    ++events_;
    const double t = static_cast<double>(ev.utime - first_utime_) * 1e-6;
    const uint8_t* d = ev.data.data();
    const size_t n = ev.data.size();
    ChannelStats& cs = channels_[ev.channel];
    if (cs.messages == 0) {
      const int64_t fp = fingerprint_of(d, n);
      cs.type = type_name(find_type(fp), fp, ev.channel);
      cs.first_t = t;
    }
    ++cs.messages;
    cs.bytes += static_cast<int64_t>(n);
    cs.last_t = t;
    ++cs.per_second[static_cast<int64_t>(std::floor(t))];
    latency_.add(ev.channel, ev.utime, d, n);

    const std::string& ch = ev.channel;
    if (ch == kVoPose) {
      aerie::pose_t m;
      if (!decode(ev, m)) return;
      traj_[ch].push_back({m.utime, {m.position[0], m.position[1], m.position[2]}, m.status, t});
      vo().row(num(t), m.utime, m.seq, int(m.status), m.inliers, m.features_2d, m.features_3d, int(m.keyframe));
      if (m.status == aerie::pose_t::LOST) ++summary_.vo_lost;
      if (last_vo_seq_ && m.seq > *last_vo_seq_ + 1) summary_.vo_frames_skipped += m.seq - *last_vo_seq_ - 1;
      last_vo_seq_ = m.seq;
    } else if (ch == kNavState) {
      aerie::nav_state_t m;
      if (!decode(ev, m)) return;
      traj_[ch].push_back({m.utime, {m.position[0], m.position[1], m.position[2]}, m.status, t});
    } else if (ch == kSimState) {
      aerie::sim_state_t m;
      if (!decode(ev, m)) return;
      traj_[ch].push_back({m.utime, {m.position[0], m.position[1], m.position[2]}, m.contact, t});
      pad_ = Eigen::Vector4d(m.target_position[0], m.target_position[1], m.target_position[2], m.target_yaw_deg);
      if (m.contact == aerie::sim_state_t::LANDED) {
        const Eigen::Vector2d e(m.touchdown_position[0] - m.target_position[0],
                                m.touchdown_position[1] - m.target_position[1]);
        summary_.landing_error_m = e.norm();  // as the flight simulator scores it (horizontal)
      }
    } else if (ch == kGtPose) {
      aerie::gt_pose_t m;
      if (!decode(ev, m)) return;
      traj_[ch].push_back({m.utime, {m.position[0], m.position[1], m.position[2]}, 0, t});
    } else if (ch == kPilotState) {
      aerie::pilot_state_t m;
      if (!decode(ev, m)) return;
      pilot().row(num(t), m.utime, int(m.state), csv_field(m.state_name), csv_field(m.reason), num(m.height_m),
                  m.losses, m.reacquisitions);
      summary_.final_pilot_state = m.state_name;
      summary_.pilot_losses = m.losses;
    } else if (ch == kTrack) {
      aerie::track_t m;
      if (!decode(ev, m)) return;
      track().row(num(t), m.utime, m.seq, csv_field(m.tracker), int(m.status), num(m.confidence), num(m.x), num(m.y),
                  num(m.width), num(m.height), m.frames_skipped, num(m.processing_ms));
      if (m.status == aerie::track_t::LOST && last_track_status_ != aerie::track_t::LOST) ++summary_.track_losses;
      last_track_status_ = m.status;
    } else if (ch == kStatusVo) {
      aerie::process_status_t m;
      if (!decode(ev, m)) return;
      for (int i = 0; i < m.ncounters; ++i)
        vo_status().row(num(t), csv_field(m.counter_names[static_cast<size_t>(i)]),
                        m.counter_values[static_cast<size_t>(i)]);
    } else if (ch == kLinkStats) {
      aerie::link_stats_t m;
      if (!decode(ev, m)) return;
      for (const auto& dir : m.directions) {
        link().row(num(t), csv_field(dir.name), dir.received, dir.delivered, dir.dropped_loss, dir.dropped_queue,
                   dir.dropped_other, dir.queue_depth, num(dir.delay_p50_ms), num(dir.delay_p99_ms),
                   num(dir.throughput_bps));
        link_last_[dir.name] = {dir.received, dir.dropped_loss + dir.dropped_queue + dir.dropped_other};
      }
    } else if (ch == kMapOctomap) {
      aerie::octomap_t m;
      if (!decode(ev, m)) return;
      if (m.full || !map_full_) {
        map_ = ev.data;
        map_full_ = m.full;
      }
    }
  }

  ReportResult finish(const std::string& log_path) {
    ReportResult r;
    summary_.log = log_path;
    summary_.events = events_;
    summary_.duration_s = events_ ? static_cast<double>(last_utime_ - first_utime_) * 1e-6 : 0.0;
    for (const char* src : {kSimState, kGtPose, kNavState, kVoPose}) {
      auto it = traj_.find(src);
      if (it == traj_.end() || it->second.empty()) continue;
      summary_.distance_m = path_length(it->second);
      summary_.distance_source = src;
      break;
    }
    if (!link_last_.empty()) {
      int64_t received = 0, dropped = 0;
      for (const auto& [name, rd] : link_last_) {
        received += rd.first;
        dropped += rd.second;
      }
      if (received > 0) summary_.link_loss_pct = 100.0 * static_cast<double>(dropped) / static_cast<double>(received);
    }
    summary_.undecodable = undecodable_;

    if (!traj_.empty()) {
      Csv& c = open("trajectory", "channel,t,utime,x,y,z");
      for (const auto& [ch, samples] : traj_)
        for (const auto& s : samples) c.row(ch, num(s.t), s.utime, num(s.p.x()), num(s.p.y()), num(s.p.z()));
    }
    if (pad_) {
      Csv& c = open("pad", "x,y,z,yaw_deg");
      c.row(num((*pad_)[0]), num((*pad_)[1]), num((*pad_)[2]), num((*pad_)[3]));
    }
    write_map();
    write_nav_error();
    write_latency();
    write_rates();

    for (auto& [name, c] : csv_) {
      c->close();
      r.rows[c->name()] = c->rows();
    }
    r.summary = summary_;
    r.sections = sections();
    write_summary(r);
    write_sections(r.sections);
    return r;
  }

  void set_damage(std::vector<logio::Damage> d) { damage_ = std::move(d); }

 private:
  template <typename Msg>
  bool decode(const logio::Event& ev, Msg& m) {
    if (bus::decode_bounded(ev.data.data(), ev.data.size(), m)) return true;
    ++undecodable_;
    return false;
  }

  Csv& open(const std::string& stem, const std::string& header) {
    auto& slot = csv_[stem];
    if (!slot) slot = std::make_unique<Csv>(dir_ / (stem + ".csv"), header);
    return *slot;
  }
  Csv& vo() { return open("vo", "t,utime,seq,status,inliers,features_2d,features_3d,keyframe"); }
  Csv& pilot() { return open("pilot", "t,utime,state,state_name,reason,height_m,losses,reacquisitions"); }
  Csv& track() {
    return open("track", "t,utime,seq,tracker,status,confidence,x,y,width,height,frames_skipped,processing_ms");
  }
  Csv& vo_status() { return open("vo_status", "t,counter,value"); }
  Csv& link() {
    return open("link", "t,direction,received,delivered,dropped_loss,dropped_queue,dropped_other,queue_depth,"
                        "delay_p50_ms,delay_p99_ms,throughput_bps");
  }

  // The occupied voxels of the last full map (or of the last message when none was full).
  void write_map() {
    if (map_.empty()) return;
#ifndef AERIE_REPORT_MAP
    notes_.push_back(std::string(kMapOctomap) + ": not drawn (this aerie-log is an air-only build, without OctoMap)");
#else
    aerie::octomap_t m;
    if (!bus::decode_bounded(map_.data(), map_.size(), m)) return;
    std::unique_ptr<octomap::OcTree> tree;
    try {
      tree = map::decode_octree(m);
    } catch (const std::invalid_argument& e) {
      notes_.push_back(std::string(kMapOctomap) + ": " + e.what());
      return;
    }
    Csv& c = open("map", "x,y,z,size");
    for (auto it = tree->begin_leafs(), end = tree->end_leafs(); it != end; ++it)
      if (tree->isNodeOccupied(*it)) c.row(num(it.getX()), num(it.getY()), num(it.getZ()), num(it.getSize()));
#endif
  }

  // NAV_STATE against the truth (SIM_STATE's body origin, else GT_POSE's camera): for each truth
  // sample the NAV_STATE nearest in message time, raw (NAV's world against the truth's) and after
  // the least-squares SE(3) alignment of all the pairs (Umeyama, as aerie-eval-traj aligns).
  void write_nav_error() {
    auto nav = traj_.find(kNavState);
    if (nav == traj_.end() || nav->second.empty()) return;
    auto truth = traj_.find(kSimState);
    if (truth == traj_.end()) truth = traj_.find(kGtPose);
    if (truth == traj_.end()) return;
    std::vector<Sample> n = nav->second;
    std::sort(n.begin(), n.end(), [](const Sample& a, const Sample& b) { return a.utime < b.utime; });
    std::vector<std::pair<const Sample*, const Sample*>> pairs;  // (truth, nav)
    for (const auto& g : truth->second) {
      auto it = std::lower_bound(n.begin(), n.end(), g.utime, [](const Sample& s, int64_t u) { return s.utime < u; });
      const Sample* best = nullptr;
      if (it != n.end()) best = &*it;
      if (it != n.begin() && (!best || g.utime - std::prev(it)->utime < best->utime - g.utime)) best = &*std::prev(it);
      if (best && std::llabs(best->utime - g.utime) <= kNavPairUs) pairs.push_back({&g, best});
    }
    std::vector<Eigen::Vector3d> est, ref;
    for (const auto& [g, e] : pairs) {
      est.push_back(e->p);
      ref.push_back(g->p);
    }
    std::optional<eval::Similarity> align;
    if (pairs.size() >= 3) align = eval::umeyama(est, ref, false);
    Csv& c = open("nav_error", "t,utime,status,nav_x,nav_y,nav_z,truth_x,truth_y,truth_z,error_m,aligned_error_m");
    for (size_t i = 0; i < pairs.size(); ++i) {
      const auto& [g, e] = pairs[i];
      const double aligned = align ? (align->apply(e->p) - g->p).norm() : std::nan("");
      c.row(num(g->t), g->utime, e->status, num(e->p.x()), num(e->p.y()), num(e->p.z()), num(g->p.x()), num(g->p.y()),
            num(g->p.z()), num((e->p - g->p).norm()), num(aligned));
    }
    nav_truth_ = truth->first;
  }

  // tools/latency's own analysis and CSV (the same table aerie-latency --csv writes).
  void write_latency() {
    const auto channels = latency_.channels();
    const auto hops = latency_.hops();
    bool any = !hops.empty();
    for (const auto& c : channels) any |= c.latency_ms.count > 0;
    if (!any) return;
    const std::string text = latency::to_csv(channels, hops);
    const fs::path p = dir_ / "latency.csv";
    std::ofstream f(p);
    if (!(f << text)) throw std::runtime_error(p.string() + ": cannot write");
    int64_t lines = 0;
    for (char ch : text) lines += ch == '\n';
    latency_rows_ = lines - 1;  // its header
  }

  void write_rates() {
    if (channels_.empty()) return;
    Csv& rates = open("rates", "channel,t,messages");
    Csv& list = open("channels", "channel,type,messages,bytes,rate_hz");
    for (const auto& [ch, s] : channels_) {
      for (const auto& [sec, count] : s.per_second) rates.row(csv_field(ch), sec, count);
      const double span = s.last_t - s.first_t;
      list.row(csv_field(ch), csv_field(s.type), s.messages, s.bytes,
               num(s.messages > 1 && span > 0 ? static_cast<double>(s.messages - 1) / span : std::nan("")));
    }
  }

  bool has(const std::string& ch) const { return channels_.count(ch) != 0; }

  std::vector<ReportSection> sections() const {
    std::vector<ReportSection> out;
    // present: `any` of the channels (all of `all` too); missing: those of both the log lacks.
    auto add = [&](std::string id, std::string title, std::vector<std::string> any, std::vector<std::string> all,
                   std::vector<std::string> files) {
      ReportSection s;
      s.id = std::move(id);
      s.title = std::move(title);
      bool one = any.empty();
      for (const auto& c : any) one |= has(c);
      bool every = true;
      for (const auto& c : all) every &= has(c);
      s.present = one && every;
      for (auto* list : {&any, &all})
        for (const auto& c : *list) {
          s.channels.push_back(c);
          if (!has(c)) s.missing.push_back(c);
        }
      if (s.present)
        for (const auto& f : files)
          if (fs::exists(dir_ / f)) s.csv.push_back(f);
      s.present = s.present && !s.csv.empty();
      out.push_back(std::move(s));
    };
    add("trajectory", "Trajectory over the map (top and side views)", {kVoPose, kNavState, kSimState, kGtPose}, {},
        {"trajectory.csv", "map.csv", "pad.csv"});
    add("pilot", "Pilot states", {kPilotState}, {}, {"pilot.csv"});
    add("track", "Tracker confidence and losses", {kTrack}, {}, {"track.csv"});
    add("vo", "VO inliers and skips", {kVoPose, kStatusVo}, {}, {"vo.csv", "vo_status.csv"});
    add("nav_error", "NAV_STATE against ground truth", {kSimState, kGtPose}, {kNavState}, {"nav_error.csv"});
    // Latency is read from every stamped channel and the STATUS_<NODE> heartbeats.
    add("latency", "Latency per channel and per hop", {}, {}, {"latency.csv"});
    add("link", "Link statistics", {kLinkStats}, {}, {"link.csv"});
    add("rates", "Message rates per channel", {}, {}, {"rates.csv", "channels.csv"});
    return out;
  }

  void write_summary(const ReportResult& r) {
    const ReportSummary& s = r.summary;
    Csv c(dir_ / "summary.csv", "key,value");
    auto opt = [](const std::optional<double>& v) { return v ? num(*v) : std::string(); };
    c.row("log", csv_field(s.log));
    c.row("events", s.events);
    c.row("duration_s", num(s.duration_s));
    c.row("distance_m", opt(s.distance_m));
    c.row("distance_source", s.distance_source);
    c.row("final_pilot_state", csv_field(s.final_pilot_state));
    c.row("landing_error_m", opt(s.landing_error_m));
    c.row("track_losses", s.track_losses);
    c.row("pilot_losses", s.pilot_losses);
    c.row("vo_lost", s.vo_lost);
    c.row("vo_frames_skipped", s.vo_frames_skipped);
    c.row("link_loss_pct", opt(s.link_loss_pct));
    c.row("undecodable", s.undecodable);
    c.row("nav_truth", nav_truth_);
    for (const auto& d : damage_) c.row("damage", csv_field(d.message));
    for (const auto& n : notes_) c.row("note", csv_field(n));
    c.close();
  }

  void write_sections(const std::vector<ReportSection>& secs) {
    Csv c(dir_ / "sections.csv", "section,title,present,channels,missing,csv");
    auto join = [](const std::vector<std::string>& v) {
      std::string s;
      for (const auto& x : v) s += (s.empty() ? "" : " ") + x;
      return s;
    };
    for (const auto& s : secs)
      c.row(s.id, csv_field(s.title), int(s.present), join(s.channels), join(s.missing), join(s.csv));
    c.close();
  }

 public:
  int64_t latency_rows() const { return latency_rows_; }

 private:
  fs::path dir_;
  int64_t events_ = 0, first_utime_ = 0, last_utime_ = 0, undecodable_ = 0, latency_rows_ = 0;
  std::map<std::string, ChannelStats> channels_;
  std::map<std::string, std::vector<Sample>> traj_;
  std::map<std::string, std::unique_ptr<Csv>> csv_;
  std::map<std::string, std::pair<int64_t, int64_t>> link_last_;  // direction -> (received, dropped)
  std::optional<Eigen::Vector4d> pad_;
  std::optional<int64_t> last_vo_seq_;
  int last_track_status_ = -1;
  std::vector<uint8_t> map_;
  bool map_full_ = false;
  std::string nav_truth_;
  std::vector<std::string> notes_;
  std::vector<logio::Damage> damage_;
  latency::LatencyAnalysis latency_;
  ReportSummary summary_;
};

}  // namespace

ReportResult write_report_data(const std::string& log_path, const std::string& out_dir, bool resync, bool force) {
  logio::Reader reader(log_path, logio::Reader::Options{resync});
  const fs::path dir(out_dir);
  if (fs::exists(dir) && !fs::is_directory(dir)) throw std::runtime_error(out_dir + ": exists and is not a folder");
  if (fs::exists(dir) && !fs::is_empty(dir) && !force)
    throw std::runtime_error(out_dir + ": folder is not empty (use --force to overwrite the report in it)");
  fs::create_directories(dir);
  Collector c(dir);
  logio::Event ev;
  while (reader.next(ev)) c.add(ev);
  c.set_damage(reader.damage());
  ReportResult r = c.finish(log_path);
  if (c.latency_rows()) r.rows["latency.csv"] = c.latency_rows();
  r.damage = reader.damage();
  return r;
}

namespace {
// Runs a command through the shell: its exit status, -1 when it did not exit normally.
int run(const std::string& cmd) {
  const int st = std::system(cmd.c_str());
  return st != -1 && WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}
std::string quoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}
}  // namespace

PlotRun run_report_plots(const std::string& python, const std::string& script, const std::string& out_dir) {
  if (script.empty() || !fs::exists(script))
    return {false, "plot script not found (" + (script.empty() ? std::string("none given") : script) +
                       "): the CSVs are written, no PNGs and no index.html"};
  if (run(quoted(python) + " -c '' >/dev/null 2>&1") != 0)
    return {false, python + " not found: the CSVs are written, no PNGs and no index.html (apt-get install python3)"};
  if (run(quoted(python) + " -c 'import numpy, matplotlib' >/dev/null 2>&1") != 0)
    return {false, python + " has no numpy/matplotlib: the CSVs are written, no PNGs and no index.html "
                            "(apt-get install python3-numpy python3-matplotlib)"};
  const std::string cmd = quoted(python) + " " + quoted(script) + " " + quoted(out_dir);
  if (run(cmd) != 0) return {false, "the plot script failed (" + cmd + "): the CSVs are written"};
  if (!fs::exists(fs::path(out_dir) / "index.html"))
    return {false, "the plot script wrote no index.html (" + cmd + "): the CSVs are written"};
  return {true, ""};
}

std::string default_report_script() {
#ifdef AERIE_REPORT_PLOTS_SCRIPT
  if (fs::exists(AERIE_REPORT_PLOTS_SCRIPT)) return AERIE_REPORT_PLOTS_SCRIPT;
#endif
  // An installed aerie-log: <prefix>/bin/aerie-log and <prefix>/share/aerie/report_plots.py.
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = exe.parent_path().parent_path() / "share" / "aerie" / "report_plots.py";
    if (fs::exists(installed)) return installed.string();
  }
  return "";
}

}  // namespace aerie::logtools
