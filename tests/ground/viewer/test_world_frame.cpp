// The viewer's display frame (ground/viewer/world_frame.hpp) and its key table against
// docs/viewer.md. No rendering.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "ground/viewer/keys.hpp"
#include "ground/viewer/world_frame.hpp"

using namespace aerie;
using namespace aerie::viewer;

namespace {

geometry::SE3 pose(double rx, double ry, double rz, const Eigen::Vector3d& t) {
  return geometry::SE3::from_rotation_vector(Eigen::Vector3d(rx, ry, rz), t);
}

// A wavy 3D trajectory (not degenerate) in the ground truth's world, 20 Hz from t0.
eval::Trajectory moving_gt(int n, double t0 = 1403715273.262) {
  eval::Trajectory gt;
  for (int i = 0; i < n; ++i) {
    const double s = 0.05 * i;
    gt.push_back(t0 + s, pose(0.1 * std::sin(s), 0.05 * s, 0.3 * s,
                              Eigen::Vector3d(2 * std::cos(s), 1.5 * std::sin(1.3 * s), 1 + 0.4 * std::sin(0.7 * s))));
  }
  return gt;
}

// The same motion seen from another world: T_vo_gt * T_gt_cam.
eval::Trajectory in_other_world(const eval::Trajectory& gt, const geometry::SE3& T_vo_gt) {
  eval::Trajectory vo;
  for (size_t i = 0; i < gt.size(); ++i) vo.push_back(gt.stamps[i], T_vo_gt * gt.poses[i]);
  return vo;
}

void expect_se3_near(const geometry::SE3& a, const geometry::SE3& b, double tol) {
  EXPECT_LT((a.translation() - b.translation()).norm(), tol) << a.translation().transpose() << " vs "
                                                             << b.translation().transpose();
  EXPECT_LT(geometry::rotation_angle(a.rotation_matrix().transpose() * b.rotation_matrix()), tol);
}

}  // namespace

TEST(WorldFrame, GroundTruthAlignmentRecoversAKnownRotationAndTranslation) {
  const geometry::SE3 T_vo_gt = pose(0.4, -1.1, 2.0, Eigen::Vector3d(-3.2, 0.7, 4.7));
  const eval::Trajectory gt = moving_gt(200);
  const auto a = align_ground_truth(gt, in_other_world(gt, T_vo_gt));
  ASSERT_TRUE(a);
  EXPECT_FALSE(a->degenerate);
  EXPECT_EQ(a->pairs, 200u);
  expect_se3_near(a->T_vo_gt, T_vo_gt, 1e-6);
  EXPECT_LT(a->ate_m, 1e-6);
  EXPECT_EQ(a->label().rfind("GT aligned: SE(3), 200 pairs, ATE 0.000 m", 0), 0u) << a->label();
}

TEST(WorldFrame, AlignmentUsesOnlyPairsMatchedByTime) {
  const geometry::SE3 T_vo_gt = pose(0, 0, 0.5, Eigen::Vector3d(1, 2, 3));
  const eval::Trajectory gt = moving_gt(100);
  eval::Trajectory vo;  // every other frame, and ten frames stamped 0.5 s off (no GT pose there)
  const eval::Trajectory all = in_other_world(gt, T_vo_gt);
  for (size_t i = 0; i < all.size(); i += 2) vo.push_back(all.stamps[i], all.poses[i]);
  for (int i = 0; i < 10; ++i) vo.push_back(all.stamps.back() + 0.5 + i, geometry::SE3());
  const auto a = align_ground_truth(gt, vo);
  ASSERT_TRUE(a);
  EXPECT_EQ(a->pairs, 50u);
  expect_se3_near(a->T_vo_gt, T_vo_gt, 1e-6);
  // Nothing matches in time: no alignment (yet), no exception.
  eval::Trajectory late;
  for (int i = 0; i < 10; ++i) late.push_back(1e6 + i, geometry::SE3());
  EXPECT_FALSE(align_ground_truth(gt, late));
}

TEST(WorldFrame, AVehicleAtRestIsAlignedByItsOrientations) {
  // EuRoC V1_01's first frames: the MAV stands still, positions within millimetres.
  const geometry::SE3 T_vo_gt = pose(1.2, 0.3, -0.4, Eigen::Vector3d(0.5, -4.0, 1.0));
  std::mt19937 rng(3);
  std::normal_distribution<double> mm(0, 0.001);
  eval::Trajectory gt;
  for (int i = 0; i < 95; ++i)
    gt.push_back(100 + 0.05 * i, pose(0.01 + mm(rng), -0.02 + mm(rng), 1.5, Eigen::Vector3d(0.8 + mm(rng), 2.1 + mm(rng), 0.9)));
  const auto a = align_ground_truth(gt, in_other_world(gt, T_vo_gt));
  ASSERT_TRUE(a);
  EXPECT_TRUE(a->degenerate);
  expect_se3_near(a->T_vo_gt, T_vo_gt, 1e-6);
  EXPECT_LT(a->ate_m, 1e-6);
  EXPECT_NE(a->label().find("at rest"), std::string::npos) << a->label();
}

