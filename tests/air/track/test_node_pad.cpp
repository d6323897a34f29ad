// aerie-track with target.shape square over memq://: TARGET_POSE from the pad's corners,
// intrinsics from the image metadata, re-seeding a tracker whose box is wrong in scale.
#include <gtest/gtest.h>

#include <aerie/target_pose_t.hpp>

#include "air/track/node/track_node.hpp"
#include "common/image/image_message.hpp"
#include "tests/air/track/pad_views.hpp"

using namespace aerie::track;
using aerie::track::test::pad_view;
using aerie::track::test::PadView;

namespace {

class PadNodeTest : public ::testing::Test {
 protected:
  PadNodeTest() : bus_("memq://"), renderer_(world(), rig()) {
    bus_.subscribe<aerie::target_pose_t>("TARGET_POSE", [this](const aerie::target_pose_t& m,
                                                               const aerie::bus::ReceiveInfo&) { poses_.push_back(m); });
  }
  static const aerie::sim::World& world() {
    static const aerie::sim::World w = aerie::sim::World::room({});
    return w;
  }
  static aerie::sim::RigConfig rig() {
    auto r = aerie::sim::landing_rig();
    r.noise_sigma = 2;
    return r;
  }
  static NodeOptions options() {
    NodeOptions o;
    o.tracker = "dcf";
    o.target.width_m = world().helipad().size;
    o.target_shape = TargetShape::Square;
    return o;
  }
  // Frame k of a slow descent from top_ (2 m) by step_ (2 cm) a frame, turning; intrinsics in
  // the metadata unless `fx` is given.
  aerie::image_t frame(int k, PadView& v, const std::string& fx = "") {
    v = pad_view(renderer_, top_ - step_ * k, 20 + 0.5 * k, 3, -2, {0.05, -0.02}, k);
    aerie::image_t m = aerie::image::to_message(v.frame.left, 1'000'000 + 50'000 * k, k);
    auto put = [&](const char* key, double value) { aerie::image::set_metadata(m, key, std::to_string(value)); };
    if (fx.empty()) put("fx", v.camera.fx);
    else aerie::image::set_metadata(m, "fx", fx);
    put("fy", v.camera.fy);
    put("cx", v.camera.cx);
    put("cy", v.camera.cy);
    return m;
  }
  void settle(TrackNode& node) {
    for (int round = 0; round < 3; ++round) {
      while (bus_.handle(0) > 0) {
      }
      ASSERT_TRUE(node.wait_idle(10000));
    }
    while (bus_.handle(0) > 0) {
    }
  }
  void init(const cv::Rect2d& box) {
    aerie::track_cmd_t c{};
    c.command = aerie::track_cmd_t::INIT;
    c.x = box.x, c.y = box.y, c.width = box.width, c.height = box.height;
    bus_.publish("TRACK_CMD", c);
  }
  // Runs frames 0..n-1 with INIT on frame 0 (box scaled by init_scale about its centre);
  // returns the view of the last frame.
  PadView run(TrackNode& node, int n, double init_scale = 1.0, const std::string& fx = "") {
    PadView v;
    for (int k = 0; k < n; ++k) {
      bus_.publish("CAM_LEFT", frame(k, v, fx));
      settle(node);
      if (k == 0) {
        const cv::Rect2d& b = v.frame.target_box;
        const cv::Point2d c(b.x + b.width / 2, b.y + b.height / 2);
        init({c.x - init_scale * b.width / 2, c.y - init_scale * b.height / 2, init_scale * b.width, init_scale * b.height});
        settle(node);
      }
    }
    return v;
  }

  aerie::bus::Bus bus_;
  aerie::sim::StereoRenderer renderer_;
  double top_ = 2.0, step_ = 0.02;
  std::vector<aerie::target_pose_t> poses_;
};

}  // namespace

TEST_F(PadNodeTest, SquareTargetPoseFromTheCornersWithIntrinsicsFromTheMetadata) {
  TrackNode node(bus_, options());  // no configured camera: the metadata brings it
  const PadView last = run(node, 12);
  ASSERT_EQ(poses_.size(), 11u);  // frame 0 came before the INIT
  const auto& p = poses_.back();
  EXPECT_EQ(p.utime, 1'000'000 + 50'000 * 11);
  const Eigen::Vector3d position(p.position[0], p.position[1], p.position[2]);
  const double error = (position - last.position).norm();
  RecordProperty("position_error_m", std::to_string(error));
  EXPECT_LT(error, 0.02);
  EXPECT_LT(std::abs(test::wrap_half_turn(p.yaw - last.yaw)), 2 * M_PI / 180);
  EXPECT_EQ(node.counter("pad_refined"), 11);
  EXPECT_EQ(node.counter("pad_not_found"), 0);
  EXPECT_EQ(node.counter("camera_metadata_errors"), 0);
  EXPECT_EQ(node.counter("tracks_published"), 12);  // TRACK unchanged: one per frame
}

TEST_F(PadNodeTest, TrackerWrongInScaleIsReseededOnThePad) {
  TrackNode node(bus_, options());
  const PadView last = run(node, 6, 0.6);  // INIT on 60 % of the pad: IoU 0.36
  EXPECT_GE(node.counter("tracker_reseeded"), 1);
  EXPECT_EQ(node.counter("pad_refined"), 5);
  const auto& p = poses_.back();
  EXPECT_LT((Eigen::Vector3d(p.position[0], p.position[1], p.position[2]) - last.position).norm(), 0.02);
}

// Low in the descent the pad is cut by the image border: the poses come from its H, still
// fitted (SOURCE_FIT), and the tracker is not re-seeded on a box that leaves the image.
TEST_F(PadNodeTest, TooCloseToSeeThePadWholeThePoseComesFromTheH) {
  top_ = 1.1, step_ = 0.02;  // 1.1 m .. 0.64 m at 0.4 m/s
  NodeOptions o = options();
  o.tracker = "amcmr-ct";  // the landing's tracker (DCF loses the pad as it outgrows the image)
  o.fit_h_when_cut = true;
  TrackNode node(bus_, o);
  const PadView last = run(node, 24);
  ASSERT_EQ(poses_.size(), 23u);
  for (const auto& p : poses_) EXPECT_EQ(p.source, aerie::target_pose_t::SOURCE_FIT) << p.utime;
  const auto& p = poses_.back();
  EXPECT_LT((Eigen::Vector3d(p.position[0], p.position[1], p.position[2]) - last.position).norm(), 0.02);
  EXPECT_LT(std::abs(test::wrap_half_turn(p.yaw - last.yaw)), 2 * M_PI / 180);
  EXPECT_EQ(node.counter("pad_refined"), 23);
  EXPECT_GE(node.counter("pad_marking_only"), 12);
  EXPECT_EQ(node.counter("tracker_reseeded"), 0);
}

TEST_F(PadNodeTest, BadMetadataIsCountedAndTheConfiguredCameraKept) {
  NodeOptions o = options();
  o.camera = renderer_.intrinsics().calibration().left;
  TrackNode node(bus_, o);
  const PadView last = run(node, 4, 1.0, "12x");
  EXPECT_EQ(node.counter("camera_metadata_errors"), 4);
  ASSERT_EQ(poses_.size(), 3u);
  const auto& p = poses_.back();
  EXPECT_LT((Eigen::Vector3d(p.position[0], p.position[1], p.position[2]) - last.position).norm(), 0.02);
}

TEST(PadNodeOptions, ShapeKeysAreParsedAndChecked) {
  auto parse = [](const std::string& yaml) { return node_options(aerie::util::Config::parse(yaml, "track.yaml")); };
  const NodeOptions o = parse("target: {width_m: 1.0, shape: square, search_margin: 0.8, reseed_iou: 0.3, border: 0.02}");
  EXPECT_EQ(o.target_shape, TargetShape::Square);
  EXPECT_DOUBLE_EQ(o.search_margin, 0.8);
  EXPECT_DOUBLE_EQ(o.reseed_iou, 0.3);
  EXPECT_DOUBLE_EQ(o.pad_border, 0.02);
  EXPECT_FALSE(o.fit_h_when_cut);
  EXPECT_TRUE(parse("target: {width_m: 1.0, shape: square, fit_h_when_cut: true}").fit_h_when_cut);
  EXPECT_EQ(parse("target: {width_m: 1.0}").target_shape, TargetShape::Box);
  EXPECT_THROW(parse("target: {shape: circle}"), std::runtime_error);
  EXPECT_THROW(parse("target: {reseed_iou: 1.5}"), std::runtime_error);
  EXPECT_THROW(parse("target: {search_margin: -1}"), std::runtime_error);
  EXPECT_THROW(parse("target: {fit_h_when_cut: maybe}"), std::runtime_error);
  aerie::bus::Bus bus("memq://");
  NodeOptions no_size;
  no_size.target_shape = TargetShape::Square;
  try {
    TrackNode node(bus, no_size);
    ADD_FAILURE() << "a square target without a size was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("width_m"), std::string::npos);
  }
}
