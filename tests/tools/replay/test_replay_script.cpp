// aerie-replay on small logs written here: control on the log's time (the live commands, not a
// hover), aerie-track with --config and --camera (TRACK for every frame), and a replay that
// produces nothing failing with a message that says why.
#include <aerie/control_cmd_t.hpp>
#include <aerie/pose_t.hpp>
#include <aerie/track_cmd_t.hpp>
#include <aerie/track_t.hpp>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "air/control/control_config.hpp"
#include "air/control/control_node.hpp"
#include "common/bus/bus.hpp"
#include "common/bus/wire.hpp"
#include "common/image/image_message.hpp"
#include "common/logio/event_log.hpp"
#include "common/util/time.hpp"
#include "procman/testbed.hpp"
#include "tests/support/test_support.hpp"

using namespace aerie;
namespace fs = std::filesystem;
namespace tb = procman::testbed;

namespace {

template <typename M>
std::vector<uint8_t> encoded(const M& m) {
  std::vector<uint8_t> b(static_cast<size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

template <typename M>
void write(logio::Writer& log, int64_t receive_utime, const std::string& channel, const M& m) {
  const auto b = encoded(m);
  log.write(receive_utime, channel, b.data(), b.size());
}

std::vector<logio::Event> events_on(const fs::path& path, const std::string& channel) {
  logio::Reader r(path.string());
  std::vector<logio::Event> out;
  for (logio::Event e; r.next(e);)
    if (e.channel == channel) out.push_back(e);
  return out;
}

std::string text_of(const fs::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct ReplayRun {
  int status = -1;
  std::string output;
};

// bin/aerie-replay ARGS inside a namespace of its own (its LCM URL is multicast on this host).
ReplayRun replay(const std::vector<std::string>& args, const fs::path& dir) {
  tb::NetNamespace ns(tb::unique_name("replay"));
  std::vector<std::string> argv = ns.exec_prefix();
  argv.push_back((test::binary_dir() / "bin" / "aerie-replay").string());
  argv.insert(argv.end(), args.begin(), args.end());
  const fs::path out = dir / "replay-output.txt";
  tb::Process p(argv, out.string());
  ReplayRun r;
  r.status = p.wait(std::chrono::seconds(240)).value_or(-1);
  r.output = text_of(out);
  return r;
}

// VO_POSE turning right by `heading` degrees (VO's frame: y down, zero heading along z).
aerie::pose_t vo_pose(int64_t utime, int64_t seq, double heading) {
  aerie::pose_t p{};
  p.utime = utime;
  p.seq = seq;
  p.status = aerie::pose_t::OK;
  const Eigen::Quaterniond q(Eigen::AngleAxisd(-heading * M_PI / 180.0, Eigen::Vector3d(0, -1, 0)));
  p.orientation[0] = q.w(), p.orientation[1] = q.x(), p.orientation[2] = q.y(), p.orientation[3] = q.z();
  return p;
}

// A small mono sequence on CAM_MONO: a bright square moving over a gradient, 20 frames at 20 Hz,
// and an operator's INIT on it before the first frame.
constexpr int kFrames = 20;
void write_mono_log(const fs::path& path, int64_t t0) {
  logio::Writer log(path.string());
  aerie::track_cmd_t init{};
  init.utime = t0 - 100'000;
  init.command = aerie::track_cmd_t::INIT;
  init.x = 60, init.y = 40, init.width = 30, init.height = 30;
  write(log, t0 - 100'000, "TRACK_CMD", init);
  for (int k = 0; k < kFrames; ++k) {
    cv::Mat img(120, 160, CV_8UC1);
    for (int y = 0; y < img.rows; ++y)
      for (int x = 0; x < img.cols; ++x) img.at<uint8_t>(y, x) = static_cast<uint8_t>((x + 2 * y) % 97);
    cv::rectangle(img, cv::Rect(60 + k, 40, 30, 30), cv::Scalar(230), cv::FILLED);
    cv::circle(img, cv::Point(75 + k, 55), 6, cv::Scalar(20), cv::FILLED);
    const int64_t utime = t0 + k * 50'000;
    write(log, utime + 5'000, "CAM_MONO", image::to_message(img, utime, k));
  }
  log.close();
}

}  // namespace

TEST(ReplayScript, ControlOnTheLogsTimeGivesTheLiveCommandsNotAHover) {
  // Issue 49: replayed a few seconds after it was recorded, every CTRL_CMD was a hover ("pose on
  // VO_POSE is 7478 ms old (limit 150 ms)"). A flight whose poses were stamped 7.5 s ago, each
  // received 20 ms after its frame; replayed through aerie-control with its own config, the
  // commands are the ones the live node gave, byte for byte.
  if (const auto why = tb::namespaces_unavailable(); !why.empty()) GTEST_SKIP() << why;
  const fs::path dir = test::scratch_dir("control");
  const fs::path config = dir / "control.yaml", log = dir / "flight.lcm", out = dir / "replay.lcm";
  std::ofstream(config) << "rate_hz: 30\nforward_speed_m_s: 0.4\nreference_deg: 45\nmax_input_age_s: 0.15\n";
  const int64_t t0 = util::wall_utime() - 7'500'000;
  std::vector<aerie::pose_t> poses;
  {
    logio::Writer w(log.string());
    for (int k = 0; k < 45; ++k) {
      poses.push_back(vo_pose(t0 + k * 33'333, k, k / 2.0));
      write(w, poses.back().utime + 20'000, "VO_POSE", poses.back());
    }
  }
  // The live node: its clock 20 ms after each frame, one command per pose as in the replay.
  std::vector<std::vector<uint8_t>> live;
  {
    bus::Bus bus("memq://");
    bus::StatusReporter status(bus, "control");
    control::NodeSetup setup = control::node_setup(util::Config::load(config.string()));
    setup.options.rate_hz = 0;
    int64_t now = 0;
    control::ControlNode node(bus, status, setup.controller, setup.options, [&] { return now; });
    bus.subscribe<aerie::control_cmd_t>("CTRL_CMD", [&](const aerie::control_cmd_t& m, const bus::ReceiveInfo&) {
      EXPECT_EQ(m.mode, aerie::control_cmd_t::ACTIVE) << m.seq;
      live.push_back(encoded(m));
    });
    for (const auto& p : poses) {
      now = p.utime + 20'000;
      bus.publish("VO_POSE", p);
      while (bus.handle(0) > 0) {
      }
    }
  }
  ASSERT_EQ(live.size(), poses.size());

  const ReplayRun r = replay({log.string(), "--out", out.string(), "--nodes", "control", "--config", "control=" + config.string()}, dir);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("aerie-replay: control: 45 CTRL_CMD messages"), std::string::npos) << r.output;
  const auto cmds = events_on(out, "CTRL_CMD");
  ASSERT_EQ(cmds.size(), live.size()) << r.output;
  for (size_t i = 0; i < cmds.size(); ++i) {
    const auto m = bus::decode_bounded<aerie::control_cmd_t>(cmds[i].data.data(), cmds[i].data.size());
    EXPECT_EQ(m.mode, aerie::control_cmd_t::ACTIVE) << i;
    EXPECT_EQ(m.utime, poses[i].utime) << i;
    EXPECT_EQ(cmds[i].data, live[i]) << "command " << i;
  }
  EXPECT_TRUE(events_on(out, "VO_POSE").size() == poses.size());  // the input, recorded with aerie-log record
}

TEST(ReplayScript, TrackWithItsConfigAndCameraPublishesATrackForEveryFrame) {
  // Issue 49: `--nodes track` on a log of CAM_MONO gave 0 TRACK: the demo's config listens on
  // CAM_DOWN. --config track=FILE chooses the tracker, --camera the channel.
  if (const auto why = tb::namespaces_unavailable(); !why.empty()) GTEST_SKIP() << why;
  const fs::path dir = test::scratch_dir("track");
  const fs::path config = dir / "track.yaml", log = dir / "mono.lcm", out = dir / "replay.lcm";
  std::ofstream(config) << "node:\n  camera_channel: CAM_LEFT\n  tracker: ct\n";
  const int64_t t0 = 1'500'000'000'000'000;
  write_mono_log(log, t0);
  const ReplayRun r = replay({log.string(), "--out", out.string(), "--nodes", "track", "--config", "track=" + config.string(),
                        "--camera", "CAM_MONO", "--speed", "2"},
                       dir);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("aerie-replay: track: 20 TRACK messages"), std::string::npos) << r.output;
  const auto tracks = events_on(out, "TRACK");
  ASSERT_EQ(tracks.size(), static_cast<size_t>(kFrames)) << r.output;
  for (int k = 0; k < kFrames; ++k) {
    const auto m = bus::decode_bounded<aerie::track_t>(tracks[k].data.data(), tracks[k].data.size());
    EXPECT_EQ(m.utime, t0 + k * 50'000) << k;  // every frame, in order
    EXPECT_EQ(m.camera, "CAM_MONO");
    EXPECT_EQ(m.tracker, "ct") << k;  // the config's tracker took the INIT
    EXPECT_NE(m.status, aerie::track_t::IDLE) << k;
  }
}

TEST(ReplayScript, AReplayThatProducesNothingFailsNamingTheChannels) {
  if (const auto why = tb::namespaces_unavailable(); !why.empty()) GTEST_SKIP() << why;
  const fs::path dir = test::scratch_dir("nothing");
  const fs::path log = dir / "mono.lcm", out = dir / "replay.lcm";
  write_mono_log(log, 1'500'000'000'000'000);
  // The demo's track config: the down camera of the simulator, not in this log.
  const ReplayRun r = replay({log.string(), "--out", out.string(), "--nodes", "track", "--speed", "4"}, dir);
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("aerie-replay: warning: track listens on CAM_DOWN, which " + log.string() +
                          " does not carry (image channels: CAM_MONO (aerie.image_t)); see --camera"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("aerie-replay: ERROR: track published 0 TRACK messages (it listened on CAM_DOWN: no messages of "
                          "it in " + log.string() + "; image channels there: CAM_MONO (aerie.image_t); choose one "
                          "with --camera or --config track=FILE)"),
            std::string::npos)
      << r.output;
  EXPECT_TRUE(events_on(out, "TRACK").empty());
}

TEST(ReplayScript, UsageErrorsExitWith2AndAOneLineMessage) {
  const fs::path dir = test::scratch_dir("usage");
  const fs::path log = dir / "mono.lcm";
  write_mono_log(log, 1'500'000'000'000'000);
  const std::string bin = (test::binary_dir() / "bin" / "aerie-replay").string();
  const auto run = [&](const std::string& args) {
    const fs::path o = dir / "out.txt";
    const int s = std::system((bin + " " + args + " > " + o.string() + " 2>&1").c_str());
    return std::make_pair(WEXITSTATUS(s), text_of(o));
  };
  const std::string l = log.string(), o = " --out " + (dir / "r.lcm").string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {l + o + " --bogus", "aerie-replay: unknown option '--bogus' (see --help)\n"},
      {l + o + " --config", "aerie-replay: --config needs a value (see --help)\n"},
      {l + o + " --config track", "aerie-replay: --config 'track': expected NODE=FILE with NODE one of track vo control pilot map nav\n"},
      {l + o + " --config control=" + l, "aerie-replay: --config 'control=" + l + "': control is not among --nodes (track,vo)\n"},
      {l + o + " --nodes track --config track=/no/such.yaml", "aerie-replay: --config 'track=/no/such.yaml': cannot read '/no/such.yaml'\n"},
      {l + o + " --nodes control --camera vo=CAM_STEREO", "aerie-replay: --camera 'vo=CAM_STEREO': vo is not among --nodes (control)\n"},
      {l + o + " --nodes trak", "aerie-replay: unknown node 'trak' in --nodes (track vo control pilot map nav)\n"},
  };
  for (const auto& [args, message] : cases) {
    const auto [status, text] = run(args);
    EXPECT_EQ(status, 2) << args;
    EXPECT_EQ(text, message) << args;
  }
  const auto [status, help] = run("--help");
  EXPECT_EQ(status, 0);
  EXPECT_EQ(help.rfind("aerie-replay: replays an Aerie log through chosen nodes", 0), 0u) << help;
  EXPECT_NE(help.find("--camera"), std::string::npos);
}
