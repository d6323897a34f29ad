// aerie-log report (issue 49 item 7): a log written here with a few messages of each kind gives
// the CSVs with their exact row counts, the summary (distance, final state, landing error,
// losses, skips) and a page naming the sections present and the missing ones; a log with one
// channel still gives a page; a truncated log is reported as damaged with what came before;
// a short closed-loop landing (the demo's nodes, lock-step) gets its report too.
#include <gtest/gtest.h>

#include <aerie/gt_pose_t.hpp>
#include <aerie/nav_state_t.hpp>
#include <aerie/octomap_t.hpp>
#include <aerie/pilot_state_t.hpp>
#include <aerie/pose_t.hpp>
#include <aerie/process_status_t.hpp>
#include <aerie/sim_state_t.hpp>
#include <aerie/track_t.hpp>
#include <sys/wait.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "air/pilot/pilot_config.hpp"
#include "common/logio/event_log.hpp"
#include "common/sim/flight/flight_config.hpp"
#include "ground/map/octomap_message.hpp"
#include "tests/support/test_support.hpp"
#include "loop/landing.hpp"
#include "tools/log/log_report.hpp"

namespace aerie::logtools {
namespace {
namespace fs = std::filesystem;

constexpr int64_t kT0 = 1'700'000'000'000'000;  // log and message time of the first frame (µs)
constexpr int64_t kFrameUs = 250'000;

template <typename Msg>
std::vector<uint8_t> encode(const Msg& m) {
  std::vector<uint8_t> buf(static_cast<size_t>(m.getEncodedSize()));
  m.encode(buf.data(), 0, static_cast<int>(buf.size()));
  return buf;
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// The data rows of a CSV (lines after the header).
int64_t data_rows(const fs::path& p) {
  std::ifstream f(p);
  std::string line;
  int64_t n = -1;
  while (std::getline(f, line)) ++n;
  return n;
}

std::map<std::string, std::string> summary(const fs::path& dir) {
  std::map<std::string, std::string> out;
  std::ifstream f(dir / "summary.csv");
  std::string line;
  std::getline(f, line);
  while (std::getline(f, line)) {
    const auto comma = line.find(',');
    out[line.substr(0, comma)] = line.substr(comma + 1);
  }
  return out;
}

// The truth of frame i: a curve (not a line, so that the NAV alignment is unique).
Eigen::Vector3d truth(int i) { return {0.5 * i, std::sin(0.4 * i), 1.0 + 0.1 * i * i}; }

class LogWriter {
 public:
  explicit LogWriter(const fs::path& p) : w_(p.string()) {}
  template <typename Msg>
  void put(int64_t t, const std::string& ch, const Msg& m) {
    const auto b = encode(m);
    w_.write(t, ch, b.data(), b.size());
    times_[ch].push_back(t);
  }
  void close() { w_.close(); }
  std::map<std::string, std::vector<int64_t>> times_;  // log times per channel

 private:
  logio::Writer w_;
};

// 10 frames, every 0.25 s: VO_POSE (frame 4 skipped, frame 7 LOST), NAV_STATE twice a frame
// (the truth + 1 m in x), SIM_STATE (landed at the end, 0.1, 0.2 m from the pad), GT_POSE,
// PILOT_STATE every other frame, TRACK on 8 frames (lost twice), STATUS_VO twice (two counters
// and a hop), one full MAP_OCTOMAP with three occupied voxels. No LINK_STATS.
std::map<std::string, std::vector<int64_t>> write_flight(const fs::path& path) {
  LogWriter w(path);
  const int track_status[8] = {1, 1, 2, 2, 1, 2, 1, 3};
  const char* pilot_states[5] = {"TAKEOFF", "SURVEY", "ACQUIRE", "APPROACH", "LANDED"};
  for (int i = 0; i < 10; ++i) {
    const int64_t t = kT0 + i * kFrameUs;
    const Eigen::Vector3d p = truth(i);
    for (int half = 0; half < 2; ++half) {  // at the frame (paired with SIM_STATE) and between frames
      aerie::nav_state_t n{};
      n.utime = t + half * kFrameUs / 2;
      n.seq = 2 * i + half;
      n.status = aerie::nav_state_t::OK;
      const Eigen::Vector3d q = (half ? 0.5 * (p + truth(i + 1)) : p) + Eigen::Vector3d(1, 0, 0);
      for (int k = 0; k < 3; ++k) n.position[k] = q[k];
      n.orientation[0] = 1;
      w.put(n.utime + 1000, "NAV_STATE", n);
    }
    aerie::sim_state_t s{};
    s.utime = t;
    s.seq = i;
    s.world = "room";
    for (int k = 0; k < 3; ++k) s.position[k] = p[k];
    s.contact = i == 9 ? aerie::sim_state_t::LANDED : aerie::sim_state_t::AIRBORNE;
    s.touchdown_position[0] = 2.1;
    s.touchdown_position[1] = 3.2;
    s.target_position[0] = 2.0;
    s.target_position[1] = 3.0;
    w.put(t + 2000, "SIM_STATE", s);
    aerie::gt_pose_t g{};
    g.utime = t;
    g.seq = i;
    g.frame_id = "sim";
    for (int k = 0; k < 3; ++k) g.position[k] = p[k];
    g.orientation[0] = 1;
    w.put(t + 2000, "GT_POSE", g);
    if (i != 4) {
      aerie::pose_t v{};
      v.utime = t;
      v.seq = i;
      v.orientation[0] = 1;
      v.inliers = 100 + i;
      v.features_3d = 150;
      v.status = i == 7 ? aerie::pose_t::LOST : aerie::pose_t::OK;
      w.put(t + 30'000, "VO_POSE", v);
    }
    if (i % 2 == 0) {
      aerie::pilot_state_t ps{};
      ps.utime = t;
      ps.seq = i / 2;
      ps.state = static_cast<int8_t>(i / 2 == 4 ? aerie::pilot_state_t::LANDED : 1 + i / 2);
      ps.state_name = pilot_states[i / 2];
      ps.reason = "reason, with a comma";
      ps.height_m = 5 - i * 0.5;
      ps.losses = 2;
      ps.controller = "fuzzy";
      w.put(t + 5000, "PILOT_STATE", ps);
    }
    if (i < 8) {
      aerie::track_t tr{};
      tr.utime = t;
      tr.seq = i;
      tr.tracker = "amcmr-ct";
      tr.camera = "CAM_DOWN";
      tr.status = static_cast<int8_t>(track_status[i]);
      tr.confidence = 0.1f * static_cast<float>(i);
      w.put(t + 40'000, "TRACK", tr);
    }
    if (i == 3 || i == 8) {
      aerie::process_status_t st{};
      st.utime = t + 50'000;
      st.node = "vo";
      st.ncounters = 2;
      st.counter_names = {"frames_skipped", "refused_pairs"};
      st.counter_values = {i, 0};
      st.last_source_utime = t;
      st.last_receive_utime = t + 10'000;
      st.last_publish_utime = t + 25'000;
      w.put(t + 50'000, "STATUS_VO", st);
    }
  }
  octomap::OcTree tree(0.1);
  for (const auto& p : {octomap::point3d(1.05, 0.05, 0.05), octomap::point3d(-2.05, 1.05, 0.55),
                        octomap::point3d(0.35, -3.05, 2.05)})
    tree.updateNode(p, true);
  aerie::octomap_t m{};
  m.utime = kT0 + 9 * kFrameUs;
  m.full = true;
  map::encode_octree(tree, true, m);
  w.put(kT0 + 9 * kFrameUs + 60'000, "MAP_OCTOMAP", m);
  w.close();
  return w.times_;
}

bool have_matplotlib() { return std::system("/usr/bin/python3 -c 'import numpy, matplotlib' >/dev/null 2>&1") == 0; }

// rates.csv's rows: per channel, the seconds since the log's first event that have a message.
int64_t rate_rows(const std::map<std::string, std::vector<int64_t>>& times) {
  int64_t first = INT64_MAX;
  for (const auto& [ch, ts] : times)
    for (int64_t t : ts) first = std::min(first, t);
  int64_t n = 0;
  for (const auto& [ch, ts] : times) {
    std::set<int64_t> secs;
    for (int64_t t : ts) secs.insert((t - first) / 1'000'000);
    n += static_cast<int64_t>(secs.size());
  }
  return n;
}

TEST(LogReport, AFlightGivesEveryCsvWithExactRowsAndAPageNamingTheSections) {
  const fs::path dir = test::scratch_dir("report");
  const fs::path log = dir / "flight.lcm";
  const auto times = write_flight(log);
  const fs::path out = dir / "report";
  const ReportResult r = write_report_data(log.string(), out.string());
  EXPECT_TRUE(r.damage.empty());

  const std::map<std::string, int64_t> expected{
      {"trajectory.csv", 9 + 20 + 10 + 10},  // VO_POSE, NAV_STATE, SIM_STATE, GT_POSE
      {"map.csv", 3},
      {"pad.csv", 1},
      {"pilot.csv", 5},
      {"track.csv", 8},
      {"vo.csv", 9},
      {"vo_status.csv", 4},
      {"nav_error.csv", 10},   // one pair per SIM_STATE frame
      {"latency.csv", 8 + 3},  // 8 channels, the vo hop's input, processing and age
      {"rates.csv", rate_rows(times)},
      {"channels.csv", 8},
  };
  EXPECT_EQ(r.rows, expected);
  for (const auto& [file, n] : expected) EXPECT_EQ(data_rows(out / file), n) << file;
  EXPECT_FALSE(fs::exists(out / "link.csv"));

  // NAV_STATE is the truth + 1 m in x: 1 m in its own world, 0 once aligned.
  std::ifstream ne(out / "nav_error.csv");
  std::string line;
  std::getline(ne, line);
  EXPECT_EQ(line, "t,utime,status,nav_x,nav_y,nav_z,truth_x,truth_y,truth_z,error_m,aligned_error_m");
  while (std::getline(ne, line)) {
    std::stringstream s(line);
    std::vector<double> v;
    for (std::string f; std::getline(s, f, ',');) v.push_back(std::stod(f));
    ASSERT_EQ(v.size(), 11u) << line;
    EXPECT_NEAR(v[9], 1.0, 1e-9) << line;
    EXPECT_NEAR(v[10], 0.0, 1e-6) << line;
  }
  // A field with a comma is quoted (RFC 4180).
  EXPECT_NE(slurp(out / "pilot.csv").find(",\"reason, with a comma\","), std::string::npos);

  const ReportSummary& s = r.summary;
  EXPECT_EQ(s.events, 20 + 10 + 10 + 9 + 5 + 8 + 2 + 1);
  EXPECT_NEAR(s.duration_s, (9 * kFrameUs + 60'000 - 1000) * 1e-6, 1e-9);
  double length = 0;
  for (int i = 1; i < 10; ++i) length += (truth(i) - truth(i - 1)).norm();
  ASSERT_TRUE(s.distance_m);
  EXPECT_NEAR(*s.distance_m, length, 1e-9);
  EXPECT_EQ(s.distance_source, "SIM_STATE");
  EXPECT_EQ(s.final_pilot_state, "LANDED");
  ASSERT_TRUE(s.landing_error_m);
  EXPECT_NEAR(*s.landing_error_m, std::hypot(0.1, 0.2), 1e-9);
  EXPECT_EQ(s.track_losses, 2);  // TRACKING -> LOST twice (LOST, LOST is one loss)
  EXPECT_EQ(s.pilot_losses, 2);
  EXPECT_EQ(s.vo_lost, 1);
  EXPECT_EQ(s.vo_frames_skipped, 1);
  EXPECT_FALSE(s.link_loss_pct);
  const auto sum = summary(out);
  EXPECT_EQ(sum.at("final_pilot_state"), "LANDED");
  EXPECT_EQ(sum.at("track_losses"), "2");
  EXPECT_EQ(sum.at("link_loss_pct"), "");

  std::map<std::string, bool> present;
  for (const auto& sec : r.sections) present[sec.id] = sec.present;
  const std::map<std::string, bool> want{{"trajectory", true}, {"pilot", true},   {"track", true},
                                         {"vo", true},         {"nav_error", true}, {"latency", true},
                                         {"link", false},      {"rates", true}};
  EXPECT_EQ(present, want);
  for (const auto& sec : r.sections)
    if (sec.id == "link") {
      EXPECT_EQ(sec.missing, std::vector<std::string>{"LINK_STATS"});
    }

  if (!have_matplotlib()) GTEST_SKIP() << "/usr/bin/python3 has no numpy/matplotlib: the page is not checked";
  const PlotRun plot = run_report_plots("/usr/bin/python3", default_report_script(), out.string());
  ASSERT_TRUE(plot.ok) << plot.message;
  const std::string page = slurp(out / "index.html");
  for (const char* id : {"trajectory", "pilot", "track", "vo", "nav_error", "latency", "rates"}) {
    EXPECT_NE(page.find("<section id=\"" + std::string(id) + "\">"), std::string::npos) << id;
    EXPECT_TRUE(fs::file_size(out / (std::string(id) + ".png")) > 1000) << id;
    EXPECT_NE(page.find("src=\"" + std::string(id) + ".png\""), std::string::npos) << id;
  }
  EXPECT_EQ(page.find("<section id=\"link\">"), std::string::npos);
  EXPECT_NE(page.find("<li id=\"missing-link\">Link statistics: the log has no LINK_STATS</li>"), std::string::npos);
  EXPECT_NE(page.find("<td>LANDED</td>"), std::string::npos);
  EXPECT_NE(page.find("<td>0.224</td>"), std::string::npos);  // the landing error
}

TEST(LogReport, ALogWithOneChannelStillGivesAPageAndNamesWhatIsMissing) {
  const fs::path dir = test::scratch_dir("one");
  const fs::path log = dir / "pilot.lcm";
  {
    logio::Writer w(log.string());
    for (int i = 0; i < 3; ++i) {
      aerie::pilot_state_t ps{};
      ps.utime = kT0 + i * kFrameUs;
      ps.seq = i;
      ps.state = aerie::pilot_state_t::HOLD;
      ps.state_name = "HOLD";
      const auto b = encode(ps);
      w.write(ps.utime + 3000, "PILOT_STATE", b.data(), b.size());
    }
  }
  const fs::path out = dir / "report";
  const ReportResult r = write_report_data(log.string(), out.string());
  EXPECT_EQ(r.rows.at("pilot.csv"), 3);
  EXPECT_EQ(r.rows.at("rates.csv"), 1);
  EXPECT_EQ(r.rows.count("trajectory.csv"), 0u);
  EXPECT_FALSE(r.summary.distance_m);
  EXPECT_EQ(r.summary.final_pilot_state, "HOLD");
  for (const auto& sec : r.sections) {
    const bool expect_present = sec.id == "pilot" || sec.id == "latency" || sec.id == "rates";
    EXPECT_EQ(sec.present, expect_present) << sec.id;
    if (sec.id == "trajectory") {
      EXPECT_EQ(sec.missing, (std::vector<std::string>{"VO_POSE", "NAV_STATE", "SIM_STATE", "GT_POSE"}));
    }
  }
  // A second report into the same folder needs --force.
  EXPECT_THROW(write_report_data(log.string(), out.string()), std::runtime_error);
  EXPECT_NO_THROW(write_report_data(log.string(), out.string(), false, true));

  if (!have_matplotlib()) GTEST_SKIP() << "/usr/bin/python3 has no numpy/matplotlib: the page is not checked";
  const PlotRun plot = run_report_plots("/usr/bin/python3", default_report_script(), out.string());
  ASSERT_TRUE(plot.ok) << plot.message;
  const std::string page = slurp(out / "index.html");
  EXPECT_NE(page.find("<section id=\"pilot\">"), std::string::npos);
  EXPECT_NE(page.find("<li id=\"missing-trajectory\">Trajectory over the map (top and side views): the log has no "
                      "VO_POSE or NAV_STATE or SIM_STATE or GT_POSE</li>"),
            std::string::npos);
  for (const char* id : {"track", "vo", "nav_error", "link"})
    EXPECT_NE(page.find("<li id=\"missing-" + std::string(id) + "\">"), std::string::npos) << id;
}

TEST(LogReport, AMissingPythonOrMatplotlibIsSaidAndTheCsvsStay) {
  const fs::path dir = test::scratch_dir("nopython");
  const fs::path log = dir / "flight.lcm";
  write_flight(log);
  const fs::path out = dir / "report";
  write_report_data(log.string(), out.string());
  const std::string script = default_report_script();
  ASSERT_FALSE(script.empty());
  PlotRun p = run_report_plots((dir / "no-such-python3").string(), script, out.string());
  EXPECT_FALSE(p.ok);
  EXPECT_NE(p.message.find("no-such-python3 not found: the CSVs are written"), std::string::npos) << p.message;
  // A python that starts but cannot import numpy/matplotlib.
  const fs::path fake = dir / "python-without-matplotlib";
  std::ofstream(fake) << "#!/bin/sh\n[ \"$2\" = \"\" ] && exit 0\nexit 1\n";
  fs::permissions(fake, fs::perms::owner_all);
  p = run_report_plots(fake.string(), script, out.string());
  EXPECT_FALSE(p.ok);
  EXPECT_NE(p.message.find("has no numpy/matplotlib: the CSVs are written"), std::string::npos) << p.message;
  p = run_report_plots("/usr/bin/python3", (dir / "none.py").string(), out.string());
  EXPECT_FALSE(p.ok);
  EXPECT_NE(p.message.find("plot script not found"), std::string::npos) << p.message;
  EXPECT_FALSE(fs::exists(out / "index.html"));
  EXPECT_EQ(data_rows(out / "pilot.csv"), 5);
}

TEST(LogReport, ATruncatedLogIsReportedAsDamagedWithWhatCameBefore) {
  const fs::path dir = test::scratch_dir("truncated");
  const fs::path log = dir / "flight.lcm";
  write_flight(log);
  fs::resize_file(log, fs::file_size(log) - 10);  // into the last event (MAP_OCTOMAP)
  const fs::path out = dir / "report";
  const ReportResult r = write_report_data(log.string(), out.string());
  ASSERT_EQ(r.damage.size(), 1u);
  EXPECT_EQ(r.damage[0].kind, logio::Damage::Kind::Truncated);
  EXPECT_NE(r.damage[0].message.find(log.string()), std::string::npos) << r.damage[0].message;
  EXPECT_EQ(r.summary.events, 20 + 10 + 10 + 9 + 5 + 8 + 2);  // all but the map
  EXPECT_EQ(r.rows.at("pilot.csv"), 5);
  EXPECT_EQ(r.rows.count("map.csv"), 0u);
  EXPECT_NE(slurp(out / "summary.csv").find("damage,"), std::string::npos);

  // The command: exit status 2, the damage named on stderr, the report written all the same.
  const fs::path out2 = dir / "report2";
  const std::string cmd = std::string(AERIE_BINARY_DIR "/bin/aerie-log report ") + log.string() + " --out " +
                          out2.string() + " --no-plots >" + (dir / "stdout").string() + " 2>" +
                          (dir / "stderr").string();
  const int st = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(st));
  EXPECT_EQ(WEXITSTATUS(st), 2);
  EXPECT_NE(slurp(dir / "stderr").find("aerie-log: DAMAGE: "), std::string::npos) << slurp(dir / "stderr");
  EXPECT_EQ(data_rows(out2 / "pilot.csv"), 5);
  EXPECT_NE(slurp(dir / "stdout").find("- Link statistics (missing: LINK_STATS)"), std::string::npos)
      << slurp(dir / "stdout");
}

TEST(LogReport, TheCommandRefusesAWrongOptionAndAMissingLog) {
  const fs::path dir = test::scratch_dir("cli");
  const std::string bin = AERIE_BINARY_DIR "/bin/aerie-log report ";
  const std::string err = " 2>" + (dir / "stderr").string() + " >/dev/null";
  int st = std::system((bin + (dir / "x.lcm").string() + " --out " + (dir / "r").string() + " --bogus" + err).c_str());
  ASSERT_TRUE(WIFEXITED(st));
  EXPECT_EQ(WEXITSTATUS(st), 2);
  EXPECT_NE(slurp(dir / "stderr").find("--bogus"), std::string::npos) << slurp(dir / "stderr");
  st = std::system((bin + (dir / "none.lcm").string() + " --out " + (dir / "r").string() + err).c_str());
  ASSERT_TRUE(WIFEXITED(st));
  EXPECT_EQ(WEXITSTATUS(st), 1);
  EXPECT_NE(slurp(dir / "stderr").find("none.lcm"), std::string::npos) << slurp(dir / "stderr");
}

// The demo's loop (flight simulator, aerie-track and aerie-pilot in lock-step), 12 s of it
// recorded as the demo's logger would, then reported.
TEST(LogReport, AShortClosedLoopFlightGetsItsReport) {
  loop::landing::RunConfig rc =
      loop::landing::load_landing_run(util::Config::parse("max_time_s: 12\n", "test_log_report"), 3, AERIE_SOURCE_DIR);
  rc.frames_after_end = 0;
  const fs::path dir = test::scratch_dir("loop");
  const fs::path log = dir / "demo.lcm";
  std::map<std::string, int64_t> counts;
  {
    logio::Writer w(log.string());
    rc.on_message = [&](link::Side, const std::string& channel, const uint8_t* data, size_t size, int64_t now_us) {
      w.write(now_us, channel, data, size);
      ++counts[channel];
    };
    loop::landing::fly(rc);
  }
  const auto count = [&](const char* ch) { return counts.count(ch) ? counts.at(ch) : int64_t{0}; };
  ASSERT_GT(count("SIM_STATE"), 0);
  ASSERT_GT(count("PILOT_STATE"), 0);
  const fs::path out = dir / "report";
  const ReportResult r = write_report_data(log.string(), out.string());
  EXPECT_TRUE(r.damage.empty());
  EXPECT_EQ(r.summary.undecodable, 0);
  EXPECT_EQ(r.rows.at("trajectory.csv"),
            count("SIM_STATE") + count("GT_POSE") + count("NAV_STATE") + count("VO_POSE"));
  EXPECT_EQ(r.rows.at("pilot.csv"), count("PILOT_STATE"));
  EXPECT_EQ(r.rows.at("track.csv"), count("TRACK"));
  EXPECT_EQ(r.rows.at("channels.csv"), static_cast<int64_t>(counts.size()));
  EXPECT_EQ(r.summary.distance_source, "SIM_STATE");
  ASSERT_TRUE(r.summary.distance_m);
  EXPECT_GT(*r.summary.distance_m, 0.5);  // it took off
  EXPECT_FALSE(r.summary.final_pilot_state.empty());
  for (const auto& sec : r.sections)
    if (sec.id == "trajectory" || sec.id == "pilot" || sec.id == "track" || sec.id == "rates") {
      EXPECT_TRUE(sec.present) << sec.id;
    }

  if (!have_matplotlib()) GTEST_SKIP() << "/usr/bin/python3 has no numpy/matplotlib: the page is not checked";
  const PlotRun plot = run_report_plots("/usr/bin/python3", default_report_script(), out.string());
  ASSERT_TRUE(plot.ok) << plot.message;
  const std::string page = slurp(out / "index.html");
  for (const char* id : {"trajectory", "pilot", "track", "rates"})
    EXPECT_NE(page.find("<section id=\"" + std::string(id) + "\">"), std::string::npos) << id;
}

}  // namespace
}  // namespace aerie::logtools
