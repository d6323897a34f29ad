// The node layer: frame -> messages, the configuration file, and a whole run of
// aerie-capture's node over memq:// received by a subscriber in the same process.
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "air/capture/capture_node.hpp"
#include "air/capture/dataset_io.hpp"
#include "air/capture/image_folder_source.hpp"
#include "air/capture/stereo_sequence_source.hpp"
#include "common/bus/node.hpp"
#include "tests/support/test_support.hpp"

namespace aerie::capture {
namespace {

Frame stereo_frame() {
  Frame f;
  f.index = 4;
  f.utime = 1'000'000;
  f.left = cv::Mat(24, 32, CV_8UC1, cv::Scalar(7));
  f.right = cv::Mat(24, 32, CV_8UC1, cv::Scalar(9));
  f.gt_pose = GroundTruthPose{geometry::SE3(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ())),
                                            Eigen::Vector3d(1, 2, 3)),
                              "sim"};
  f.gt_box = GroundTruthBox{"helipad", true, {3, 4, 5, 6}, {}};
  f.gt_box->corners[2] = {8, 10};
  return f;
}

TEST(MessageBuilder, StereoFrameGivesPairStereoAndGroundTruth) {
  CaptureConfig cfg;
  cfg.channels.split_stereo = true;  // the images alone too (the default publishes each image once: CAM_STEREO)
  const camera::RectifiedStereo r{100, 101, 15.5, 11.5, 0.12, {32, 24}};
  MessageBuilder b(cfg, true, r);
  const auto m = b.build(stereo_frame(), 2'000'000, 17);
  ASSERT_TRUE(m.left && m.right && m.stereo && m.gt_pose && m.gt_box);
  EXPECT_FALSE(m.mono);
  EXPECT_EQ(m.left->utime, 2'000'000);
  EXPECT_EQ(image::sequence_number(*m.left), 17);
  EXPECT_EQ(image::metadata(*m.right, "camera"), "right");
  EXPECT_EQ(image::from_message(*m.right).at<uint8_t>(0, 0), 9);
  EXPECT_EQ(m.stereo->seq, 17);
  EXPECT_DOUBLE_EQ(m.stereo->fx, 100);
  EXPECT_DOUBLE_EQ(m.stereo->cy, 11.5);
  EXPECT_DOUBLE_EQ(m.stereo->baseline_m, 0.12);
  EXPECT_EQ(m.stereo->left.data, m.left->data);
  EXPECT_EQ(m.gt_pose->frame_id, "sim");
  EXPECT_DOUBLE_EQ(m.gt_pose->position[2], 3);
  EXPECT_NEAR(m.gt_pose->orientation[0], std::cos(0.15), 1e-12);  // w first
  EXPECT_NEAR(m.gt_pose->orientation[3], std::sin(0.15), 1e-12);
  EXPECT_EQ(m.gt_box->camera, "CAM_LEFT");
  EXPECT_EQ(m.gt_box->seq, 17);
  EXPECT_DOUBLE_EQ(m.gt_box->corners[2][1], 10);
}

TEST(MessageBuilder, ChannelsTurnedOffAndJpeg) {
  CaptureConfig cfg;
  cfg.channels.split_stereo = true;  // the right image alone as well
  cfg.channels.left = "";
  cfg.channels.gt_track = "";
  cfg.encoding = "jpeg";
  MessageBuilder b(cfg, true, camera::RectifiedStereo{100, 100, 16, 12, 0.1, {32, 24}});
  const auto m = b.build(stereo_frame(), 5, 0);
  EXPECT_FALSE(m.left);
  EXPECT_TRUE(m.right);
  ASSERT_TRUE(m.stereo);
  EXPECT_EQ(m.stereo->left.pixelformat, aerie::image_t::PIXEL_FORMAT_MJPEG);
  EXPECT_FALSE(m.gt_box);
  // A stereo source without calibration: no CAM_STEREO.
  MessageBuilder raw(CaptureConfig{}, true, std::nullopt);
  EXPECT_FALSE(raw.build(stereo_frame(), 5, 0).stereo);
  // One camera: CAM_MONO, and GT_TRACK refers to it.
  MessageBuilder mono(CaptureConfig{}, false, std::nullopt);
  const auto mm = mono.build(stereo_frame(), 5, 0);
  EXPECT_TRUE(mm.mono);
  EXPECT_FALSE(mm.left || mm.stereo);
  EXPECT_EQ(mm.gt_box->camera, "CAM_MONO");
  cfg.encoding = "webp";
  EXPECT_THROW(MessageBuilder(cfg, true, std::nullopt), std::invalid_argument);
}

