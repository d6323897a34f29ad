// aerie-track with target.pose_source apriltag / aruco over memq://: TRACK and TARGET_POSE from
// the fiducial board in the whole frame (source SOURCE_APRILTAG / SOURCE_ARUCO), no tracker run;
// the config's pose source and fiducial section read and refused.
#include <aerie/target_pose_t.hpp>
#include <aerie/track_t.hpp>
#include <gtest/gtest.h>

#include "air/track/node/track_node.hpp"
#include "common/image/image_message.hpp"
#include "tests/air/track/fiducial/fiducial_views.hpp"

using namespace aerie::track;

namespace {

class FiducialNodeTest : public ::testing::TestWithParam<FiducialKind> {
 protected:
  FiducialNodeTest() : bus_("memq://") {
    bus_.subscribe<aerie::target_pose_t>("TARGET_POSE", [this](const aerie::target_pose_t& m, const aerie::bus::ReceiveInfo&) {
      poses_.push_back(m);
    });
    bus_.subscribe<aerie::track_t>("TRACK", [this](const aerie::track_t& m, const aerie::bus::ReceiveInfo&) { tracks_.push_back(m); });
  }
  void send(const cv::Mat& image, int k) {
    aerie::image_t m = aerie::image::to_message(image, 1'000'000 + 50'000 * k, k);
    for (const auto& [key, v] : {std::pair{"fx", camera_.fx}, {"fy", camera_.fy}, {"cx", camera_.cx}, {"cy", camera_.cy}})
      aerie::image::set_metadata(m, key, std::to_string(v));
    bus_.publish("CAM_LEFT", m);
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
  aerie::bus::Bus bus_;
  aerie::camera::CameraModel camera_ = test::vga_camera();
  std::vector<aerie::target_pose_t> poses_;
  std::vector<aerie::track_t> tracks_;
};

// One node per test: a bus keeps its subscriptions for its lifetime.
TEST_P(FiducialNodeTest, PosesFromTheBoardWithTheSourceSet) {
  {
    const FiducialKind kind = GetParam();
    NodeOptions o;
    o.fiducial = FiducialBoard{kind, kind == FiducialKind::AprilTag ? "tagCustom48h12" : "DICT_4X4_50",
                               {{0, 0.6, 0, 0}, {1, 0.06, 0, 0}}};
    if (kind == FiducialKind::ArUco) o.fiducial->tags[1].x = 0.45;  // no free centre: beside
    const BoardImage board = render_board(*o.fiducial, 2048);
    TrackNode node(bus_, o);
    const cv::Mat blank(camera_.height, camera_.width, CV_8UC1, cv::Scalar(128));
    send(blank, 0);  // before the board: IDLE
    settle(node);
    const test::BoardPose truth = test::looking_down(1.6, 25, 8, 0.05, 0);
    send(test::render_view(board, camera_, truth), 1);
    settle(node);
    send(blank, 2);  // the board gone: LOST
    settle(node);
    ASSERT_EQ(tracks_.size(), 3u);
    EXPECT_EQ(tracks_[0].status, aerie::track_t::IDLE);
    EXPECT_EQ(tracks_[1].status, aerie::track_t::TRACKING);
    EXPECT_EQ(tracks_[1].tracker, to_string(kind));
    EXPECT_EQ(tracks_[2].status, aerie::track_t::LOST);
    ASSERT_EQ(poses_.size(), 1u);
    const auto& p = poses_[0];
    EXPECT_EQ(p.utime, tracks_[1].utime);
    EXPECT_EQ(p.source, kind == FiducialKind::AprilTag ? aerie::target_pose_t::SOURCE_APRILTAG : aerie::target_pose_t::SOURCE_ARUCO);
    EXPECT_LT((Eigen::Vector3d(p.position[0], p.position[1], p.position[2]) - truth.position).norm(), 0.01);
    EXPECT_NEAR(p.yaw, 25 * M_PI / 180, 1 * M_PI / 180);
    // The TRACK box holds the tags' projection: the board origin projects inside it.
    const Eigen::Vector2d c = camera_.project(truth.position);
    EXPECT_NEAR(tracks_[1].x, c.x(), tracks_[1].width / 2);
    EXPECT_NEAR(tracks_[1].y, c.y(), tracks_[1].height / 2);
    EXPECT_EQ(node.counter("fiducial_found"), 1);
    EXPECT_EQ(node.counter("fiducial_miss_no_tag"), 2);
    EXPECT_EQ(node.counter("tracks_published"), 3);
  }
}

INSTANTIATE_TEST_SUITE_P(Kinds, FiducialNodeTest, ::testing::Values(FiducialKind::AprilTag, FiducialKind::ArUco),
                         [](const auto& info) { return to_string(info.param); });

NodeOptions options_from(const std::string& text) { return node_options(aerie::util::Config::parse(text, "track_landing.yaml")); }

void expect_refused(const std::string& text, const std::string& part) {
  try {
    options_from(text);
    ADD_FAILURE() << "accepted: " << text;
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(FiducialNodeOptions, PoseSourceAndFiducialSection) {
  EXPECT_FALSE(options_from("target: {pose_source: tracker}\n").fiducial);
  EXPECT_FALSE(options_from("target: {width_m: 1}\n").fiducial);  // the default: the tracker
  const NodeOptions o = options_from("target: {pose_source: aruco}\nfiducial:\n  family: DICT_5X5_100\n"
                                     "  tags: [{id: 3, size: 0.4}]\n  max_reprojection_px: 3\n");
  ASSERT_TRUE(o.fiducial);
  EXPECT_EQ(o.fiducial->kind, FiducialKind::ArUco);
  EXPECT_EQ(o.fiducial->family, "DICT_5X5_100");
  EXPECT_EQ(o.fiducial->tags.at(0).id, 3);
  EXPECT_DOUBLE_EQ(o.fiducial_options.max_reprojection_px, 3.0);
  // The repository's landing config names a valid board.
  const auto repo = aerie::util::Config::load(AERIE_SOURCE_DIR "/config/track_landing.yaml");
  EXPECT_NO_THROW(fiducial_board(repo.section("fiducial"), FiducialKind::AprilTag));
  expect_refused("target: {pose_source: qr}\n", "track_landing.yaml: target.pose_source must be tracker, apriltag or aruco, got 'qr'");
  expect_refused("target: {pose_source: apriltag}\nfiducial: {family: tag99h1, tags: [{id: 0, size: 0.5}]}\n",
                 "track_landing.yaml:fiducial: fiducial family 'tag99h1' does not exist for apriltag");
  expect_refused("target: {pose_source: apriltag}\nfiducial: {tags: [{id: 0, size: 0}]}\n", "size 0.000000 m must be > 0");
  expect_refused("target: {pose_source: apriltag}\n", "track_landing.yaml:fiducial.tags: expected a list");
}

}  // namespace
