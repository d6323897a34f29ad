// aerie-cmd over memq://: every command of the command line arrives decoded with every field as
// sent; --wait-ack against an answering pilot and a running in-process aerie-track node.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "air/track/node/track_node.hpp"
#include "common/image/image_message.hpp"
#include "common/util/time.hpp"
#include "tests/air/track/synthetic.hpp"
#include "tools/cmd/cli.hpp"
#include "tools/cmd/sender.hpp"

namespace {

using aerie::bus::Bus;
using aerie::bus::ReceiveInfo;

struct CliRun {
  int rc = -1;
  std::string out, err;
};

CliRun cli(Bus& bus, const std::vector<std::string>& args) {
  std::ostringstream out, err;
  CliRun r;
  r.rc = aerie::cmd::run(args, out, err, &bus);
  r.out = out.str();
  r.err = err.str();
  return r;
}

// Every message of type M on `channel` that the command line sends.
template <typename M>
std::vector<M> received(Bus& bus, const std::string& channel, const std::vector<std::string>& args, CliRun* run = nullptr) {
  std::vector<M> got;
  auto& sub = bus.subscribe<M>(channel, [&](const M& m, const ReceiveInfo&) { got.push_back(m); });
  const int64_t before = aerie::util::wall_utime();
  const CliRun r = cli(bus, args);
  while (bus.handle(0) > 0) {
  }
  bus.unsubscribe(sub);
  EXPECT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  for (const M& m : got) {
    EXPECT_GE(m.utime, before);
    EXPECT_LE(m.utime, aerie::util::wall_utime());
    EXPECT_EQ(m.seq, 0);  // each run is a new publisher
  }
  if (run) *run = r;
  return got;
}

}  // namespace

TEST(CmdBus, TrackInitRoundTrip) {
  Bus bus("memq://");
  CliRun r;
  const auto got = received<aerie::track_cmd_t>(
      bus, "TRACK_CMD", {"track", "--box", "12.5,20,30,40", "--tracker", "amcmr-ct", "--camera", "CAM_MONO"}, &r);
  ASSERT_EQ(got.size(), 1u);
  const auto& c = got[0];
  EXPECT_EQ(c.command, aerie::track_cmd_t::INIT);
  EXPECT_EQ(c.tracker, "amcmr-ct");
  EXPECT_EQ(c.camera, "CAM_MONO");
  EXPECT_EQ(c.x, 12.5);
  EXPECT_EQ(c.y, 20);
  EXPECT_EQ(c.width, 30);
  EXPECT_EQ(c.height, 40);
  EXPECT_EQ(c.nparams, 0);
  EXPECT_TRUE(c.param_names.empty());
  EXPECT_TRUE(c.param_values.empty());
  EXPECT_EQ(r.out, "sent TRACK_CMD INIT tracker=amcmr-ct camera=CAM_MONO box=(12.5, 20, 30, 40)\n");
}

TEST(CmdBus, TrackDefaultsAndStopRoundTrip) {
  Bus bus("memq://");
  auto got = received<aerie::track_cmd_t>(bus, "TRACK_CMD", {"track", "--box", "1,2,3,4"});
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].tracker, "");  // the node's
  EXPECT_EQ(got[0].camera, "");   // the node's camera channel
  got = received<aerie::track_cmd_t>(bus, "TRACK_CMD", {"track", "stop"});
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].command, aerie::track_cmd_t::STOP);
  EXPECT_EQ(got[0].tracker, "");
  EXPECT_EQ(got[0].camera, "");
  EXPECT_EQ(got[0].x, 0);
  EXPECT_EQ(got[0].y, 0);
  EXPECT_EQ(got[0].width, 0);
  EXPECT_EQ(got[0].height, 0);
  EXPECT_EQ(got[0].nparams, 0);
}

