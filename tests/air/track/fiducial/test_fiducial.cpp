// air/track/fiducial: AprilTag and ArUco boards rendered into pinhole views at known poses
// (fiducial_views.hpp), detected, their pose checked against the truth; nested boards, blank
// images and refused boards.
#include <gtest/gtest.h>

#include "air/track/fiducial/fiducial.hpp"
#include "tests/air/track/fiducial/fiducial_views.hpp"

using namespace aerie::track;
using aerie::track::test::BoardPose;
using aerie::track::test::looking_down;
using aerie::track::test::render_view;
using aerie::track::test::rotation_error_deg;
using aerie::track::test::vga_camera;

namespace {

FiducialBoard single(FiducialKind kind, const std::string& family, int id, double size) {
  return {kind, family, {{id, size, 0, 0}}};
}

struct Case {
  double height, yaw_deg, tilt_deg, ax, ay;
  double max_position_m, max_rotation_deg;
};

// Every case seen, with the exact id, within its bounds.
void expect_poses(const FiducialBoard& board, const std::vector<Case>& cases, const std::vector<int>& ids) {
  FiducialDetector detector(board);
  const BoardImage image = render_board(board, 2048);
  const auto camera = vga_camera();
  for (const Case& c : cases) {
    SCOPED_TRACE(::testing::Message() << "height " << c.height << " m, yaw " << c.yaw_deg << " deg, tilt " << c.tilt_deg
                                      << " deg, aim (" << c.ax << ", " << c.ay << ")");
    const BoardPose truth = looking_down(c.height, c.yaw_deg, c.tilt_deg, c.ax, c.ay);
    FiducialMiss miss = FiducialMiss::None;
    const auto pose = detector.estimate(render_view(image, camera, truth), camera, &miss);
    ASSERT_TRUE(pose) << to_string(miss);
    EXPECT_EQ(pose->ids, ids);
    EXPECT_LT((pose->position - truth.position).norm(), c.max_position_m) << pose->position.transpose();
    EXPECT_LT(rotation_error_deg(pose->rotation, truth.rotation), c.max_rotation_deg);
    EXPECT_LT(pose->reprojection_rms, 1.0);
    const double yaw = std::atan2(truth.rotation(1, 0), truth.rotation(0, 0));
    EXPECT_NEAR(std::remainder(pose->yaw - yaw, 2 * M_PI), 0, c.max_rotation_deg * M_PI / 180);
  }
}

// Close (mm, < 1 deg), middle and far (cm) views, turned and tilted.
const std::vector<Case> kSingleTagCases = {
    {0.8, 0, 0, 0, 0, 0.005, 1.0},     {1.0, 30, 15, 0.05, -0.03, 0.005, 1.0}, {1.5, -120, 25, 0, 0, 0.01, 1.0},
    {3.0, 75, 10, 0.1, 0.1, 0.03, 3.0}, {5.0, 200, 0, -0.3, 0.2, 0.08, 5.0},
};

TEST(Fiducial, AprilTagSingleTagPose) {
  expect_poses(single(FiducialKind::AprilTag, "tag36h11", 3, 0.4), kSingleTagCases, {3});
}

TEST(Fiducial, AprilTagStandard41h12Pose) {
  // Its data ring lies outside the detected square (9 cells to 5): a smaller tag keeps it in view.
  expect_poses(single(FiducialKind::AprilTag, "tagStandard41h12", 12, 0.3), kSingleTagCases, {12});
}

TEST(Fiducial, ArucoSingleTagPose) {
  expect_poses(single(FiducialKind::ArUco, "DICT_4X4_50", 7, 0.4), kSingleTagCases, {7});
}

// The corners come in the printed tag's order whatever the view's rotation: the yaw is the full turn.
TEST(Fiducial, CornersInPrintedOrder) {
  for (const auto& board : {single(FiducialKind::AprilTag, "tag36h11", 0, 0.3), single(FiducialKind::ArUco, "DICT_5X5_100", 9, 0.3)}) {
    SCOPED_TRACE(to_string(board.kind));
    FiducialDetector detector(board);
    const BoardImage image = render_board(board, 1024);
    const auto camera = vga_camera();
    const auto view = render_view(image, camera, looking_down(1.0));  // upright
    const auto found = detector.detect(view);
    ASSERT_EQ(found.size(), 1u);
    const auto& p = found[0].corners;
    EXPECT_LT(p[0].x, p[1].x);  // top left -> top right
    EXPECT_LT(p[1].y, p[2].y);  // top right -> bottom right
    EXPECT_GT(p[2].x, p[3].x);  // bottom right -> bottom left
    // 0.3 m at 1 m with f = 500: 150 px sides.
    EXPECT_NEAR(p[1].x - p[0].x, 150, 1.0);
    EXPECT_NEAR(p[3].y - p[0].y, 150, 1.0);
  }
}

TEST(Fiducial, DistortedCameraThroughTheModel) {
  auto camera = vga_camera();
  camera.distortion = aerie::camera::Distortion::RadTan;
  camera.coeffs = {-0.25, 0.08, 0.001, -0.0005, 0};
  const FiducialBoard board = single(FiducialKind::AprilTag, "tag36h11", 5, 0.3);
  FiducialDetector detector(board);
  const BoardImage image = render_board(board, 2048);
  for (const auto& truth : {looking_down(1.0, 20, 10, 0.25, 0.1), looking_down(1.5, -60, 20, -0.4, -0.2)}) {
    const auto pose = detector.estimate(render_view(image, camera, truth, 2), camera);
    ASSERT_TRUE(pose);
    EXPECT_LT((pose->position - truth.position).norm(), 0.01) << pose->position.transpose();
    EXPECT_LT(rotation_error_deg(pose->rotation, truth.rotation), 1.0);
  }
}

TEST(Fiducial, CovarianceGrowsWithRange) {
  const FiducialBoard board = single(FiducialKind::ArUco, "DICT_4X4_50", 1, 0.4);
  FiducialDetector detector(board);
  const BoardImage image = render_board(board, 2048);
  const auto camera = vga_camera();
  double last = 0;
  for (const double h : {1.0, 2.0, 4.0}) {
    const auto pose = detector.estimate(render_view(image, camera, looking_down(h, 10, 5)), camera);
    ASSERT_TRUE(pose) << h;
    const Eigen::Matrix<double, 6, 6>& C = pose->covariance;
    EXPECT_TRUE(C.allFinite());
    EXPECT_GT(C.ldlt().vectorD().minCoeff(), 0) << "not positive definite at " << h << " m";
    EXPECT_GT(C(5, 5), last) << h;  // the range's variance
    last = C(5, 5);
    EXPECT_GE(pose->quality, 0.0);
    EXPECT_LE(pose->quality, 1.0);
  }
}

// A large tag for altitude with a small one in its free centre (tagCustom48h12 keeps its centre
// free for that): both from high up, the small one alone once the large one leaves the view.
TEST(Fiducial, NestedAprilTagBoardSwitchesToTheSmallTag) {
  const FiducialBoard board{FiducialKind::AprilTag, "tagCustom48h12", {{0, 0.6, 0, 0}, {1, 0.06, 0, 0}}};
  expect_poses(board, {{2.5, 15, 10, 0, 0, 0.02, 2.0}, {1.5, -20, 0, 0.02, 0, 0.01, 1.0}}, {0, 1});
  // Below about 1 m the large tag's outer data ring leaves the 640x480 view.
  expect_poses(board, {{0.8, 15, 5, 0, 0, 0.01, 1.0}, {0.3, 25, 5, 0, 0, 0.005, 1.0}, {0.2, -70, 0, 0.01, 0.01, 0.005, 1.0}}, {1});
}

// ArUco has no free centre: the small tags sit beside the large one (the last metre over them).
TEST(Fiducial, ArucoBoardBesideSwitchesToTheSmallTag) {
  const FiducialBoard board{FiducialKind::ArUco, "DICT_4X4_50", {{0, 0.5, 0, 0}, {1, 0.1, 0.42, 0}, {2, 0.1, -0.42, 0}}};
  expect_poses(board, {{2.5, 10, 10, 0, 0, 0.02, 2.0}, {1.5, 0, 0, 0, 0, 0.01, 1.0}}, {0, 1, 2});
  expect_poses(board, {{0.35, 20, 0, 0.42, 0, 0.01, 1.0}}, {1});
  expect_poses(board, {{0.35, -30, 5, -0.42, 0.01, 0.01, 1.0}}, {2});
}

// Tags of another board (ids not on this one) are detected but not used.
TEST(Fiducial, ForeignIdsAreIgnored) {
  const FiducialBoard printed{FiducialKind::AprilTag, "tag36h11", {{4, 0.3, -0.25, 0}, {8, 0.3, 0.25, 0}}};
  const FiducialBoard ours{FiducialKind::AprilTag, "tag36h11", {{8, 0.3, 0.25, 0}}};
  FiducialDetector detector(ours);
  const auto camera = vga_camera();
  const BoardPose truth = looking_down(1.5, 30, 10);
  const cv::Mat view = render_view(render_board(printed, 2048), camera, truth);
  const auto all = detector.detect(view);
  std::vector<int> ids;
  for (const auto& d : all) ids.push_back(d.id);
  std::sort(ids.begin(), ids.end());
  EXPECT_EQ(ids, (std::vector<int>{4, 8}));
  const auto pose = detector.estimate(view, camera);
  ASSERT_TRUE(pose);
  EXPECT_EQ(pose->ids, std::vector<int>{8});
  EXPECT_LT((pose->position - truth.position).norm(), 0.01);
}

TEST(Fiducial, BlankImageGivesNoDetection) {
  const auto camera = vga_camera();
  cv::Mat gradient(camera.height, camera.width, CV_8UC1);
  for (int v = 0; v < gradient.rows; ++v)
    for (int u = 0; u < gradient.cols; ++u) gradient.at<uint8_t>(v, u) = static_cast<uint8_t>((u + v) * 255 / 1120);
  for (const auto kind : {FiducialKind::AprilTag, FiducialKind::ArUco}) {
    FiducialDetector detector(single(kind, kind == FiducialKind::AprilTag ? "tag36h11" : "DICT_4X4_50", 0, 0.5));
    for (const cv::Mat& image : {cv::Mat(camera.height, camera.width, CV_8UC1, cv::Scalar(128)), gradient}) {
      FiducialMiss miss = FiducialMiss::None;
      EXPECT_TRUE(detector.detect(image).empty());
      EXPECT_FALSE(detector.estimate(image, camera, &miss));
      EXPECT_EQ(miss, FiducialMiss::NoTag);
    }
    EXPECT_THROW(detector.detect(cv::Mat()), std::invalid_argument);
    auto other = camera;
    other.width = 320;
    EXPECT_THROW(detector.estimate(gradient, other), std::invalid_argument);
  }
}

void expect_refused(const FiducialBoard& board, const std::string& part) {
  try {
    FiducialDetector detector(board);
    ADD_FAILURE() << "accepted a board that should be refused for: " << part;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(Fiducial, BadBoardsAreRefused) {
  expect_refused(single(FiducialKind::AprilTag, "tag99h99", 0, 0.5), "fiducial family 'tag99h99' does not exist for apriltag");
  expect_refused(single(FiducialKind::AprilTag, "DICT_4X4_50", 0, 0.5), "known: tag36h11");
  expect_refused(single(FiducialKind::ArUco, "DICT_9X9_50", 0, 0.5), "fiducial family 'DICT_9X9_50' does not exist for aruco");
  expect_refused(single(FiducialKind::ArUco, "DICT_4X4_50", 0, 0), "fiducial tag 0: size 0.000000 m must be > 0");
  expect_refused(single(FiducialKind::AprilTag, "tag36h11", 0, -0.2), "size -0.200000 m must be > 0");
  expect_refused(single(FiducialKind::ArUco, "DICT_4X4_50", 50, 0.3), "fiducial tag 50: no such id in aruco DICT_4X4_50 (ids 0..49)");
  expect_refused({FiducialKind::AprilTag, "tag36h11", {}}, "has no tags");
  expect_refused({FiducialKind::AprilTag, "tag36h11", {{1, 0.3, 0, 0}, {1, 0.1, 0.5, 0}}}, "fiducial tag 1 is on the board twice");
  // Beside each other but touching through the quiet zones; and tag36h11 has no free centre.
  expect_refused({FiducialKind::AprilTag, "tag36h11", {{0, 0.4, 0, 0}, {1, 0.4, 0.45, 0}}}, "fiducial tags 0 and 1 overlap");
  expect_refused({FiducialKind::AprilTag, "tag36h11", {{0, 0.6, 0, 0}, {1, 0.05, 0, 0}}}, "fiducial tags 0 and 1 overlap");
  // tagCustom48h12's free centre holds a small tag, not one too large for it or off its centre.
  EXPECT_NO_THROW(FiducialDetector({FiducialKind::AprilTag, "tagCustom48h12", {{0, 0.6, 0, 0}, {1, 0.06, 0, 0}}}));
  expect_refused({FiducialKind::AprilTag, "tagCustom48h12", {{0, 0.6, 0, 0}, {1, 0.3, 0, 0}}}, "the free centre of tag 0 is");
  expect_refused({FiducialKind::AprilTag, "tagCustom48h12", {{0, 0.6, 0, 0}, {1, 0.06, 0.15, 0}}}, "overlap");
  expect_refused({FiducialKind::ArUco, "DICT_4X4_50", {{0, 0.5, 0, 0}, {1, 0.05, 0, 0}}}, "fiducial tags 0 and 1 overlap");
  FiducialOptions bad;
  bad.max_hamming = 3;
  EXPECT_THROW(FiducialDetector(single(FiducialKind::AprilTag, "tag36h11", 0, 0.5), bad), std::invalid_argument);
}

aerie::util::Config yaml(const std::string& text) { return aerie::util::Config::parse(text, "landing.yaml"); }

void expect_config_refused(const std::string& text, const std::string& part) {
  try {
    fiducial_board(yaml(text).section("fiducial"), FiducialKind::AprilTag);
    ADD_FAILURE() << "accepted: " << text;
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(Fiducial, ConfigSection) {
  const FiducialBoard b = fiducial_board(yaml("fiducial:\n  family: tagCustom48h12\n  tags:\n"
                                              "    - {id: 0, size: 0.6}\n    - {id: 1, size: 0.06, x: 0, y: 0}\n"
                                              "  quad_decimate: 2\n")
                                             .section("fiducial"),
                                         FiducialKind::AprilTag);
  EXPECT_EQ(b.family, "tagCustom48h12");
  ASSERT_EQ(b.tags.size(), 2u);
  EXPECT_EQ(b.tags[1].id, 1);
  EXPECT_DOUBLE_EQ(b.tags[1].size, 0.06);
  EXPECT_DOUBLE_EQ(fiducial_options(yaml("fiducial:\n  quad_decimate: 2\n").section("fiducial")).quad_decimate, 2.0);
  expect_config_refused("fiducial:\n  family: tag37h11\n  tags: [{id: 0, size: 0.5}]\n",
                        "landing.yaml:fiducial: fiducial family 'tag37h11' does not exist");
  expect_config_refused("fiducial:\n  tags: [{id: 0, size: -1}]\n", "landing.yaml:fiducial: fiducial tag 0: size");
  expect_config_refused("fiducial:\n  tags: [{id: 0, size: 0.5}, {id: 1, size: 0.5, x: 0.1}]\n", "overlap");
  expect_config_refused("fiducial:\n  tags: [{id: 0, size: 0.5, z: 1}]\n", "landing.yaml:fiducial.tags[0]: unknown key 'z'");
  expect_config_refused("fiducial:\n  tags: [{id: 0}]\n", "landing.yaml:fiducial.tags[0]: needs id and size");
  expect_config_refused("fiducial:\n  family: tag36h11\n", "landing.yaml:fiducial.tags: expected a list");
  expect_config_refused("fiducial:\n  tag: []\n", "landing.yaml:fiducial: unknown key 'tag'");
  EXPECT_THROW(fiducial_kind_from_string("qr"), std::invalid_argument);
}

TEST(Fiducial, BoardImage) {
  const FiducialBoard board{FiducialKind::ArUco, "DICT_4X4_50", {{0, 0.5, 0, 0}, {1, 0.08, 0.4, 0}}};
  const BoardImage image = render_board(board, 600);
  // 4x4 markers: 6 cells detected, 8 with the quiet zone; the tags reach 0.4 + 0.08 * 8 / 6 / 2 m,
  // and one cell of the largest tag (0.5 / 6 m) of margin follows.
  EXPECT_NEAR(image.side_m, 2 * (0.4 + 0.08 * 8 / 6 / 2 + 0.5 / 6), 1e-9);
  EXPECT_EQ(image.image.size(), cv::Size(600, 600));
  EXPECT_EQ(image.image.at<uint8_t>(0, 0), 255);  // the margin is white
  EXPECT_EQ(image.image.at<uint8_t>(300, 300 - static_cast<int>(0.24 * image.pixels_per_metre)), 0);  // the black border
  EXPECT_THROW(render_board(board, 600, 0.5), std::invalid_argument);  // the small tag lies outside 0.5 m
  EXPECT_THROW(render_board(board, 40), std::invalid_argument);         // its cells would be under 2 px
}

}  // namespace
