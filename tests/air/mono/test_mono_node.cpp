// aerie-mono's node over memq://: images in, MONO_POSE out with the arbitrary-scale flag and
// the map counts in status; refused, frozen, blank and corrupt inputs are counted with a
// reason and never stop it.
#include <gtest/gtest.h>

#include <aerie/pose_t.hpp>

#include <random>

#include "air/mono/node/mono_node.hpp"
#include "common/image/image_message.hpp"
#include "common/sim/simulation.hpp"
#include "tests/support/test_support.hpp"

using namespace aerie;

namespace {

aerie::image_t to_message(const cv::Mat& img, int64_t utime, int64_t seq, const sim::Intrinsics& K) {
  aerie::image_t m = image::to_message(img, utime, seq);
  image::set_metadata(m, "fx", std::to_string(K.fx));
  image::set_metadata(m, "fy", std::to_string(K.fy));
  image::set_metadata(m, "cx", std::to_string(K.cx));
  image::set_metadata(m, "cy", std::to_string(K.cy));
  return m;
}

void drain(bus::Bus& bus) {
  while (bus.handle(0) > 0) {
  }
}

}  // namespace

TEST(MonoNode, PublishesScaleArbitraryPosesAndCountsBadInput) {
  bus::Bus bus("memq://");
  std::vector<aerie::pose_t> poses;
  bus.subscribe<aerie::pose_t>("MONO_POSE", [&](const aerie::pose_t& p, const bus::ReceiveInfo&) { poses.push_back(p); });
  mono::MonoNodeConfig cfg;
  cfg.mono.ba.enabled = false;
  mono::MonoNode node(bus, cfg);

  const sim::World world = sim::World::room(sim::WorldConfig{});
  sim::StereoSimulation simulation(world, sim::RigConfig{}, sim::Trajectory::survey_loops(world, 1, 1.0), 20.0);
  const auto K = simulation.intrinsics();
  sim::StereoFrame f;
  int n = 0;
  for (; n < 40 && simulation.next(f); ++n) {
    bus.publish("CAM_MONO", to_message(f.left, f.utime, f.seq, K));
    drain(bus);
  }
  ASSERT_EQ(node.processed(), 40);
  ASSERT_EQ(poses.size(), 40u);
  for (const auto& p : poses) EXPECT_TRUE(p.status & aerie::pose_t::SCALE_ARBITRARY);
  EXPECT_EQ(poses[0].status & aerie::pose_t::STATE_MASK, aerie::pose_t::INITIALISING);
  EXPECT_EQ(poses.back().status & aerie::pose_t::STATE_MASK, aerie::pose_t::OK) << node.status().message();
  EXPECT_GT(poses.back().features_3d, 50);
  EXPECT_GE(node.status().counter("keyframes"), 2);
  EXPECT_GT(node.status().counter("landmarks"), 50);

  // The same image again (frozen camera), a black one: skipped with the reason, counted.
  aerie::image_t frozen = to_message(f.left, f.utime + 50000, f.seq + 1, K);
  node.on_image(frozen, 0);
  EXPECT_EQ(node.status().counter("frozen_frames"), 1);
  EXPECT_NE(node.status().message().find("frozen camera"), std::string::npos) << node.status().message();
  node.on_image(to_message(cv::Mat(f.left.size(), CV_8UC1, cv::Scalar(0)), f.utime + 100000, f.seq + 2, K), 0);
  EXPECT_EQ(node.status().counter("blank_frames"), 1);
  EXPECT_NE(node.status().message().find("blank frame"), std::string::npos) << node.status().message();

  // No intrinsics, a corrupt payload, an image of another size with bad intrinsics: refused.
  node.on_image(image::to_message(f.left, f.utime + 150000, f.seq + 3), 0);
  EXPECT_NE(node.status().message().find("no intrinsics"), std::string::npos) << node.status().message();
  aerie::image_t corrupt = to_message(f.left, f.utime + 200000, f.seq + 4, K);
  corrupt.size = 10;
  corrupt.data.resize(10);
  node.on_image(corrupt, 0);
  aerie::image_t bad = to_message(cv::Mat(120, 188, CV_8UC1, cv::Scalar(9)), f.utime + 250000, f.seq + 5, K);
  image::set_metadata(bad, "fx", "nan");
  node.on_image(bad, 0);
  EXPECT_EQ(node.refused(), 3);
  EXPECT_EQ(node.status().counter("refused_images"), 3);

  // Random noise (NaN-free garbage): processed, no crash; then the real images again.
  std::mt19937 rng(3);
  cv::Mat noise(f.left.size(), CV_8UC1);
  cv::randu(noise, 0, 256);
  node.on_image(to_message(noise, f.utime + 300000, f.seq + 6, K), 0);
  const int64_t before = node.processed();
  for (int i = 0; i < 20 && simulation.next(f); ++i) {
    bus.publish("CAM_MONO", to_message(f.left, f.utime + 400000, f.seq + 10, K));
    drain(bus);
  }
  EXPECT_EQ(node.processed(), before + 20);
  EXPECT_TRUE(poses.back().status & aerie::pose_t::SCALE_ARBITRARY);
}

TEST(MonoNode, ConfigRefusesUnknownNodeKeys) {
  try {
    mono::load_mono_node_config(util::Config::parse("node:\n  inptu: CAM_LEFT\n", "m.yaml"));
    FAIL() << "accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("inptu"), std::string::npos) << e.what();
  }
  const auto c = mono::load_mono_node_config(util::Config::load((test::source_dir() / "config/mono.yaml").string()));
  EXPECT_EQ(c.input, "CAM_MONO");
  EXPECT_EQ(c.pose, "MONO_POSE");
}