TEST(WorldFrame, GravityFromAccelerometerSamplesMapsMeasuredGravityToMinusZ) {
  // An IMU at rest, tilted: specific force is +g along the world's up seen in the body.
  const Eigen::Matrix3d R_world_body = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 0.5).normalized()).toRotationMatrix();
  const Eigen::Vector3d f_body = R_world_body.transpose() * Eigen::Vector3d(0, 0, 9.81);
  std::vector<Eigen::Vector3d> samples;
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0, 0.05);
  for (int i = 0; i < 200; ++i) samples.push_back(f_body + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& s : samples) mean += s;
  mean /= 200.0;
  const geometry::SE3 T_body_cam = pose(-1.2, 0.1, -1.5, Eigen::Vector3d(0.05, -0.02, 0.01));  // EuRoC-like
  const geometry::SE3 T_vo_cam = pose(0.02, -0.01, 0.03, Eigen::Vector3d(0.1, 0, 0));          // VO's first pose
  const Eigen::Matrix3d R = gravity_rotation(samples, T_body_cam, T_vo_cam);
  EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
  // Measured gravity (-f, averaged) in VO's world, through R: exactly along -z.
  const Eigen::Vector3d g_vo = -(T_vo_cam.rotation_matrix() * T_body_cam.rotation_matrix().transpose() * mean);
  const Eigen::Vector3d g_display = R * g_vo;
  EXPECT_NEAR(g_display.x(), 0, 1e-12);
  EXPECT_NEAR(g_display.y(), 0, 1e-12);
  EXPECT_NEAR(g_display.z(), -g_vo.norm(), 1e-12);
  // Not at rest (or not an accelerometer): refused with the reason.
  try {
    gravity_rotation({Eigen::Vector3d(0, 0, 2)}, T_body_cam, T_vo_cam);
    FAIL() << "expected a refusal";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("not at rest"), std::string::npos) << e.what();
  }
  EXPECT_THROW(gravity_rotation({}, T_body_cam, T_vo_cam), std::invalid_argument);
}

TEST(WorldFrame, FirstGroundTruthPoseMakesTheDisplayTheGroundTruthsWorld) {
  // VO's world is its first camera: T_vo_cam(0) = identity; the camera looks forward, level
  // (optical z along world x, y down), 1.2 m up.
  Eigen::Matrix3d R_gt_cam;
  R_gt_cam.col(0) = Eigen::Vector3d(0, -1, 0);
  R_gt_cam.col(1) = Eigen::Vector3d(0, 0, -1);
  R_gt_cam.col(2) = Eigen::Vector3d(1, 0, 0);
  const geometry::SE3 T_gt_cam(R_gt_cam, Eigen::Vector3d(3, 4, 1.2));
  const geometry::SE3 T_D_vo = frame_from_first_gt_pose(T_gt_cam, geometry::SE3());
  // A point 2 m ahead of the first camera lies 2 m along world x at the camera's height.
  const Eigen::Vector3d p = T_D_vo * Eigen::Vector3d(0, 0, 2);
  EXPECT_LT((p - Eigen::Vector3d(5, 4, 1.2)).norm(), 1e-12);
  // A VO world that already is the ground truth's (the simulator's): the identity.
  const geometry::SE3 same = frame_from_first_gt_pose(T_gt_cam, T_gt_cam);
  expect_se3_near(same, geometry::SE3(), 1e-12);
  EXPECT_EQ(gravity_label(GravitySource::FirstGtPose), "gravity: first GT pose");
  EXPECT_EQ(gravity_label(GravitySource::Imu), "gravity: IMU");
  EXPECT_EQ(gravity_label(GravitySource::None), "gravity: none (camera frame)");
}

TEST(ViewerKeys, TheDocsKeyTableIsTheCodes) {
  // docs/viewer.md "Keys": a table | key | action | whose rows are keys.hpp's, in order.
  std::ifstream in(AERIE_SOURCE_DIR "/docs/viewer.md");
  ASSERT_TRUE(in) << "cannot read docs/viewer.md";
  std::string line;
  bool in_section = false;
  std::vector<std::pair<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    if (line.rfind("## ", 0) == 0) in_section = line == "## Keys";
    if (!in_section || line.rfind("| `", 0) != 0) continue;
    // | `key` | action |
    const size_t k1 = line.find('`'), k2 = line.find('`', k1 + 1);
    const size_t bar = line.find('|', k2);
    const size_t end = line.rfind('|');
    ASSERT_TRUE(k2 != std::string::npos && bar != std::string::npos && end > bar) << line;
    std::string action = line.substr(bar + 1, end - bar - 1);
    action.erase(0, action.find_first_not_of(' '));
    action.erase(action.find_last_not_of(' ') + 1);
    rows.emplace_back(line.substr(k1 + 1, k2 - k1 - 1), action);
  }
  ASSERT_EQ(rows.size(), kKeys.size()) << "docs/viewer.md's \"## Keys\" table has " << rows.size() << " rows";
  for (size_t i = 0; i < kKeys.size(); ++i) {
    EXPECT_EQ(rows[i].first, kKeys[i].key) << "row " << i + 1;
    EXPECT_EQ(rows[i].second, kKeys[i].action) << "row " << i + 1 << " (`" << kKeys[i].key << "`)";
  }
}