TEST(CaptureConfig, ReadsEveryKeyAndNamesBadOnes) {
  const auto c = load_capture_config(util::Config::parse(R"(
source: {type: kitti, path: /data/06, fps: 10}
sim: {seed: 7, trajectory: survey}
output: {width: 376, height: 240, color: true, encoding: jpeg, jpeg_quality: 80}
playback: {rate: 0, start: 3, stop: 9, duration: 2.5, stamp: wall}
channels: {left: L, stereo: ""}
)", "test.yaml"));
  EXPECT_EQ(c.source.type, "kitti");
  EXPECT_EQ(c.source.path, "/data/06");
  EXPECT_EQ(c.source.sim.seed, 7u);
  EXPECT_EQ(c.source.sim.trajectory, "survey");
  EXPECT_EQ(c.output.width, 376);
  EXPECT_TRUE(c.output.color);
  EXPECT_EQ(c.encoding, "jpeg");
  EXPECT_EQ(c.rate, 0);
  EXPECT_EQ(c.stop, 9);
  EXPECT_EQ(c.stamp, "wall");
  EXPECT_EQ(c.channels.left, "L");
  EXPECT_EQ(c.channels.stereo, "");
  EXPECT_EQ(c.channels.right, "CAM_RIGHT");
  const auto s = c.source_options();
  EXPECT_EQ(s.width, 376);
  EXPECT_TRUE(s.color);
  try {
    load_capture_config(util::Config::parse("playback: {rate: fast}", "bad.yaml"));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("playback.rate"), std::string::npos);
  }
}

TEST(CaptureConfig, RefusesUnknownKeysAndValuesOutsideTheirRanges) {
  const auto load = [](const std::string& text) { load_capture_config(util::Config::parse(text, "capture.yaml")); };
  const std::vector<std::pair<std::string, std::string>> cases{
      {"source: {fps: 1e308}\n", "capture.yaml: key 'source.fps' = 1e+308 is outside its valid range [0.01, 1000] (line 1)"},
      {"sim:\n  speed: 1e308\n", "key 'sim.speed' = 1e+308 is outside its valid range [0.01, 20] (line 2)"},
      {"output: {jpeg_quality: 0}\n", "'output.jpeg_quality' = 0 is outside its valid range [1, 100]"},
      {"playback: {rate: -1}\n", "'playback.rate' = -1 is outside"},
      {"source: {fsp: 20}\n", "unknown key 'source.fsp' (line 1)"},
      {"playback: 1\n", "'playback' is a section of keys, not a value (line 1)"},
      {"- source: {}\n", "expected a map of keys, not a list"},
  };
  test::expect_refusals(load, cases);
}

