// End to end: aerie-capture publishes a dataset, the stock lcm-logger records it, the
// stock lcm-logplayer replays it and a second lcm-logger records the replay. The
// recorded payloads must be exactly the messages the capture library builds, and the
// replay must give them again. Over real UDP multicast inside a network namespace
// the test creates (and removes), and over memq:// in-process. Corrupt payloads on
// the camera channels must not crash a consumer.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "air/capture/capture_node.hpp"
#include "air/capture/sim_source.hpp"
#include "air/capture/stereo_sequence_source.hpp"
#include "common/bus/node.hpp"
#include "common/logio/event_log.hpp"
#include "tests/integration/process.hpp"
#include "tests/support/test_support.hpp"

namespace aerie {
namespace {
namespace fs = std::filesystem;
using test::NetNamespace;
using test::Process;

const char* kKitti = "stereo_seq/KITTI_odom_06_f000-050";
const std::string kUrl = "udpm://239.255.76.67:7667?ttl=0";
// The logger's socket buffer: 4 MB (net.core.rmem_max here), see docs/logs.md.
const std::string kLoggerUrl = kUrl + "&recv_buf_size=4194304";

std::string bin(const std::string& name) { return (test::binary_dir() / "bin" / name).string(); }

template <typename Msg>
std::vector<uint8_t> encode(const Msg& m) {
  std::vector<uint8_t> b(static_cast<size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

using Payloads = std::map<std::string, std::vector<std::vector<uint8_t>>>;  // channel -> payloads in order

Payloads payloads_of(const std::string& log, bool with_status = false) {
  const auto r = logio::read_all(log);
  EXPECT_TRUE(r.damage.empty()) << (r.damage.empty() ? "" : r.damage[0].message);
  Payloads p;
  for (const auto& ev : r.events)
    if (with_status || ev.channel.rfind("STATUS_", 0) != 0) p[ev.channel].push_back(ev.data);
  return p;
}

// The messages the capture library makes of the first `frames` frames of a source.
Payloads expected_messages(capture::FrameSource& src, const capture::CaptureConfig& cfg, int frames) {
  const capture::OutputFormat fmt(cfg.output, src.size());
  const capture::MessageBuilder builder(cfg, true, fmt.apply(*src.rectified()));
  Payloads p;
  capture::Frame f;
  for (int i = 0; i < frames && src.next(f); ++i) {
    fmt.apply(f);
    const auto m = builder.build(f, f.utime, i);
    if (m.left) p["CAM_LEFT"].push_back(encode(*m.left));  // only with channels.split_stereo (issue 49)
    if (m.right) p["CAM_RIGHT"].push_back(encode(*m.right));
    p["CAM_STEREO"].push_back(encode(*m.stereo));
    if (m.gt_pose) p["GT_POSE"].push_back(encode(*m.gt_pose));
    if (m.gt_box) p["GT_TRACK"].push_back(encode(*m.gt_box));
  }
  return p;
}

// The first `frames` KITTI frames at half size.
Payloads expected_kitti(int frames) {
  capture::CaptureConfig cfg;
  cfg.output.downscale = 2;
  capture::StereoSequenceSource src(capture::load_kitti(test::shared_data(kKitti).string()), false);
  return expected_messages(src, cfg, frames);
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Starts the stock lcm-logger inside the namespace and waits until it has opened the log.
std::unique_ptr<Process> start_logger(const NetNamespace& ns, const fs::path& log, const fs::path& out) {
  auto p = std::make_unique<Process>(ns.exec({"lcm-logger", "-f", "--lcm-url=" + kLoggerUrl, log.string()}), out);
  for (int i = 0; i < 250 && !fs::exists(log); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // subscribed and listening
  return p;
}

void stop_logger(Process& logger, const fs::path& out) {
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the last datagrams arrive
  logger.signal(SIGINT);
  const auto rc = logger.wait(10);
  ASSERT_TRUE(rc) << "lcm-logger did not stop on SIGINT";
  EXPECT_EQ(*rc, 0) << slurp(out);
}

// capture -> UDP multicast -> lcm-logger, then lcm-logplayer -> UDP -> lcm-logger,
// inside a fresh namespace: the first log holds exactly `expected`, the second the
// same events again.
void record_and_replay(const fs::path& dir, const std::vector<std::string>& capture_args, const Payloads& expected) {
  NetNamespace ns("aerie-capture-it-" + std::to_string(getpid()));
  auto logger = start_logger(ns, dir / "flight.lcm", dir / "logger1.txt");
  std::vector<std::string> argv = {bin("aerie-capture"), "--lcm-url", kUrl};
  argv.insert(argv.end(), capture_args.begin(), capture_args.end());
  Process capture(ns.exec(argv), dir / "capture.txt");
  const auto rc = capture.wait(300);
  ASSERT_TRUE(rc) << "aerie-capture did not finish";
  ASSERT_EQ(*rc, 0) << slurp(dir / "capture.txt");
  stop_logger(*logger, dir / "logger1.txt");

  const auto recorded = payloads_of((dir / "flight.lcm").string());
  ASSERT_EQ(recorded.size(), expected.size()) << "channels";
  for (const auto& [channel, payloads] : expected) {
    ASSERT_TRUE(recorded.count(channel)) << channel;
    ASSERT_EQ(recorded.at(channel).size(), payloads.size()) << channel << ": messages lost";
    for (size_t i = 0; i < payloads.size(); ++i)
      EXPECT_TRUE(recorded.at(channel)[i] == payloads[i]) << channel << " message " << i << " differs";
  }

  auto logger2 = start_logger(ns, dir / "replay.lcm", dir / "logger2.txt");
  Process player(ns.exec({"lcm-logplayer", "-s", "4", "--lcm-url=" + kUrl, (dir / "flight.lcm").string()}),
                 dir / "player.txt");
  const auto prc = player.wait(120);
  ASSERT_TRUE(prc) << "lcm-logplayer did not finish";
  EXPECT_EQ(*prc, 0) << slurp(dir / "player.txt");
  stop_logger(*logger2, dir / "logger2.txt");
  EXPECT_EQ(payloads_of((dir / "replay.lcm").string(), true), payloads_of((dir / "flight.lcm").string(), true));
}

TEST(CaptureReplay, KittiOverUdpMulticastLoggerAndLogplayerInNamespace) {
  AERIE_REQUIRE_DATA(kKitti);
  if (const auto why = NetNamespace::unavailable(); !why.empty()) GTEST_SKIP() << why;
  const auto dir = test::scratch_dir("udp");
  constexpr int kFrames = 20;
  record_and_replay(dir,
                    {"--source", "kitti", "--path", test::shared_data(kKitti).string(), "--downscale", "2", "--rate",
                     "4", "--stop", std::to_string(kFrames)},
                    expected_kitti(kFrames));

  // aerie-log info on the recording: no drops, no damage.
  const auto info = dir / "info.txt";
  const int info_rc = std::system((bin("aerie-log") + " info " + (dir / "flight.lcm").string() + " > " + info.string()).c_str());
  EXPECT_EQ(info_rc, 0);
  EXPECT_NE(slurp(info).find("dropped messages (sequence gaps): 0"), std::string::npos) << slurp(info);
  EXPECT_NE(slurp(info).find("aerie.stereo_image_t"), std::string::npos);
}

// A simulated flight (fixed start time, so the run is reproducible): the log holds the
// same payloads as an in-process rerun of the simulator, and its replay gives them again.
TEST(CaptureReplay, SimulatedFlightRecordedAndReplayedOverUdp) {
  if (const auto why = NetNamespace::unavailable(); !why.empty()) GTEST_SKIP() << why;
  const auto dir = test::scratch_dir("sim");
  constexpr int kFrames = 30;  // 1.5 s of flight at 20 Hz
  capture::SimSourceOptions sim;
  sim.start_utime = 1'000'000;
  capture::SimSource src(sim, 0, 0, false, 20.0);
  record_and_replay(dir,
                    {"--source", "sim", "--sim-start-utime", "1000000", "--rate", "2", "--stop",
                     std::to_string(kFrames)},
                    expected_messages(src, capture::CaptureConfig{}, kFrames));
}

// In-process: capture -> memq -> a recorder writing the standard log format -> a
// replay of that log onto a fresh memq bus gives the same messages.
TEST(CaptureReplay, MemqRecordAndReplayInProcess) {
  AERIE_REQUIRE_DATA(kKitti);
  const auto dir = test::scratch_dir("memq");
  constexpr int kFrames = 8;
  {
    bus::Bus bus("memq://");
    logio::Writer log((dir / "memq.lcm").string());
    bus.subscribe_raw(".*", [&](const uint8_t* data, size_t size, const bus::ReceiveInfo& info) {
      log.write(info.recv_utime, info.channel, data, size);
    }, 10000);
    capture::CaptureConfig cfg;
    cfg.rate = 0;
    cfg.stop = kFrames;
    cfg.output.downscale = 2;
    capture::CaptureNode node(bus, cfg, std::make_unique<capture::StereoSequenceSource>(
                                            capture::load_kitti(test::shared_data(kKitti).string()), false));
    node.run();
    while (bus.handle(0) > 0) {
    }
  }
  const auto recorded = payloads_of((dir / "memq.lcm").string());
  EXPECT_EQ(recorded, expected_kitti(kFrames));

  bus::Bus replay_bus("memq://");
  Payloads replayed;
  replay_bus.subscribe_raw(".*", [&](const uint8_t* data, size_t size, const bus::ReceiveInfo& info) {
    if (info.channel.rfind("STATUS_", 0) != 0) replayed[info.channel].emplace_back(data, data + size);
  }, 10000);
  logio::Reader reader((dir / "memq.lcm").string());
  logio::Event ev;
  while (reader.next(ev)) {
    replay_bus.publish_raw(ev.channel, ev.data.data(), static_cast<unsigned>(ev.data.size()));
    replay_bus.handle(0);
  }
  while (replay_bus.handle(0) > 0) {
  }
  EXPECT_EQ(replayed, recorded);
}

// Corrupt payloads on CAM_* reach a consumer (decode + image conversion): each is
// counted as malformed and dropped, and the next good frame is used.
TEST(CaptureReplay, CorruptCameraPayloadsDoNotCrashAConsumer) {
  bus::Bus bus("memq://");
  int images = 0, pairs = 0;
  auto& left = bus.subscribe<aerie::image_t>("CAM_LEFT", [&](const aerie::image_t& m, const bus::ReceiveInfo&) {
    const cv::Mat img = image::from_message(m);  // throws std::invalid_argument on inconsistent images
    images += img.empty() ? 0 : 1;
  }, 100);
  auto& stereo = bus.subscribe<aerie::stereo_image_t>("CAM_STEREO", [&](const aerie::stereo_image_t& m, const bus::ReceiveInfo&) {
    const cv::Mat l = image::from_message(m.left), r = image::from_message(m.right);
    pairs += l.size() == r.size() ? 1 : 0;
  }, 100);

  const cv::Mat img(12, 16, CV_8UC1, cv::Scalar(3));
  const auto good = image::to_message(img, 1, 0);
  auto publish_bytes = [&](const std::string& ch, std::vector<uint8_t> b) {
    bus.publish_raw(ch, b.data(), static_cast<unsigned>(b.size()));
    bus.handle(0);
  };
  // 1. random bytes, 2. a good image cut short, 3. another type on the channel,
  // 4. an image whose size field disagrees with its data, 5. a JPEG that is not one.
  publish_bytes("CAM_LEFT", {1, 2, 3, 4, 5, 6, 7, 8, 9});
  auto cut = encode(good);
  cut.resize(cut.size() - 50);
  publish_bytes("CAM_LEFT", cut);
  aerie::gt_pose_t pose{};
  publish_bytes("CAM_LEFT", encode(pose));
  auto wrong = good;
  wrong.height = 500;
  publish_bytes("CAM_LEFT", encode(wrong));
  auto jpeg = good;
  jpeg.pixelformat = aerie::image_t::PIXEL_FORMAT_MJPEG;
  publish_bytes("CAM_LEFT", encode(jpeg));
  aerie::stereo_image_t s{};
  s.left = good;
  s.right = wrong;
  publish_bytes("CAM_STEREO", encode(s));
  publish_bytes("CAM_STEREO", {0xff});
  // Good messages still get through.
  publish_bytes("CAM_LEFT", encode(good));
  s.right = good;
  publish_bytes("CAM_STEREO", encode(s));

  EXPECT_EQ(images, 1);
  EXPECT_EQ(pairs, 1);
  EXPECT_EQ(left.counters().received, 6);
  EXPECT_EQ(left.counters().malformed, 5);
  EXPECT_EQ(stereo.counters().malformed, 2);
  EXPECT_NE(left.last_error().find("CAM_LEFT"), std::string::npos);
}

// Ctrl-C (SIGINT) stops aerie-capture cleanly mid-run, with exit status 0.
TEST(CaptureReplay, InterruptStopsCaptureCleanly) {
  AERIE_REQUIRE_DATA(kKitti);
  const auto dir = test::scratch_dir("sigint");
  Process capture({bin("aerie-capture"), "--lcm-url", "memq://", "--source", "kitti", "--path",
                   test::shared_data(kKitti).string(), "--rate", "1"},
                  dir / "capture.txt");
  // Once it runs (it says where it publishes after installing its handlers; start-up takes
  // seconds on a loaded machine), then mid-sequence (5 s at real time).
  for (int i = 0; i < 300 && slurp(dir / "capture.txt").find("-> memq://") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_NE(slurp(dir / "capture.txt").find("-> memq://"), std::string::npos) << slurp(dir / "capture.txt");
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));
  capture.signal(SIGINT);
  const auto rc = capture.wait(5);
  ASSERT_TRUE(rc) << "aerie-capture ignored SIGINT";
  EXPECT_EQ(*rc, 0) << slurp(dir / "capture.txt");
  EXPECT_NE(slurp(dir / "capture.txt").find("published"), std::string::npos) << slurp(dir / "capture.txt");
}

// Startup errors: non-zero exit and a message naming the file.
TEST(CaptureReplay, StartupErrorsNameTheFile) {
  const auto dir = test::scratch_dir("errors");
  Process capture({bin("aerie-capture"), "--lcm-url", "memq://", "--source", "euroc", "--path", "/no/such/euroc"},
                  dir / "capture.txt");
  const auto rc = capture.wait(30);
  ASSERT_TRUE(rc);
  EXPECT_EQ(*rc, 1);
  EXPECT_NE(slurp(dir / "capture.txt").find("/no/such/euroc"), std::string::npos) << slurp(dir / "capture.txt");

  std::ofstream(dir / "broken.lcm") << "definitely not an LCM log";
  const int info_rc = std::system((bin("aerie-log") + " info " + (dir / "broken.lcm").string() + " > " +
                                   (dir / "info.txt").string() + " 2>&1").c_str());
  EXPECT_EQ(WEXITSTATUS(info_rc), 2);
  EXPECT_NE(slurp(dir / "info.txt").find("at byte 0 (event 0)"), std::string::npos) << slurp(dir / "info.txt");
}

}  // namespace
}  // namespace aerie
