// Issue 49: each image once on the wire. A calibrated stereo source publishes CAM_STEREO only
// (left/right alone on request, split_stereo); the bytes per frame, counted per channel over
// memq://, carry each image once; a contradictory channel config is refused.
#include <gtest/gtest.h>

#include <aerie/image_t.hpp>
#include <aerie/stereo_image_t.hpp>

#include <map>

#include "air/capture/capture_node.hpp"
#include "air/capture/source_factory.hpp"
#include "tests/support/test_support.hpp"

namespace aerie::capture {
namespace {

struct Wire {
  std::map<std::string, int64_t> messages, bytes;  // per channel
  int64_t pixels = 0;                              // image payload bytes decoded from every image channel
};

// Plays `frames` frames of `options` as fast as possible and counts what goes out.
Wire play(SourceOptions options, CaptureConfig cfg, int frames) {
  bus::Bus bus("memq://");
  Wire w;
  bus.subscribe_raw(".*", [&](const uint8_t*, size_t size, const bus::ReceiveInfo& info) {
    ++w.messages[info.channel];
    w.bytes[info.channel] += static_cast<int64_t>(size);
  }, 10000);
  bus.subscribe<aerie::stereo_image_t>("CAM_STEREO", [&](const aerie::stereo_image_t& m, const auto&) {
    w.pixels += static_cast<int64_t>(m.left.data.size() + m.right.data.size());
  }, 10000);
  for (const char* ch : {"CAM_LEFT", "CAM_RIGHT"})
    bus.subscribe<aerie::image_t>(ch, [&](const aerie::image_t& m, const auto&) {
      w.pixels += static_cast<int64_t>(m.data.size());
    }, 10000);
  cfg.rate = 0;
  cfg.stop = frames;
  CaptureNode node(bus, cfg, make_source(options));
  EXPECT_EQ(node.run().published, frames);
  while (bus.handle(0) > 0) {
  }
  return w;
}

int64_t image_bytes(const Wire& w) {
  int64_t n = 0;
  for (const char* ch : {"CAM_LEFT", "CAM_RIGHT", "CAM_STEREO"})
    if (w.bytes.count(ch)) n += w.bytes.at(ch);
  return n;
}

TEST(CaptureChannels, AStereoSourcePublishesEachImageOncePerFrame) {
  SourceOptions sim;  // the simulator's stereo rig, 376 x 240 gray
  const int frames = 5;
  const int64_t pair = 2 * 376 * 240;
  const Wire once = play(sim, CaptureConfig{}, frames);
  EXPECT_EQ(once.messages.count("CAM_LEFT"), 0u);
  EXPECT_EQ(once.messages.count("CAM_RIGHT"), 0u);
  ASSERT_EQ(once.messages.at("CAM_STEREO"), frames);
  EXPECT_EQ(once.messages.at("GT_POSE"), frames);
  EXPECT_EQ(once.pixels, frames * pair);  // each image's pixels once
  // What the image channels carry beyond the pixels: headers, metadata and intrinsics only.
  EXPECT_GE(image_bytes(once), frames * pair);
  EXPECT_LT(image_bytes(once), frames * (pair + 1024));

  // Asked for the images alone as well: each image twice, as before issue 49.
  CaptureConfig split;
  split.channels.split_stereo = true;
  const Wire twice = play(sim, split, frames);
  EXPECT_EQ(twice.messages.at("CAM_LEFT"), frames);
  EXPECT_EQ(twice.messages.at("CAM_RIGHT"), frames);
  EXPECT_EQ(twice.pixels, 2 * frames * pair);
  EXPECT_GE(image_bytes(twice), 2 * frames * pair);
}

TEST(CaptureChannels, EurocAt752x480CarriesOnePairPerFrame) {
  AERIE_REQUIRE_DATA("stereo_seq/EuRoC_V1_01_easy_f000-094");
  SourceOptions euroc;
  euroc.type = "euroc";
  euroc.path = test::shared_data("stereo_seq/EuRoC_V1_01_easy_f000-094").string();
  const Wire w = play(euroc, CaptureConfig{}, 3);
  EXPECT_EQ(w.messages.count("CAM_LEFT"), 0u);
  ASSERT_EQ(w.messages.at("CAM_STEREO"), 3);
  EXPECT_EQ(w.pixels, 3 * 2 * 752 * 480);
  EXPECT_LT(image_bytes(w), 3 * (2 * 752 * 480 + 1024));
}

TEST(CaptureChannels, WithoutCalibrationOrStereoChannelTheImagesGoOutAlone) {
  // The stereo channel turned off: left and right are the only way out.
  CaptureConfig cfg;
  cfg.channels.stereo = "";
  const Wire w = play(SourceOptions{}, cfg, 2);
  EXPECT_EQ(w.messages.at("CAM_LEFT"), 2);
  EXPECT_EQ(w.messages.at("CAM_RIGHT"), 2);
  EXPECT_EQ(w.messages.count("CAM_STEREO"), 0u);
  // GT_TRACK names the channel whose image the box is in.
  const camera::RectifiedStereo r{100, 100, 16, 12, 0.1, {32, 24}};
  Frame f;
  f.left = cv::Mat(24, 32, CV_8UC1, cv::Scalar(1));
  f.right = f.left.clone();
  f.gt_box = GroundTruthBox{"helipad", true, {1, 2, 3, 4}, {}};
  EXPECT_EQ(MessageBuilder(CaptureConfig{}, true, r).build(f, 1, 0).gt_box->camera, "CAM_STEREO");
  EXPECT_EQ(MessageBuilder(CaptureConfig{}, true, std::nullopt).build(f, 1, 0).gt_box->camera, "CAM_LEFT");
}

TEST(CaptureChannels, SplitStereoWithoutItsChannelsIsRefused) {
  const auto load = [](const std::string& text) { load_capture_config(util::Config::parse(text, "capture.yaml")); };
  test::expect_refusals(load, {
      {"channels: {split_stereo: true, stereo: \"\"}\n",
       "capture.yaml: channels.split_stereo: true needs channels.stereo and channels.left or channels.right"},
      {"channels: {split_stereo: true, left: \"\", right: \"\"}\n", "channels.split_stereo: true needs"},
      {"channels: {split_stereo: maybe}\n", "channels.split_stereo"},
      {"channels: {split: true}\n", "unknown key 'channels.split'"},
  });
  EXPECT_TRUE(load_capture_config(util::Config::parse("channels: {split_stereo: true}\n", "capture.yaml"))
                  .channels.split_stereo);
  EXPECT_FALSE(load_capture_config(util::Config::load(AERIE_SOURCE_DIR "/config/capture.yaml")).channels.split_stereo);
  // The same rule for a config made in code or by command-line options (--split-stereo --stereo-channel "").
  CaptureConfig cfg;
  cfg.channels.split_stereo = true;
  cfg.channels.stereo = "";
  bus::Bus bus("memq://");
  try {
    CaptureNode node(bus, cfg, make_source(SourceOptions{}));
    FAIL() << "split_stereo without a stereo channel accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("aerie-capture: channels.split_stereo: true needs"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace aerie::capture