TEST(CaptureConfig, ShippedConfigsLoad) {
  for (const auto& entry : std::filesystem::directory_iterator(test::source_dir() / "config")) {
    const auto name = entry.path().filename().string();
    if (name.rfind("capture", 0) != 0 || entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(name);
    const auto c = load_capture_config(util::Config::load(entry.path().string()));
    EXPECT_FALSE(c.source.type.empty());
  }
}

// Collects what the node publishes (memq://, same process).
struct Collector {
  std::vector<aerie::image_t> left, right;
  std::vector<aerie::stereo_image_t> stereo;
  std::vector<aerie::gt_pose_t> poses;
  std::vector<aerie::process_status_t> status;
  explicit Collector(bus::Bus& bus) {
    bus.subscribe<aerie::image_t>("CAM_LEFT", [this](const auto& m, const auto&) { left.push_back(m); }, 1000);
    bus.subscribe<aerie::image_t>("CAM_RIGHT", [this](const auto& m, const auto&) { right.push_back(m); }, 1000);
    bus.subscribe<aerie::stereo_image_t>("CAM_STEREO", [this](const auto& m, const auto&) { stereo.push_back(m); }, 1000);
    bus.subscribe<aerie::gt_pose_t>("GT_POSE", [this](const auto& m, const auto&) { poses.push_back(m); }, 1000);
    bus.subscribe<aerie::process_status_t>("STATUS_CAPTURE", [this](const auto& m, const auto&) { status.push_back(m); }, 1000);
  }
};

TEST(CaptureNode, KittiOverMemqWithStartStopAndDownscale) {
  AERIE_REQUIRE_DATA("stereo_seq/KITTI_odom_06_f000-050");
  const auto dir = test::shared_data("stereo_seq/KITTI_odom_06_f000-050");
  bus::Bus bus("memq://");
  Collector got(bus);
  CaptureConfig cfg;
  cfg.rate = 0;
  cfg.start = 10;
  cfg.stop = 16;
  cfg.output.downscale = 2;
  cfg.channels.split_stereo = true;  // CAM_LEFT / CAM_RIGHT as well
  CaptureNode node(bus, cfg, std::make_unique<StereoSequenceSource>(load_kitti(dir.string()), false));
  const auto st = node.run();
  while (bus.handle(0) > 0) {
  }
  EXPECT_EQ(st.published, 6);
  EXPECT_EQ(st.unreadable, 0);
  ASSERT_EQ(got.stereo.size(), 6u);
  ASSERT_EQ(got.left.size(), 6u);
  ASSERT_EQ(got.right.size(), 6u);
  ASSERT_EQ(got.poses.size(), 6u);
  const auto times = read_timestamps((dir / "times.txt").string());
  for (int i = 0; i < 6; ++i) {
    const auto& s = got.stereo[static_cast<size_t>(i)];
    EXPECT_EQ(s.seq, i);
    EXPECT_EQ(s.utime, times[static_cast<size_t>(10 + i)]);
    EXPECT_EQ(got.poses[static_cast<size_t>(i)].utime, s.utime);
    EXPECT_EQ(s.left.width, 613);
    EXPECT_EQ(s.left.height, 185);
  }
  EXPECT_NEAR(got.stereo[0].fx, 707.0912 / 2, 0.5);
  EXPECT_NEAR(got.stereo[0].baseline_m, 0.53716, 1e-4);
  ASSERT_FALSE(got.status.empty());
  EXPECT_EQ(got.status.back().node, "capture");
}

// An unreadable image is counted and skipped; the run goes on.
TEST(CaptureNode, UnreadableFramesAreCountedAndSkipped) {
  const auto dir = test::scratch_dir("folder");
  for (int i = 0; i < 5; ++i)
    cv::imwrite((dir / (std::to_string(i) + ".png")).string(), cv::Mat(16, 16, CV_8UC1, cv::Scalar(i * 10)));
  std::ofstream(dir / "3.png") << "broken";
  bus::Bus bus("memq://");
  std::vector<aerie::image_t> mono;
  bus.subscribe<aerie::image_t>("CAM_MONO", [&](const auto& m, const auto&) { mono.push_back(m); }, 100);
  CaptureConfig cfg;
  cfg.rate = 0;
  CaptureNode node(bus, cfg, std::make_unique<ImageFolderSource>(dir.string(), "", 20, false));
  const auto st = node.run();
  while (bus.handle(0) > 0) {
  }
  EXPECT_EQ(st.published, 4);
  EXPECT_EQ(st.unreadable, 1);
  ASSERT_EQ(mono.size(), 4u);
  EXPECT_EQ(mono[3].utime, 200'000);  // frame 4 at 20 Hz
  EXPECT_EQ(image::sequence_number(mono[3]), 3);
}

}  // namespace
}  // namespace aerie::capture

namespace aerie::capture {
namespace {

// Looping a recorded source: times keep increasing by the frame interval across the
// restart, seq goes on, and the duration limit ends the run.
TEST(CaptureNode, LoopKeepsTimesAndSeqIncreasing) {
  const auto dir = test::scratch_dir("folder");
  for (int i = 0; i < 3; ++i)
    cv::imwrite((dir / (std::to_string(i) + ".png")).string(), cv::Mat(16, 16, CV_8UC1, cv::Scalar(i * 10)));
  bus::Bus bus("memq://");
  std::vector<aerie::image_t> mono;
  bus.subscribe<aerie::image_t>("CAM_MONO", [&](const auto& m, const auto&) { mono.push_back(m); }, 100);
  CaptureConfig cfg;
  cfg.rate = 0;
  cfg.loop = true;
  cfg.duration_s = 0.4;
  CaptureNode node(bus, cfg, std::make_unique<ImageFolderSource>(dir.string(), "", 20, false));
  EXPECT_EQ(node.run().published, 8);
  while (bus.handle(0) > 0) {
  }
  ASSERT_EQ(mono.size(), 8u);
  for (size_t i = 0; i < mono.size(); ++i) {
    EXPECT_EQ(mono[i].utime, static_cast<int64_t>(i) * 50'000);
    EXPECT_EQ(image::sequence_number(mono[i]), static_cast<int64_t>(i));
    EXPECT_EQ(image::from_message(mono[i]).at<uint8_t>(0, 0), (i % 3) * 10);
  }
}

}  // namespace
}  // namespace aerie::capture
