// aerie-track's node logic over memq://: frames and commands in, TRACK / TARGET_POSE out.
#include <gtest/gtest.h>

#include <aerie/target_pose_t.hpp>

#include "air/track/node/track_node.hpp"
#include "common/image/image_message.hpp"
#include "air/track/factory.hpp"
#include "tests/air/track/synthetic.hpp"
#include "tests/common/bus/reliability_data.hpp"
#include "tests/support/test_support.hpp"

#include <opencv2/imgproc.hpp>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <tuple>

using namespace aerie::track;
using aerie::track::test::Motion;
using aerie::track::test::Scene;

namespace {

class NodeTest : public ::testing::Test {
 protected:
  NodeTest() : bus_("memq://"), scene_({240, 180}, {40, 32}) {
    bus_.subscribe<aerie::track_t>("TRACK", [this](const aerie::track_t& m, const aerie::bus::ReceiveInfo&) {
      tracks_.push_back(m);
    });
    bus_.subscribe<aerie::target_pose_t>("TARGET_POSE", [this](const aerie::target_pose_t& m,
                                                               const aerie::bus::ReceiveInfo&) { poses_.push_back(m); });
  }
  // Delivers everything published so far, lets the worker finish, delivers its output.
  void settle(TrackNode& node) {
    for (int round = 0; round < 3; ++round) {
      while (bus_.handle(0) > 0) {
      }
      ASSERT_TRUE(node.wait_idle(5000));
    }
    while (bus_.handle(0) > 0) {
    }
  }
  Motion motion(int i) const {
    Motion m;
    m.centre = {80 + 2.0 * i, 90 + 1.0 * i};
    return m;
  }
  aerie::image_t frame(int i) const {
    return aerie::image::to_message(scene_.render(motion(i)), 1'000'000 + 33'333 * i, i);
  }
  // INIT with the box; a parameter override (search_radius 16) unless the tracker has none.
  void send_init(const cv::Rect2d& box, const std::string& tracker = "", bool search_radius = true) {
    aerie::track_cmd_t c{};
    c.command = aerie::track_cmd_t::INIT;
    c.tracker = tracker;
    c.x = box.x, c.y = box.y, c.width = box.width, c.height = box.height;
    if (search_radius) {
      c.nparams = 1;
      c.param_names = {"search_radius"};
      c.param_values = {"16"};
    }
    bus_.publish("TRACK_CMD", c);
  }

  aerie::bus::Bus bus_;
  Scene scene_;
  std::vector<aerie::track_t> tracks_;
  std::vector<aerie::target_pose_t> poses_;
};

}  // namespace

TEST_F(NodeTest, InitThenTracksEveryFrameWithTheSourceUtime) {
  NodeOptions opt;
  opt.target.width_m = 0.8;  // the 40 x 32 px target is 0.8 x 0.64 m
  opt.target.height_m = 0.64;
  opt.camera = aerie::camera::CameraModel{};
  opt.camera->fx = opt.camera->fy = 200;
  opt.camera->cx = 120, opt.camera->cy = 90;
  TrackNode node(bus_, opt);

  bus_.publish("CAM_LEFT", frame(0));
  settle(node);
  ASSERT_EQ(tracks_.size(), 1u);
  EXPECT_EQ(tracks_[0].status, aerie::track_t::IDLE);  // no target yet

  send_init(scene_.box(motion(0)), "amcmr-ct");  // INIT uses the newest frame: frame 0
  settle(node);
  for (int i = 1; i <= 15; ++i) {
    bus_.publish("CAM_LEFT", frame(i));
    settle(node);
  }
  ASSERT_EQ(tracks_.size(), 16u);
  for (size_t k = 1; k < tracks_.size(); ++k) {
    const auto& t = tracks_[k];
    EXPECT_EQ(t.utime, 1'000'000 + 33'333 * static_cast<int64_t>(k));
    EXPECT_EQ(t.tracker, "amcmr-ct");
    EXPECT_EQ(t.camera, "CAM_LEFT");
    EXPECT_NE(t.status, aerie::track_t::IDLE);
  }
  const auto& last = tracks_.back();
  const Motion truth = motion(15);
  EXPECT_NEAR(last.x, truth.centre.x, 4);
  EXPECT_NEAR(last.y, truth.centre.y, 4);
  ASSERT_GE(last.nlevels, 1);
  EXPECT_GT(last.levels[0].evaluated, 0);
  EXPECT_EQ(last.levels[0].npoints, static_cast<int>(last.levels[0].u.size()));
  EXPECT_LE(last.levels[0].npoints, 200);
  // TARGET_POSE for every tracked frame: a 0.8 m target 40 px wide at f = 200 px is 4 m away
  ASSERT_EQ(poses_.size(), 15u);
  EXPECT_EQ(poses_.back().utime, last.utime);
  EXPECT_NEAR(poses_.back().position[2], 200 * 0.8 / last.width, 1e-6);
  EXPECT_NEAR(poses_.back().position[2], 4.0, 0.4);  // the target keeps its size
  EXPECT_NEAR(poses_.back().position[0], (last.x - 120) / 200 * poses_.back().position[2], 1e-6);
  EXPECT_EQ(node.counter("frames_received"), 16);  // frame 0 came before the INIT
  EXPECT_EQ(node.counter("frames_processed") + node.counter("frames_skipped") + 1, node.counter("frames_received"));
}

// Replay (--replay): frames delivered faster than the tracker runs are all tracked, in order,
// with the same boxes as when they come one at a time.
TEST_F(NodeTest, EveryFrameModeTracksABurstInOrderAsOneAtATime) {
  auto fly = [&](bool burst) {
    aerie::bus::Bus bus("memq://");  // one bus per node: a node's subscriptions live as long as its bus
    std::vector<aerie::track_t> tracks;
    bus.subscribe<aerie::track_t>("TRACK", [&](const aerie::track_t& m, const aerie::bus::ReceiveInfo&) { tracks.push_back(m); });
    NodeOptions opt;
    opt.every_frame = true;
    TrackNode node(bus, opt);
    auto settle_bus = [&] {
      for (int round = 0; round < 3; ++round) {
        while (bus.handle(0) > 0) {
        }
        EXPECT_TRUE(node.wait_idle(5000));
      }
      while (bus.handle(0) > 0) {
      }
    };
    bus.publish("CAM_LEFT", frame(0));
    settle_bus();
    aerie::track_cmd_t c{};
    c.command = aerie::track_cmd_t::INIT;
    c.tracker = "amcmr-ct";
    const cv::Rect2d box = scene_.box(motion(0));
    c.x = box.x, c.y = box.y, c.width = box.width, c.height = box.height;
    bus.publish("TRACK_CMD", c);
    settle_bus();
    for (int i = 1; i <= 40; ++i) {
      bus.publish("CAM_LEFT", frame(i));
      if (!burst) settle_bus();
    }
    settle_bus();
    EXPECT_EQ(node.counter("frames_skipped"), 0);
    return tracks;
  };
  const auto paced = fly(false), burst = fly(true);
  ASSERT_EQ(paced.size(), 41u);
  ASSERT_EQ(burst.size(), 41u);
  for (size_t k = 0; k < burst.size(); ++k) {
    EXPECT_EQ(burst[k].utime, 1'000'000 + 33'333 * static_cast<int64_t>(k));
    EXPECT_EQ(burst[k].x, paced[k].x) << k;
    EXPECT_EQ(burst[k].y, paced[k].y) << k;
  }
}

// The correlation-filter tracker chosen by an INIT command, with its own parameter.
TEST_F(NodeTest, DcfChosenByTheInitCommand) {
  TrackNode node(bus_, NodeOptions{});
  bus_.publish("CAM_LEFT", frame(0));
  settle(node);
  send_init(scene_.box(motion(0)), "dcf", false);
  settle(node);
  for (int i = 1; i <= 10; ++i) {
    bus_.publish("CAM_LEFT", frame(i));
    settle(node);
  }
  ASSERT_EQ(tracks_.size(), 11u);
  const auto& last = tracks_.back();
  EXPECT_EQ(last.tracker, "dcf");
  EXPECT_NE(last.status, aerie::track_t::IDLE);
  EXPECT_NEAR(last.x, motion(10).centre.x, 3);
  EXPECT_NEAR(last.y, motion(10).centre.y, 3);
  EXPECT_EQ(node.counter("command_errors"), 0);
}

TEST_F(NodeTest, BadMessagesAndCommandsAreCountedNotFatal) {
  TrackNode node(bus_, NodeOptions{});
  aerie::bus::StatusReporter status(bus_, "track");
  const uint8_t junk[5] = {1, 2, 3, 4, 5};
  bus_.publish_raw("CAM_LEFT", junk, sizeof(junk));  // not an image_t
  aerie::image_t bad = frame(0);
  bad.size = 10;
  bad.data.resize(10);  // inconsistent payload: decodes as an error
  bus_.publish("CAM_LEFT", bad);
  settle(node);
  send_init({10, 10, 30, 30}, "no-such-tracker");
  bus_.publish("CAM_LEFT", frame(1));
  settle(node);
  send_init({230, 10, 30, 30});  // outside the 240x180 image
  aerie::track_cmd_t reset{};
  reset.command = aerie::track_cmd_t::RESET;  // nothing to reset
  bus_.publish("TRACK_CMD", reset);
  bus_.publish("CAM_LEFT", frame(2));
  settle(node);
  EXPECT_EQ(node.counter("decode_errors"), 1);
  EXPECT_EQ(node.counter("command_errors"), 3);
  EXPECT_EQ(bus_.subscriptions()[2]->counters().malformed, 1);  // CAM_LEFT subscription
  node.report(status);
  EXPECT_EQ(status.counter("command_errors"), 3);
  // still alive: a good INIT tracks, STOP returns to IDLE
  send_init(scene_.box(motion(3)), "amcmr-ct");
  bus_.publish("CAM_LEFT", frame(3));
  settle(node);
  bus_.publish("CAM_LEFT", frame(4));
  settle(node);
  EXPECT_EQ(tracks_.back().status, aerie::track_t::TRACKING);
  EXPECT_EQ(tracks_.back().tracker, "amcmr-ct");
  aerie::track_cmd_t stop{};
  stop.command = aerie::track_cmd_t::STOP;
  bus_.publish("TRACK_CMD", stop);
  bus_.publish("CAM_LEFT", frame(5));
  settle(node);
  EXPECT_EQ(tracks_.back().status, aerie::track_t::IDLE);
}

TEST_F(NodeTest, StereoLeftImageAndInitFromGroundTruth) {
  NodeOptions opt;
  opt.camera_channel = "CAM_STEREO";
  opt.stereo = true;
  opt.init_from_gt = 2;
  opt.tracker = "ct";
  opt.target.width_m = opt.target.height_m = 1.0;
  TrackNode node(bus_, opt);
  for (int i = 0; i < 6; ++i) {
    const cv::Rect2d box = scene_.box(motion(i));
    aerie::gt_box_t gt{};
    gt.utime = 1'000'000 + 33'333 * i;
    gt.target = "helipad";
    gt.visible = true;
    gt.x = box.x, gt.y = box.y, gt.width = box.width, gt.height = box.height;
    bus_.publish("GT_TRACK", gt);
    aerie::stereo_image_t st{};
    st.utime = gt.utime;
    st.seq = i;
    st.left = frame(i);
    st.right = frame(i);
    st.fx = st.fy = 300, st.cx = 120, st.cy = 90, st.baseline_m = 0.1;
    bus_.publish("CAM_STEREO", st);
    settle(node);
  }
  ASSERT_EQ(tracks_.size(), 6u);
  EXPECT_EQ(tracks_[1].status, aerie::track_t::IDLE);
  EXPECT_EQ(tracks_[2].status, aerie::track_t::TRACKING);  // 2 frames seen: initialised on the third
  EXPECT_EQ(tracks_[2].tracker, "ct");
  EXPECT_NEAR(tracks_[2].x, motion(2).centre.x, 1e-9);
  EXPECT_NEAR(tracks_.back().x, motion(5).centre.x, 3);
  ASSERT_FALSE(poses_.empty());  // intrinsics from the stereo message
  EXPECT_NEAR(poses_.back().position[2], 300.0 * 1.0 / std::sqrt(tracks_.back().width * tracks_.back().height), 1e-6);
}

TEST(NodeOptions, ReadsTheYamlSectionsAndRejectsBadValues) {
  const auto cfg = aerie::util::Config::parse(R"(
node: {camera_channel: CAM_MONO, tracker: am3, max_points: 50}
target: {name: helipad, width_m: 1.2}
camera: {fx: 400, cx: 320, cy: 240}
trackers: {am3: {search_radius: 24}}
)",
                                              "track.yaml");
  const NodeOptions o = node_options(cfg);
  EXPECT_EQ(o.camera_channel, "CAM_MONO");
  EXPECT_EQ(o.tracker, "am3");
  EXPECT_EQ(o.max_points, 50);
  EXPECT_EQ(o.target_name, "helipad");
  EXPECT_DOUBLE_EQ(o.target.height_m, 1.2);
  ASSERT_TRUE(o.camera.has_value());
  EXPECT_DOUBLE_EQ(o.camera->fy, 400);
  EXPECT_EQ(o.trackers.section("am3").get("search_radius", 0), 24);
  EXPECT_THROW(node_options(aerie::util::Config::parse("node: {tracker: kcf}")), std::runtime_error);
  EXPECT_THROW(node_options(aerie::util::Config::parse("target: {width_m: -1}")), std::runtime_error);
}

TEST(NodeOptions, TheShippedConfigIsValidForEveryTracker) {
  const auto cfg = aerie::util::Config::load((aerie::test::source_dir() / "config" / "track.yaml").string());
  const NodeOptions o = node_options(cfg);
  EXPECT_EQ(o.camera_channel, "CAM_LEFT");
  for (const auto& name : aerie_tracker_names()) EXPECT_NO_THROW(make_tracker(name, o.trackers.section(name))) << name;
}

TEST(NodeOptions, RefusesUnknownKeysSectionsAndBadTrackerParametersAtStartUp) {
  const auto load = [](const std::string& text) { node_options(aerie::util::Config::parse(text, "track.yaml")); };
  const std::vector<std::pair<std::string, std::string>> cases{
      {"node:\n  trackr: ct\n", "track.yaml: unknown key 'node.trackr' (line 2"},
      {"target: 5\n", "'target' is a section of keys, not a value (line 1)"},
      {"- node: {}\n", "expected a map of keys, not a list (line 1)"},
      {"node: {max_points: -1}\n", "'max_points' = -1 is outside its valid range [0, 100000]"},
      {"target: {width_m: 1e308}\n", "'width_m' = 1e+308 is outside its valid range [0, 1000]"},
      {"camera: {fx: 400, cx: 1, cy: 1, width: 100000}\n", "'width' = 100000 is outside"},
      // Tracker sections are checked now, not at the first INIT.
      {"trackers:\n  kcf: {}\n", "trackers.kcf: unknown tracker (line 2)"},
      {"trackers:\n  dcf: {template_area: 1e9}\n", "'template_area' = 1e+09 is outside its valid range [64, 1.04858e+06]"},
      {"trackers:\n  ct: {features: 10000000}\n", "'features' = 10000000 is outside its valid range [1, 10000]"},
      {"trackers:\n  mil: {featurs: 10}\n", "unknown parameter 'featurs' for tracker 'mil'"},
  };
  aerie::test::expect_refusals(load, cases);
  for (const char* shipped : {"track.yaml", "track_landing.yaml"})
    EXPECT_NO_THROW(node_options(aerie::util::Config::load((aerie::test::source_dir() / "config" / shipped).string())))
        << shipped;
}

TEST_F(NodeTest, OversizedOverridesAreRefusedAndTrackingGoesOn) {
  // TRACK_CMD overrides template_area=1e9 and features=1e7 stalled tracking for tens of seconds.
  TrackNode node(bus_, NodeOptions{});
  bus_.publish("CAM_LEFT", frame(0));
  settle(node);
  send_init(scene_.box(motion(0)), "amcmr-ct");
  bus_.publish("CAM_LEFT", frame(1));
  settle(node);
  for (const auto& [tracker, name, value] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {"dcf", "template_area", "1e9"}, {"amcmr-ct", "features", "10000000"}}) {
    aerie::track_cmd_t c{};
    c.command = aerie::track_cmd_t::SET_TRACKER;
    c.tracker = tracker;
    c.nparams = 1;
    c.param_names = {name};
    c.param_values = {value};
    bus_.publish("TRACK_CMD", c);
  }
  bus_.publish("CAM_LEFT", frame(2));
  settle(node);
  EXPECT_EQ(node.counter("command_errors"), 2);
  aerie::bus::StatusReporter status(bus_, "track");
  node.report(status);
  EXPECT_NE(status.message().find("'features' = 10000000 is outside its valid range"), std::string::npos)
      << status.message();
  EXPECT_EQ(tracks_.back().status, aerie::track_t::TRACKING);
  EXPECT_EQ(tracks_.back().tracker, "amcmr-ct");
}

TEST_F(NodeTest, AFrameOfAnotherSizeEndsTheTrackWithAReason) {
  TrackNode node(bus_, NodeOptions{});
  aerie::bus::StatusReporter status(bus_, "track");
  bus_.publish("CAM_LEFT", frame(0));
  settle(node);
  send_init(scene_.box(motion(0)), "amcmr-ct");
  bus_.publish("CAM_LEFT", frame(1));
  settle(node);
  ASSERT_EQ(tracks_.back().status, aerie::track_t::TRACKING);
  cv::Mat small;
  cv::resize(scene_.render(motion(2)), small, {120, 90});
  bus_.publish("CAM_LEFT", aerie::image::to_message(small, 2'000'000, 2));
  settle(node);
  EXPECT_EQ(tracks_.back().status, aerie::track_t::IDLE);  // the pilot sees the track end at once
  EXPECT_EQ(tracks_.back().utime, 2'000'000);
  EXPECT_EQ(node.counter("frame_size_changes"), 1);
  node.report(status);
  EXPECT_NE(status.message().find("frame size changed from 240x180 to 120x90; track of amcmr-ct ended"),
            std::string::npos) << status.message();
  // A new INIT on the new size tracks again.
  send_init({40, 40, 20, 16}, "amcmr-ct");
  bus_.publish("CAM_LEFT", aerie::image::to_message(small, 2'100'000, 3));
  settle(node);
  bus_.publish("CAM_LEFT", aerie::image::to_message(small, 2'200'000, 4));
  settle(node);
  EXPECT_EQ(tracks_.back().status, aerie::track_t::TRACKING);
}

TEST_F(NodeTest, APngBombIsRefusedBeforeDecoding) {
  // 249 KB of PNG declaring 16000 x 16000 (256 MB decoded): refused by its declared size.
  TrackNode node(bus_, NodeOptions{});
  aerie::bus::StatusReporter status(bus_, "track");
  const auto payload = aerie::test::read_bytes(aerie::test::reliability_data_dir() / "cam_left_png_bomb_16000x16000.bin");
  bus_.publish_raw("CAM_LEFT", payload.data(), static_cast<unsigned>(payload.size()));
  settle(node);
  EXPECT_EQ(node.counter("decode_errors"), 1);
  node.report(status);
  EXPECT_NE(status.message().find("16000x16000 is larger than the limit of 16777216 pixels"), std::string::npos)
      << status.message();
  // With a configured camera, the cap is its size: a larger frame is refused, the camera's size tracks.
  NodeOptions opt;
  opt.camera = aerie::camera::CameraModel{};
  opt.camera->width = 240, opt.camera->height = 180;
  TrackNode capped(bus_, opt);
  cv::Mat big;
  cv::resize(scene_.render(motion(0)), big, {480, 360});
  bus_.publish("CAM_LEFT", aerie::image::to_message(big, 1'000'000, 0, aerie::image::Encoding::Png));
  settle(capped);
  EXPECT_EQ(capped.counter("decode_errors"), 1);
  bus_.publish("CAM_LEFT", aerie::image::to_message(scene_.render(motion(1)), 1'100'000, 1, aerie::image::Encoding::Png));
  settle(capped);
  EXPECT_EQ(capped.counter("decode_errors"), 1);
}

// Issue 20: while the camera was down aerie-track kept health OK. Lock-step: the node clock
// moves 33 ms a frame; 25 s without frames; the camera comes back 25 s later in utime.
TEST_F(NodeTest, ACameraOutageIsReportedAndTrackingGoesOnAfterIt) {
  int64_t now = 1'000'000'000;
  TrackNode node(bus_, NodeOptions{}, [&] { return now; });
  aerie::bus::StatusReporter status(bus_, "track");
  auto send = [&](int i, int64_t shift_us) {
    aerie::image_t m = frame(i);
    m.utime += shift_us;
    bus_.publish("CAM_LEFT", m);
    settle(node);
    now += 33'333;
    node.report(status);
    return m.utime;
  };
  send(0, 0);
  send_init(scene_.box(motion(0)), "amcmr-ct");
  settle(node);
  for (int i = 1; i <= 5; ++i) send(i, 0);
  EXPECT_EQ(tracks_.back().status, aerie::track_t::TRACKING);
  EXPECT_EQ(status.counter("CAM_LEFT.stale"), 0);
  EXPECT_EQ(status.message(), "tracking with amcmr-ct");

  for (int k = 0; k < 250; ++k, now += 100'000) node.report(status);
  EXPECT_EQ(status.counter("CAM_LEFT.stale"), 1);
  EXPECT_EQ(status.counter("CAM_LEFT.outages"), 1);
  EXPECT_EQ(status.message().rfind("CAM_LEFT stale: no message for 2.", 0), 0u) << status.message();

  // Back 25 s later: 2 frames held (nothing published for them), then tracked with their utime.
  const size_t before = tracks_.size();
  send(6, 25'000'000);
  send(7, 25'000'000);
  EXPECT_EQ(tracks_.size(), before);
  EXPECT_EQ(status.counter("CAM_LEFT.time_jumps"), 2);
  for (int i = 8; i <= 12; ++i) {
    const int64_t utime = send(i, 25'000'000);
    ASSERT_FALSE(tracks_.empty());
    EXPECT_EQ(tracks_.back().utime, utime);
  }
  EXPECT_EQ(tracks_.back().status, aerie::track_t::TRACKING);
  EXPECT_NEAR(tracks_.back().x, motion(12).centre.x, 4);
  EXPECT_EQ(status.counter("CAM_LEFT.time_resyncs"), 1);
  EXPECT_EQ(status.counter("CAM_LEFT.stale"), 0);
  EXPECT_EQ(status.message(), "tracking with amcmr-ct");

  // A frame stamped INT64_MAX is held: no TRACK or TARGET_POSE carries that time.
  aerie::image_t bogus = frame(13);
  bogus.utime = std::numeric_limits<int64_t>::max();
  bus_.publish("CAM_LEFT", bogus);
  settle(node);
  send(14, 25'000'000);
  for (const auto& t : tracks_) EXPECT_NE(t.utime, std::numeric_limits<int64_t>::max());
  EXPECT_EQ(status.counter("CAM_LEFT.time_jumps"), 3);
  EXPECT_EQ(tracks_.back().status, aerie::track_t::TRACKING);
}

// The default tracker (an INIT that names none) is eco, the accurate tracker that runs at
// air-side speed (docs/track.md "Which to fly").
TEST_F(NodeTest, TheDefaultTrackerIsEco) {
  TrackNode node(bus_, NodeOptions{});
  bus_.publish("CAM_LEFT", frame(0));
  settle(node);
  send_init(scene_.box(motion(0)), "", false);
  for (int i = 1; i <= 3; ++i) {
    bus_.publish("CAM_LEFT", frame(i));
    settle(node);
  }
  ASSERT_FALSE(tracks_.empty());
  EXPECT_EQ(tracks_.back().tracker, "eco");
  EXPECT_EQ(tracks_.back().status, aerie::track_t::TRACKING);
}

// Issue 46: 8 MB TRACK_CMD INITs queued before the first frame grew the tracker from 55 to
// 157 MB. Before the first frame only the newest INIT waits; the others are superseded.
TEST_F(NodeTest, OnlyTheNewestInitWaitsForTheFirstFrame) {
  TrackNode node(bus_, NodeOptions{});
  const int kInits = 40;
  for (int i = 0; i < kInits; ++i) {
    send_init(cv::Rect2d(20 + i, 30, 40, 32), "amcmr-ct");
    while (bus_.handle(0) > 0) {
    }
  }
  settle(node);
  EXPECT_EQ(node.counter("commands"), kInits);
  // Superseded by the worker, or dropped from its queue when it had not run yet: one is left.
  EXPECT_EQ(node.counter("commands_dropped.superseded") + node.counter("commands_dropped.queue_full"), kInits - 1);
  EXPECT_GE(node.counter("commands_dropped.superseded"), 1);
  bus_.publish("CAM_LEFT", frame(0));
  settle(node);
  ASSERT_EQ(tracks_.size(), 1u);
  EXPECT_EQ(tracks_[0].status, aerie::track_t::TRACKING);
  EXPECT_DOUBLE_EQ(tracks_[0].x, 20 + (kInits - 1) + 20.0);  // the centre of the last INIT's box
  EXPECT_DOUBLE_EQ(tracks_[0].y, 30 + 16.0);
  EXPECT_EQ(node.counter("command_errors"), 0);
}

TEST_F(NodeTest, AStopBeforeTheFirstFrameCancelsTheWaitingInit) {
  TrackNode node(bus_, NodeOptions{});
  send_init(scene_.box(motion(0)), "amcmr-ct");
  settle(node);
  aerie::track_cmd_t stop{};
  stop.command = aerie::track_cmd_t::STOP;
  bus_.publish("TRACK_CMD", stop);
  settle(node);
  bus_.publish("CAM_LEFT", frame(0));
  settle(node);
  ASSERT_EQ(tracks_.size(), 1u);
  EXPECT_EQ(tracks_[0].status, aerie::track_t::IDLE);  // the INIT was superseded by the STOP
  EXPECT_EQ(node.counter("commands_dropped.superseded"), 1);
  EXPECT_EQ(node.counter("command_errors"), 0);
}

TEST_F(NodeTest, OversizedCommandsAreRefusedOnArrivalNamingTheField) {
  TrackNode node(bus_, NodeOptions{});
  aerie::bus::StatusReporter status(bus_, "track");
  bus_.publish("CAM_LEFT", frame(0));
  settle(node);
  const cv::Rect2d box = scene_.box(motion(0));
  auto init = [&] {
    aerie::track_cmd_t c{};
    c.command = aerie::track_cmd_t::INIT;
    c.tracker = "amcmr-ct";
    c.x = box.x, c.y = box.y, c.width = box.width, c.height = box.height;
    return c;
  };
  auto with_params = [&](int n, size_t value_size) {
    aerie::track_cmd_t c = init();
    c.nparams = n;
    for (int i = 0; i < n; ++i) {
      c.param_names.push_back("p" + std::to_string(i));
      c.param_values.push_back(std::string(value_size, '1'));
    }
    return c;
  };
  struct Case {
    aerie::track_cmd_t cmd;
    std::string reason, message;
  };
  std::vector<Case> cases;
  {
    aerie::track_cmd_t c = init();
    c.nparams = 1;
    c.param_names = {"search_radius"};
    c.param_values = {std::string(size_t{8} << 20, '1')};  // the issue's 8 MB INIT
    cases.push_back({c, "too_large", "param_values[0] ('search_radius') of 8388608 characters (at most 1024)"});
  }
  cases.push_back({with_params(1000, 1), "too_large", "nparams = 1000 (at most 64 parameter overrides)"});
  {
    aerie::track_cmd_t c = init();
    c.tracker = std::string(100, 'x');
    cases.push_back({c, "too_large", "tracker name of 100 characters (at most 64)"});
  }
  {
    aerie::track_cmd_t c = init();
    c.camera = std::string(300, 'C');
    cases.push_back({c, "too_large", "camera of 300 characters (at most 256)"});
  }
  cases.push_back({with_params(64, 1024), "too_large", "bytes encoded (at most 65536)"});
  {
    aerie::track_cmd_t c = init();
    c.width = std::nan("");
    cases.push_back({c, "bad_box", "INIT box width = nan is not a number of pixels in [-65536, 65536]"});
  }
  {
    aerie::track_cmd_t c = init();
    c.x = 1e300;
    cases.push_back({c, "bad_box", "INIT box x = 1e+300 is not a number of pixels"});
  }
  std::map<std::string, int64_t> expected;
  for (const auto& c : cases) {
    bus_.publish("TRACK_CMD", c.cmd);
    settle(node);
    node.report(status);
    EXPECT_NE(status.message().find(c.message), std::string::npos) << status.message();
    EXPECT_NE(status.message().find("refused"), std::string::npos) << status.message();
    EXPECT_EQ(node.counter("commands_refused." + c.reason), ++expected[c.reason]) << c.message;
  }
  EXPECT_EQ(node.counter("commands"), static_cast<int64_t>(cases.size()));
  EXPECT_EQ(node.counter("command_errors"), 0);  // refused on arrival: none reached the tracker
  bus_.publish("CAM_LEFT", frame(1));
  settle(node);
  EXPECT_EQ(tracks_.back().status, aerie::track_t::IDLE);
  // A command at the limits is accepted and tracks.
  aerie::track_cmd_t ok = init();
  ok.nparams = 1;
  ok.param_names = {"search_radius"};
  ok.param_values = {"16" + std::string(kMaxCommandValue - 2, ' ')};  // YAML: trailing spaces
  bus_.publish("TRACK_CMD", ok);
  settle(node);
  bus_.publish("CAM_LEFT", frame(2));
  settle(node);
  EXPECT_EQ(node.counter("command_errors"), 0);
  EXPECT_EQ(tracks_.back().status, aerie::track_t::TRACKING);
  EXPECT_EQ(tracks_.back().tracker, "amcmr-ct");
}

TEST(NodeOptions, CommandQueueBoundsAreReadAndRanged) {
  const NodeOptions o = node_options(aerie::util::Config::parse("node: {max_queued_commands: 5, max_queued_bytes: 131072}\n", "t.yaml"));
  EXPECT_EQ(o.max_queued_commands, 5);
  EXPECT_EQ(o.max_queued_bytes, 131072);
  EXPECT_EQ(NodeOptions{}.max_queued_commands, 32);
  EXPECT_THROW(node_options(aerie::util::Config::parse("node: {max_queued_commands: 0}\n", "t.yaml")), std::runtime_error);
  EXPECT_THROW(node_options(aerie::util::Config::parse("node: {max_queued_bytes: 1000000000}\n", "t.yaml")), std::runtime_error);
}

// IPSL's counts had no upper bound (particles, ipsl.cpp): a TRACK_CMD override beyond the
// documented range is refused and the current track goes on.
TEST_F(NodeTest, IpslCountsOverriddenByACommandAreBounded) {
  if (!is_known_tracker("ipsl")) GTEST_SKIP() << "ipsl is not built";
  TrackNode node(bus_, NodeOptions{});
  aerie::bus::StatusReporter status(bus_, "track");
  bus_.publish("CAM_LEFT", frame(0));
  settle(node);
  send_init(scene_.box(motion(0)), "amcmr-ct");
  bus_.publish("CAM_LEFT", frame(1));
  settle(node);
  for (const auto& [tracker, name, value, message] :
       std::vector<std::tuple<std::string, std::string, std::string, std::string>>{
           {"ipsl", "particles", "6000", "particles = 6000 is outside [1, 5000]"},
           {"ipsl-mr", "max_levels", "100", "max_levels = 100 is outside [1, 8]"},
           {"ipsl", "block_size", "100000", "block_size = 100000 is outside [1, 256]"}}) {
    aerie::track_cmd_t c{};
    c.command = aerie::track_cmd_t::SET_TRACKER;
    c.tracker = tracker;
    c.nparams = 1;
    c.param_names = {name};
    c.param_values = {value};
    bus_.publish("TRACK_CMD", c);
    settle(node);
    node.report(status);
    EXPECT_NE(status.message().find(message), std::string::npos) << status.message();
  }
  EXPECT_EQ(node.counter("command_errors"), 3);
  bus_.publish("CAM_LEFT", frame(2));
  settle(node);
  EXPECT_EQ(tracks_.back().status, aerie::track_t::TRACKING);
  EXPECT_EQ(tracks_.back().tracker, "amcmr-ct");
}

// Issue 49: an INIT waited forever, silently, when the camera published on another channel
// (CAM_MONO) than the node's (CAM_LEFT). After init_wait_warn_s the node warns once and says
// in status which channels carry images; the probe that learns them is gone once frames come.
TEST_F(NodeTest, AnInitWithoutFramesWarnsOnceNamingTheChannelsThatCarryImages) {
  int64_t now = 1'000'000'000;
  const size_t subscriptions = bus_.subscriptions().size();
  TrackNode node(bus_, NodeOptions{}, [&] { return now; });
  const size_t node_subscriptions = bus_.subscriptions().size();
  aerie::bus::StatusReporter status(bus_, "track");
  aerie::track_cmd_t init{};
  init.command = aerie::track_cmd_t::INIT;
  init.seq = 7;
  init.tracker = "amcmr-ct";
  const cv::Rect2d box = scene_.box(motion(0));
  init.x = box.x, init.y = box.y, init.width = box.width, init.height = box.height;
  bus_.publish("TRACK_CMD", init);
  settle(node);
  node.report(status);  // the wait is seen: the probe listens
  EXPECT_EQ(bus_.subscriptions().size(), node_subscriptions + 1);
  EXPECT_EQ(status.message(), "idle");

  bus_.publish("CAM_MONO", frame(0));
  aerie::stereo_image_t st{};
  st.left = st.right = frame(0);
  bus_.publish("CAM_STEREO", st);
  aerie::gt_box_t gt{};  // not an image
  bus_.publish("GT_TRACK", gt);
  settle(node);
  now += 2'900'000;
  node.report(status);
  EXPECT_EQ(status.counter("init_waits_without_frames"), 0);
  EXPECT_EQ(status.message(), "idle");

  now += 200'000;
  node.report(status);
  EXPECT_EQ(status.counter("init_waits_without_frames"), 1);
  EXPECT_EQ(status.message(),
            "INIT seq 7 waits: no frame on CAM_LEFT (image_t) for 3.1 s; images are on CAM_MONO (image_t), "
            "CAM_STEREO (stereo_image_t): start aerie-track with --camera CHANNEL (and --stereo for stereo_image_t)");
  now += 5'000'000;
  node.report(status);
  EXPECT_EQ(status.counter("init_waits_without_frames"), 1);  // warned once, still in status
  EXPECT_EQ(status.message().rfind("INIT seq 7 waits: no frame on CAM_LEFT (image_t) for 8.1 s;", 0), 0u)
      << status.message();

  // A frame comes: the INIT runs, the warning and the probe go.
  bus_.publish("CAM_LEFT", frame(0));
  settle(node);
  node.report(status);
  ASSERT_EQ(tracks_.size(), 1u);
  EXPECT_EQ(tracks_[0].status, aerie::track_t::TRACKING);
  EXPECT_EQ(status.message(), "tracking with amcmr-ct");
  EXPECT_EQ(bus_.subscriptions().size(), node_subscriptions);
  EXPECT_GT(node_subscriptions, subscriptions);
}

TEST_F(NodeTest, AnInitWithoutFramesAndNoImagesAnywhereSaysSo) {
  int64_t now = 1'000'000'000;
  NodeOptions opt;
  opt.init_wait_warn_s = 1.0;
  TrackNode node(bus_, opt, [&] { return now; });
  aerie::bus::StatusReporter status(bus_, "track");
  send_init(scene_.box(motion(0)), "amcmr-ct");
  settle(node);
  node.report(status);
  now += 1'000'000;
  node.report(status);
  EXPECT_EQ(status.counter("init_waits_without_frames"), 1);
  EXPECT_EQ(status.message(),
            "INIT seq 0 waits: no frame on CAM_LEFT (image_t) for 1.0 s; no channel carries images (is the camera running?)");
  // A STOP cancels the wait: the warning goes.
  aerie::track_cmd_t stop{};
  stop.command = aerie::track_cmd_t::STOP;
  bus_.publish("TRACK_CMD", stop);
  settle(node);
  node.report(status);
  EXPECT_EQ(status.message(), "idle");
}
