// aerie-vo's node class over memq://: stereo pairs in, VO_POSE / VO_DEPTH out; refused and
// malformed inputs are counted and never stop it.
#include <gtest/gtest.h>

#include <aerie/pose_t.hpp>
#include <aerie/spherical_depth_t.hpp>

#include <opencv2/imgproc.hpp>

#include <limits>
#include <tuple>

#include "air/stereo/node/vo_node.hpp"
#include "common/image/image_message.hpp"
#include "common/sim/simulation.hpp"
#include "tests/support/test_support.hpp"

using namespace aerie;

namespace {

aerie::stereo_image_t to_message(const sim::StereoFrame& f, const sim::Intrinsics& K) {
  aerie::stereo_image_t m;
  m.utime = f.utime;
  m.seq = f.seq;
  m.left = image::to_message(f.left, f.utime, f.seq);
  m.right = image::to_message(f.right, f.utime, f.seq);
  m.fx = K.fx;
  m.fy = K.fy;
  m.cx = K.cx;
  m.cy = K.cy;
  m.baseline_m = K.baseline;
  return m;
}

// The survey every test flies: the standard room, one loop at 1 m/s, 20 pairs a second
// (the world outlives the simulation that refers to it).
struct Survey {
  const sim::World world = sim::World::room(sim::WorldConfig{});
  sim::StereoSimulation simulation{world, sim::RigConfig{}, sim::Trajectory::survey_loops(world, 1, 1.0), 20.0};
};

// The node without its bundle-adjuster thread: every pose is the front end's, at once.
stereo::VoNodeConfig without_ba() {
  stereo::VoNodeConfig cfg;
  cfg.vo.ba.enabled = false;
  return cfg;
}

}  // namespace

TEST(VoNode, PublishesPosesAndDepthAndRefusesBadPairs) {
  bus::Bus bus("memq://");
  bus::StatusReporter status(bus, "VO");
  std::vector<aerie::pose_t> poses;
  int depth_msgs = 0;
  bus.subscribe<aerie::pose_t>("VO_POSE", [&](const aerie::pose_t& p, const bus::ReceiveInfo&) { poses.push_back(p); });
  bus.subscribe<aerie::spherical_depth_t>("VO_DEPTH",
                                          [&](const aerie::spherical_depth_t&, const bus::ReceiveInfo&) { ++depth_msgs; });
  const stereo::VoNodeConfig cfg = without_ba();
  stereo::VoNode node(bus, status, cfg);

  Survey survey;
  sim::StereoSimulation& simulation = survey.simulation;
  const auto K = simulation.intrinsics();
  sim::StereoFrame f;
  for (int i = 0; i < 6 && simulation.next(f); ++i) {
    bus.publish("CAM_STEREO", to_message(f, K));
    while (bus.handle(0) > 0) {
    }
  }
  ASSERT_EQ(node.processed(), 6);
  ASSERT_EQ(poses.size(), 6u);
  EXPECT_EQ(poses[0].status, aerie::pose_t::INITIALISING);
  EXPECT_EQ(poses[5].status, aerie::pose_t::OK);
  EXPECT_EQ(poses[5].utime, f.utime);
  EXPECT_GT(poses[5].features_3d, 50);
  EXPECT_EQ(depth_msgs, 3);  // dense depth on one of every two pairs
  // The pose follows the ground truth (the camera moved ~25 cm in 5 frames).
  const geometry::SE3 T = geometry::SE3::from_wxyz(poses[5].orientation, poses[5].position);
  sim::StereoFrame f0 = simulation.frame(0);
  const geometry::SE3 truth = f0.T_world_left.inverse() * f.T_world_left;
  EXPECT_LT((T.translation() - truth.translation()).norm(), 0.02);

  // Mismatched sizes, mismatched timestamps, a corrupt payload: refused, counted, no pose.
  simulation.next(f);
  auto bad = to_message(f, K);
  cv::Mat small;
  cv::resize(f.right, small, cv::Size(188, 120));
  bad.right = image::to_message(small, f.utime, f.seq);
  node.on_stereo(bad, 0);
  bad = to_message(f, K);
  bad.right.utime += 40000;
  node.on_stereo(bad, 0);
  bad = to_message(f, K);
  bad.left.size = 10;
  bad.left.data.resize(10);
  node.on_stereo(bad, 0);
  bad = to_message(f, K);
  bad.baseline_m = 0;
  node.on_stereo(bad, 0);
  EXPECT_EQ(node.refused(), 4);
  EXPECT_EQ(status.counter("refused_pairs"), 4);
  EXPECT_EQ(node.processed(), 6);
  // A garbage message on the channel is counted by the bus and dropped.
  const uint8_t junk[7] = {1, 2, 3, 4, 5, 6, 7};
  bus.publish_raw("CAM_STEREO", junk, sizeof junk);
  while (bus.handle(0) > 0) {
  }
  // And the node goes on with good pairs.
  node.on_stereo(to_message(f, K), 0);
  EXPECT_EQ(node.processed(), 7);
  ASSERT_TRUE(node.last().has_value());
  EXPECT_EQ(node.last()->status, stereo::VoStatus::Ok);
  // Copies of the last pair (a burst of duplicated or corrupted datagrams) and one stray
  // older pair are dropped and counted; the odometry goes on.
  const aerie::stereo_image_t last_pair = to_message(f, K);
  for (int i = 0; i < 30; ++i) node.on_stereo(last_pair, 0);
  node.on_stereo(to_message(simulation.frame(2), K), 0);
  EXPECT_EQ(status.counter("duplicate_pairs"), 30);
  EXPECT_EQ(status.counter("out_of_order_pairs"), 1);
  EXPECT_EQ(status.counter("time_resets"), 0);
  EXPECT_EQ(node.processed(), 7);
  EXPECT_EQ(node.last()->status, stereo::VoStatus::Ok);
  // Time going backwards for good (a log replayed from its start): the third older pair in
  // a row, each newer than the one before, restarts the odometry and says so.
  node.on_stereo(to_message(simulation.frame(0), K), 0);
  node.on_stereo(to_message(simulation.frame(1), K), 0);
  EXPECT_EQ(node.processed(), 7);
  node.on_stereo(to_message(simulation.frame(2), K), 0);
  EXPECT_EQ(node.processed(), 8);
  EXPECT_EQ(node.last()->status, stereo::VoStatus::Reset);
  EXPECT_EQ(status.counter("time_resets"), 1);
}