TEST(CmdBus, PilotRoundTrips) {
  Bus bus("memq://");
  const std::string source = aerie::cmd::command_source();
  ASSERT_EQ(source.rfind("aerie-cmd@", 0), 0u);
  const std::vector<std::pair<std::string, int8_t>> words = {{"abort", aerie::pilot_cmd_t::ABORT},
                                                             {"land", aerie::pilot_cmd_t::LAND},
                                                             {"resume", aerie::pilot_cmd_t::RESUME},
                                                             {"start", aerie::pilot_cmd_t::START}};
  for (const auto& [word, code] : words) {
    const auto got = received<aerie::pilot_cmd_t>(bus, "PILOT_CMD", {"pilot", word});
    ASSERT_EQ(got.size(), 1u) << word;
    EXPECT_EQ(got[0].command, code) << word;
    EXPECT_EQ(got[0].source, source) << word;
  }
}

TEST(CmdBus, MapRoundTrips) {
  Bus bus("memq://");
  const int64_t before = aerie::util::wall_utime();
  auto got = received<aerie::map_cmd_t>(bus, "MAP_CMD", {"map", "save"});
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].command, aerie::map_cmd_t::SAVE);
  // The default name is the time of the command, UTC, to the second.
  const std::string first = aerie::cmd::default_map_name(before), last = aerie::cmd::default_map_name(got[0].utime);
  EXPECT_TRUE(got[0].path == first || got[0].path == last) << got[0].path;
  EXPECT_EQ(got[0].path, aerie::cmd::default_map_name(got[0].utime));
  got = received<aerie::map_cmd_t>(bus, "MAP_CMD", {"map", "save", "hall.ot"});
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].command, aerie::map_cmd_t::SAVE);
  EXPECT_EQ(got[0].path, "hall.ot");
  got = received<aerie::map_cmd_t>(bus, "MAP_CMD", {"map", "load", "hall.bt"});
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].command, aerie::map_cmd_t::LOAD);
  EXPECT_EQ(got[0].path, "hall.bt");
  got = received<aerie::map_cmd_t>(bus, "MAP_CMD", {"map", "clear"});
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].command, aerie::map_cmd_t::CLEAR);
  EXPECT_EQ(got[0].path, "");
  got = received<aerie::map_cmd_t>(bus, "MAP_CMD", {"map", "publish"});
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].command, aerie::map_cmd_t::PUBLISH_FULL);
}

TEST(CmdBus, RefusalsSendNothing) {
  Bus bus("memq://");
  int sent = 0;
  bus.subscribe_raw(".*", [&](const uint8_t*, size_t, const ReceiveInfo&) { ++sent; });
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"track", "--box", "1,2,3"}, "aerie-cmd: --box '1,2,3': expected four numbers X,Y,W,H in pixels (X, Y >= 0; W, H > 0), got 3\n"},
      {{"track", "--box", "1,2,-3,4"}, "W = -3"},
      {{"track", "--box", "1,2,3,4", "--tracker", "kfc"}, "aerie-cmd: --tracker 'kfc': unknown tracker (known: "},
      {{"track"}, "aerie-cmd: track: --box X,Y,W,H is required to start tracking (or: track stop)\n"},
      {{"track", "stop", "--box", "1,2,3,4"}, "aerie-cmd: track stop: takes no --box or --tracker\n"},
      {{"track", "go"}, "aerie-cmd: track: unknown action 'go' (expected --box X,Y,W,H or stop)\n"},
      // Beyond aerie-track's own bound (track::kMaxBoxCoordinate): refused with the node's words.
      {{"track", "--box", "70000,2,3,4"}, "aerie-cmd: TRACK_CMD: INIT box x = 70000 is not a number of pixels in [-65536, 65536] (aerie-track would refuse it)\n"},
      {{"pilot"}, "aerie-cmd: pilot: a command is required (abort, land, resume or start)\n"},
      {{"pilot", "hover"}, "aerie-cmd: pilot: unknown command 'hover' (expected abort, land, resume or start)\n"},
      {{"map", "save", "../x.bt"}, "has a directory"},
      {{"map", "load"}, "aerie-cmd: map load: a file NAME is required (NAME.bt or NAME.ot)\n"},
      {{"map", "load", "x.png"}, "map: file name 'x.png' does not end in .bt or .ot"},
      {{"map", "clear", "x.bt"}, "aerie-cmd: map clear: takes no file name, got 'x.bt'\n"},
      {{"map", "erase"}, "aerie-cmd: map: unknown command 'erase' (expected save [NAME], load NAME, clear or publish)\n"},
      {{"map", "clear", "--wait-ack", "1"}, "--wait-ack"},
      {{"fly"}, "aerie-cmd: unknown sub-command 'fly' (expected track, pilot or map; see --help)\n"},
      {{"track", "--box", "1,2,3,4", "--bogus"}, "aerie-cmd track: "},
      {{"pilot", "abort", "--wait-ack", "-1"}, "aerie-cmd pilot: "}};
  for (const auto& [args, message] : cases) {
    const CliRun r = cli(bus, args);
    std::string line;
    for (const auto& a : args) line += a + " ";
    EXPECT_EQ(r.rc, 2) << line;
    EXPECT_NE(r.err.find(message), std::string::npos) << line << "-> " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << line << "-> one line: " << r.err;
    EXPECT_TRUE(r.out.empty()) << line << "-> " << r.out;
  }
  while (bus.handle(0) > 0) {
  }
  EXPECT_EQ(sent, 0);
}