// Hostile stamps (INT64_MIN, INT64_MAX) in a pair: refused as a skew, naming the stamps,
// counted; no overflow (docs/fuzz.md, finding 6) and the odometry goes on.
TEST(VoNode, HostileStampsAreRefusedAsASkew) {
  bus::Bus bus("memq://");
  bus::StatusReporter status(bus, "VO");
  stereo::VoNode node(bus, status, without_ba());
  Survey survey;
  const auto K = survey.simulation.intrinsics();
  sim::StereoFrame f;
  ASSERT_TRUE(survey.simulation.next(f));
  node.on_stereo(to_message(f, K), 0);
  ASSERT_EQ(node.processed(), 1);
  constexpr int64_t lo = std::numeric_limits<int64_t>::min(), hi = std::numeric_limits<int64_t>::max();
  ASSERT_TRUE(survey.simulation.next(f));
  int refused = 0;
  for (const auto& [pair, left, right] : {std::tuple{f.utime, lo, f.utime}, std::tuple{f.utime, f.utime, lo},
                                          std::tuple{lo, f.utime, f.utime}, std::tuple{hi, lo, hi},
                                          std::tuple{lo, lo, hi}}) {
    auto m = to_message(f, K);
    m.utime = pair;
    m.left.utime = left;
    m.right.utime = right;
    node.on_stereo(m, 0);
    EXPECT_EQ(node.refused(), ++refused);
    EXPECT_NE(status.message().find("differ by more than"), std::string::npos) << status.message();
    EXPECT_NE(status.message().find(std::to_string(lo)), std::string::npos) << status.message();
  }
  EXPECT_EQ(status.counter("refused_pairs"), 5);
  EXPECT_EQ(node.processed(), 1);
  node.on_stereo(to_message(f, K), 0);
  EXPECT_EQ(node.processed(), 2);
  EXPECT_EQ(node.last()->status, stereo::VoStatus::Ok);
}