TEST(CmdBus, PilotWaitAckSeesTheStateTheCommandLeadsTo) {
  Bus bus("memq://");
  // A pilot that answers ABORT with ABORT and anything else by staying in HOLD.
  bus.subscribe<aerie::pilot_cmd_t>("PILOT_CMD", [&](const aerie::pilot_cmd_t& c, const ReceiveInfo&) {
    aerie::pilot_state_t s{};
    s.seq = 41;
    s.state = aerie::pilot_state_t::HOLD;
    s.state_name = "HOLD";
    s.reason = "target lost for 10 frames";
    bus.publish("PILOT_STATE", s);
    if (c.command == aerie::pilot_cmd_t::ABORT) {
      s.seq = 42;
      s.state = aerie::pilot_state_t::ABORT;
      s.state_name = "ABORT";
      s.reason = "operator ABORT";
      bus.publish("PILOT_STATE", s);
    }
  });
  CliRun r = cli(bus, {"pilot", "abort", "--wait-ack", "5"});
  EXPECT_EQ(r.rc, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("took effect: PILOT_STATE seq 42: ABORT (operator ABORT)"), std::string::npos) << r.out;

  r = cli(bus, {"pilot", "land", "--wait-ack", "0.3"});
  EXPECT_EQ(r.rc, 1);
  EXPECT_NE(r.out.find("sent PILOT_CMD LAND"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("not seen to take effect within 0.3 s: 1 on PILOT_STATE, the last: PILOT_STATE seq 41: HOLD "
                       "(target lost for 10 frames)"),
            std::string::npos)
      << r.out;
}

TEST(CmdBus, TrackWaitAckWithoutANodeTimesOut) {
  Bus bus("memq://");
  const auto t0 = std::chrono::steady_clock::now();
  const CliRun r = cli(bus, {"track", "--box", "1,2,3,4", "--wait-ack", "0.2"});
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(r.rc, 1);
  EXPECT_NE(r.out.find("not seen to take effect within 0.2 s: no message on TRACK"), std::string::npos) << r.out;
  EXPECT_GE(s, 0.2);
}

namespace {

// An aerie-track node on the test's memq bus and a camera that keeps publishing a still scene
// on CAM_LEFT from another thread while the command line waits.
class CmdTrackNode : public ::testing::Test {
 protected:
  CmdTrackNode() : bus_("memq://"), scene_({240, 180}, {40, 32}) {
    motion_.centre = {100, 80};
    bus_.subscribe<aerie::track_t>("TRACK", [this](const aerie::track_t& m, const ReceiveInfo&) { tracks_.push_back(m); });
  }
  ~CmdTrackNode() override { stop_camera(); }
  void publish_frame() {
    const int i = frames_++;
    bus_.publish("CAM_LEFT", aerie::image::to_message(scene_.render(motion_), 1'000'000 + 50'000 * i, i));
  }
  void start_camera() {
    stop_ = false;
    camera_ = std::thread([this] {
      while (!stop_) {
        publish_frame();
        std::this_thread::sleep_for(std::chrono::milliseconds(40));
      }
    });
  }
  void stop_camera() {
    stop_ = true;
    if (camera_.joinable()) camera_.join();
  }
  void settle(aerie::track::TrackNode& node) {
    for (int round = 0; round < 3; ++round) {
      while (bus_.handle(0) > 0) {
      }
      ASSERT_TRUE(node.wait_idle(5000));
    }
    while (bus_.handle(0) > 0) {
    }
  }
  std::string box() const {
    const cv::Rect2d b = scene_.box(motion_);
    return std::to_string(b.x) + "," + std::to_string(b.y) + "," + std::to_string(b.width) + "," +
           std::to_string(b.height);
  }

  Bus bus_;
  aerie::track::test::Scene scene_;
  aerie::track::test::Motion motion_;
  std::vector<aerie::track_t> tracks_;
  std::atomic<int> frames_{0};
  std::atomic<bool> stop_{false};
  std::thread camera_;
};

}  // namespace

TEST_F(CmdTrackNode, TrackBoxStartsTheNodeTracking) {
  aerie::track::NodeOptions opt;  // CAM_LEFT, TRACK_CMD, TRACK
  aerie::track::TrackNode node(bus_, opt);
  publish_frame();
  settle(node);
  ASSERT_EQ(tracks_.size(), 1u);
  EXPECT_EQ(tracks_[0].status, aerie::track_t::IDLE);

  start_camera();
  const CliRun r = cli(bus_, {"track", "--box", box(), "--tracker", "amcmr-ct", "--wait-ack", "20"});
  stop_camera();
  settle(node);
  EXPECT_EQ(r.rc, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("sent TRACK_CMD INIT tracker=amcmr-ct camera=(node's) box=(80, 64, 40, 32)"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("took effect: TRACK seq "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(": TRACKING tracker=amcmr-ct camera=CAM_LEFT centre=(100, 80)"), std::string::npos) << r.out;
  // The node tracks the still target from then on, with the tracker asked for.
  const size_t before = tracks_.size();
  for (int i = 0; i < 5; ++i) {
    publish_frame();
    settle(node);
  }
  ASSERT_EQ(tracks_.size(), before + 5);
  const auto& last = tracks_.back();
  EXPECT_EQ(last.tracker, "amcmr-ct");
  EXPECT_TRUE(last.status == aerie::track_t::TRACKING || last.status == aerie::track_t::REDETECTED) << int(last.status);
  EXPECT_NEAR(last.x, motion_.centre.x, 3);
  EXPECT_NEAR(last.y, motion_.centre.y, 3);
  EXPECT_EQ(node.counter("command_errors"), 0);

  // And stops it.
  start_camera();
  const CliRun s = cli(bus_, {"track", "stop", "--wait-ack", "20"});
  stop_camera();
  settle(node);
  EXPECT_EQ(s.rc, 0) << s.out << s.err;
  EXPECT_NE(s.out.find("took effect: TRACK seq "), std::string::npos) << s.out;
  EXPECT_NE(s.out.find(": IDLE tracker="), std::string::npos) << s.out;
  EXPECT_EQ(tracks_.back().status, aerie::track_t::IDLE);
}

TEST_F(CmdTrackNode, ACommandForAnotherCameraIsSeenNotToTakeEffect) {
  aerie::track::NodeOptions opt;
  aerie::track::TrackNode node(bus_, opt);
  publish_frame();
  settle(node);
  start_camera();
  const CliRun r = cli(bus_, {"track", "--box", box(), "--camera", "CAM_DOWN", "--wait-ack", "1"});
  stop_camera();
  settle(node);
  EXPECT_EQ(r.rc, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("not seen to take effect within 1 s: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("the last: TRACK seq"), std::string::npos) << r.out;
  EXPECT_EQ(node.counter("command_errors"), 1);  // "command for camera CAM_DOWN, this tracker follows CAM_LEFT"
  EXPECT_EQ(tracks_.back().status, aerie::track_t::IDLE);
}