TEST(VoNode, OneCorruptPairDoesNotRestartTheOdometryAPersistentNewCameraDoes) {
  // A burst of bit-flipped pairs in an avoidance flight: a baseline of 2e+307 passed the
  // "positive" check and restarted the odometry twice, and the flight lost its frame.
  bus::Bus bus("memq://");
  bus::StatusReporter status(bus, "VO");
  const stereo::VoNodeConfig cfg = without_ba();
  stereo::VoNode node(bus, status, cfg);
  Survey survey;
  sim::StereoSimulation& simulation = survey.simulation;
  const auto K = simulation.intrinsics();
  sim::StereoFrame f;
  auto next = [&] {
    simulation.next(f);
    return to_message(f, K);
  };
  for (int i = 0; i < 6; ++i) node.on_stereo(next(), 0);
  ASSERT_EQ(node.last()->status, stereo::VoStatus::Ok);
  aerie::stereo_image_t m = next();
  m.baseline_m = 2e307;
  node.on_stereo(m, 0);
  m = next();
  m.fx = 1e9;
  node.on_stereo(m, 0);
  EXPECT_EQ(status.counter("refused_pairs"), 2);
  m = next();
  m.fx *= 1.5;  // plausible, but another camera: once, then the real one again
  node.on_stereo(m, 0);
  node.on_stereo(next(), 0);
  EXPECT_EQ(status.counter("camera_change_pending"), 1);
  EXPECT_EQ(status.counter("camera_changes"), 1);  // the first camera only
  EXPECT_EQ(node.processed(), 7);
  EXPECT_EQ(node.last()->status, stereo::VoStatus::Ok);
  // The same new camera for resync_messages pairs in a row: the odometry starts over with it.
  for (int i = 0; i < cfg.message_time.resync_messages; ++i) {
    m = next();
    m.fx *= 1.5;
    node.on_stereo(m, 0);
  }
  EXPECT_EQ(status.counter("camera_change_pending"), cfg.message_time.resync_messages);
  EXPECT_EQ(status.counter("camera_changes"), 2);
  EXPECT_EQ(node.processed(), 8);
  EXPECT_EQ(node.last()->status, stereo::VoStatus::Initialising);
}

TEST(VoNode, OddImageSizesGiveDepthOnEveryDepthFrame) {
  // 377 x 241 simulator frames failed on every pair ("disparity is 188x120, encoder expects
  // 189x121"). 377/2 and 241/2 round down, 379/2 and 243/2 round up in cv::resize: both work.
  for (const cv::Size size : {cv::Size(377, 241), cv::Size(379, 243)}) {
    SCOPED_TRACE(std::to_string(size.width) + "x" + std::to_string(size.height));
    bus::Bus bus("memq://");
    bus::StatusReporter status(bus, "VO");
    int depth_msgs = 0;
    bus.subscribe<aerie::spherical_depth_t>("VO_DEPTH",
                                            [&](const aerie::spherical_depth_t&, const bus::ReceiveInfo&) { ++depth_msgs; });
    const stereo::VoNodeConfig cfg = without_ba();
    stereo::VoNode node(bus, status, cfg);
    Survey survey;
  sim::StereoSimulation& simulation = survey.simulation;
    const auto K = simulation.intrinsics();
    sim::StereoFrame f;
    for (int i = 0; i < 6 && simulation.next(f); ++i) {
      // Grown on the right and bottom: the intrinsics stay those of the rig.
      const int dx = size.width - f.left.cols, dy = size.height - f.left.rows;
      cv::copyMakeBorder(f.left, f.left, 0, dy, 0, dx, cv::BORDER_REPLICATE);
      cv::copyMakeBorder(f.right, f.right, 0, dy, 0, dx, cv::BORDER_REPLICATE);
      ASSERT_EQ(f.left.size(), size);
      node.on_stereo(to_message(f, K), 0);
      while (bus.handle(0) > 0) {
      }
    }
    EXPECT_EQ(node.processed(), 6);
    EXPECT_EQ(status.counter("errors"), 0);
    EXPECT_EQ(depth_msgs, 3);
    ASSERT_TRUE(node.last().has_value());
    EXPECT_EQ(node.last()->status, stereo::VoStatus::Ok);
  }
}

TEST(VoNode, A25SecondCameraOutageIsReportedAndTheOdometryRecovers) {
  // Issue 20: while the camera was down aerie-vo kept health OK. Lock-step: the node clock
  // moves 50 ms per pair; 25 s of silence; then the camera comes back (25 s later in utime).
  bus::Bus bus("memq://");
  bus::StatusReporter status(bus, "VO");
  std::vector<aerie::pose_t> poses;
  bus.subscribe<aerie::pose_t>("VO_POSE", [&](const aerie::pose_t& p, const bus::ReceiveInfo&) { poses.push_back(p); });
  const stereo::VoNodeConfig cfg = without_ba();
  int64_t now = 1'000'000'000;
  stereo::VoNode node(bus, status, cfg, [&] { return now; });
  Survey survey;
  sim::StereoSimulation& simulation = survey.simulation;
  const auto K = simulation.intrinsics();
  sim::StereoFrame f;
  auto pair = [&](int64_t shift_us) {
    simulation.next(f);
    auto m = to_message(f, K);
    m.utime += shift_us;
    m.left.utime += shift_us;
    m.right.utime += shift_us;
    node.on_stereo(m, 0);
    while (bus.handle(0) > 0) {
    }
    node.tick();
    now += 50'000;
    return m.utime;
  };
  for (int i = 0; i < 6; ++i) pair(0);
  EXPECT_EQ(node.last()->status, stereo::VoStatus::Ok);
  EXPECT_EQ(status.counter("CAM_STEREO.stale"), 0);

  for (int k = 0; k < 250; ++k, now += 100'000) node.tick();
  EXPECT_EQ(status.counter("CAM_STEREO.stale"), 1);
  EXPECT_EQ(status.counter("CAM_STEREO.outages"), 1);
  EXPECT_EQ(status.message().rfind("CAM_STEREO stale: no message for 2.", 0), 0u) << status.message();

  // Back 25 s later: 2 pairs held, the 3rd re-synchronises and restarts the odometry from the
  // last pose (RESET), then OK poses with the new times; status OK again.
  const size_t before = poses.size();
  pair(25'000'000);
  pair(25'000'000);
  EXPECT_EQ(poses.size(), before);
  EXPECT_EQ(status.counter("CAM_STEREO.time_jumps"), 2);
  const int64_t resync_utime = pair(25'000'000);
  ASSERT_EQ(poses.size(), before + 1);
  EXPECT_EQ(poses.back().utime, resync_utime);
  EXPECT_EQ(poses.back().status, aerie::pose_t::RESET);
  EXPECT_EQ(status.counter("CAM_STEREO.time_resyncs"), 1);
  EXPECT_EQ(status.counter("CAM_STEREO.stale"), 0);
  for (int i = 0; i < 4; ++i) pair(25'000'000);
  EXPECT_EQ(node.last()->status, stereo::VoStatus::Ok);
  EXPECT_EQ(poses.back().status, aerie::pose_t::OK);
  EXPECT_EQ(status.message(), "OK");
  EXPECT_EQ(status.counter("errors"), 0);
}

TEST(VoNode, MessageTimeKeysAreReadWithTheirRanges) {
  const auto cfg = stereo::load_vo_node_config(util::Config::load((test::source_dir() / "config" / "vo.yaml").string()));
  EXPECT_EQ(cfg.message_time.max_jump_us, 10'000'000);
  EXPECT_EQ(cfg.message_time.resync_messages, 3);
  EXPECT_EQ(cfg.message_time.stale_timeout_us, 2'000'000);
  const auto load = [](const std::string& text) { stereo::load_vo_node_config(util::Config::parse(text, "vo.yaml")); };
  test::expect_refusals(load, {
      {"message_time:\n  stale_timeout_s: -1\n", "vo.yaml:message_time: key 'stale_timeout_s' = -1 is outside its valid range"},
      {"message_time:\n  resync_messages: 1001\n", "key 'resync_messages' = 1001 is outside its valid range [1, 1000]"},
      {"message_time:\n  jump: 1\n", "unknown key 'jump'"},
  });
}
