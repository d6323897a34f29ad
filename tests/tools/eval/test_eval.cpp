// Trajectory metrics: exact values on constructed cases, and agreement with evo's
// published results on KITTI 00 (ORB-SLAM and S-PTAM estimates).
#include <gtest/gtest.h>

#include <fstream>

#include "tests/support/test_support.hpp"
#include "tools/eval/report.hpp"

using aerie::geometry::SE3;
using namespace aerie::eval;

namespace {

Trajectory square_loop(int n_per_side, double side) {
  Trajectory t;
  int k = 0;
  const Eigen::Vector3d corners[4] = {{0, 0, 0}, {side, 0, 0}, {side, side, 0}, {0, side, 0}};
  for (int s = 0; s < 4; ++s)
    for (int i = 0; i < n_per_side; ++i, ++k) {
      const double a = double(i) / n_per_side;
      const Eigen::Vector3d p = (1 - a) * corners[s] + a * corners[(s + 1) % 4];
      t.push_back(0.1 * k, SE3::from_rotation_vector(Eigen::Vector3d(0, 0, M_PI / 2 * s), p));
    }
  t.push_back(0.1 * k, SE3::from_rotation_vector(Eigen::Vector3d(0, 0, 2 * M_PI), Eigen::Vector3d::Zero()));
  return t;
}

}  // namespace

TEST(Eval, UmeyamaRecoversSimilarity) {
  std::vector<Eigen::Vector3d> est, ref;
  const SE3 T = SE3::from_rotation_vector(Eigen::Vector3d(0.3, -0.2, 1.1), Eigen::Vector3d(4, -2, 0.5));
  for (int i = 0; i < 20; ++i) {
    est.emplace_back(std::sin(i), std::cos(0.7 * i), 0.1 * i);
    ref.push_back(T.rotation() * (2.5 * est.back()) + T.translation());
  }
  const Similarity sim = umeyama(est, ref, true);
  EXPECT_NEAR(sim.scale, 2.5, 1e-12);
  EXPECT_LT((sim.transform.rotation_matrix() - T.rotation_matrix()).norm(), 1e-12);
  EXPECT_LT((sim.transform.translation() - T.translation()).norm(), 1e-12);
  const Similarity se3 = umeyama(est, est, false);
  EXPECT_DOUBLE_EQ(se3.scale, 1.0);
  EXPECT_LT(se3.transform.translation().norm(), 1e-12);
}

TEST(Eval, ExactErrorsOnConstructedTrajectories) {
  const Trajectory ref = square_loop(10, 4.0);
  EXPECT_NEAR(ref.path_length(), 16.0, 1e-12);
  // A rigidly moved copy: zero ATE after SE3 alignment, zero RPE, same per-axis.
  Trajectory moved;
  const SE3 G = SE3::from_rotation_vector(Eigen::Vector3d(0.1, 0.2, -0.4), Eigen::Vector3d(1, 2, 3));
  for (size_t i = 0; i < ref.size(); ++i) moved.push_back(ref.stamps[i], G * ref.poses[i]);
  ReportOptions opt;
  Report r = evaluate(ref, moved, opt);
  EXPECT_EQ(r.matched, ref.size());
  EXPECT_LT(r.ate.rmse, 1e-9);
  EXPECT_LT(r.rpe_trans.max, 1e-9);
  EXPECT_LT(r.axes.rpy_deg.norm(), 1e-6);
  // Without alignment the ATE equals the offset for a pure translation.
  Trajectory shifted;
  for (size_t i = 0; i < ref.size(); ++i)
    shifted.push_back(ref.stamps[i], SE3::from_rotation_vector(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.3, 0, 0.4)) *
                                         ref.poses[i]);
  opt.alignment = Alignment::None;
  r = evaluate(ref, shifted, opt);
  EXPECT_NEAR(r.ate.rmse, 0.5, 1e-12);
  EXPECT_NEAR(r.axes.position.x(), 0.3, 1e-12);
  EXPECT_NEAR(r.axes.position.z(), 0.4, 1e-12);
  // A loop whose estimate ends 0.16 m off the start: 1 % of 16 m.
  Trajectory open = ref;
  open.poses.back() = SE3::from_rotation_vector(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0.16, 0));
  const Drift d = end_point_drift(ref, open);
  EXPECT_NEAR(d.loop_closure_m, 0.16, 1e-12);
  EXPECT_NEAR(d.percent(), 1.0, 1e-9);
}

TEST(Eval, RelativeErrorPerFrameIsScaleOfStep) {
  Trajectory ref, est;
  for (int i = 0; i < 11; ++i) {
    ref.push_back(i, SE3::from_rotation_vector(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 1.0 * i)));
    est.push_back(i, SE3::from_rotation_vector(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 1.02 * i)));
  }
  const RelativeErrors rel = rpe_frames(ref, est, 1);
  ASSERT_EQ(rel.translation.size(), 10u);
  EXPECT_NEAR(rel.translation_percent(), 2.0, 1e-9);
  EXPECT_NEAR(statistics(rel.translation).rmse, 0.02, 1e-12);
  EXPECT_THROW(rpe_frames(ref, est, 0), std::invalid_argument);
}

TEST(Eval, TumRoundTripAndBadInput) {
  const auto dir = aerie::test::scratch_dir("tum");
  const Trajectory ref = square_loop(5, 2.0);
  write_tum(ref, (dir / "a.txt").string());
  const Trajectory back = read_trajectory((dir / "a.txt").string());
  ASSERT_EQ(back.size(), ref.size());
  for (size_t i = 0; i < ref.size(); ++i) {
    EXPECT_NEAR(back.stamps[i], ref.stamps[i], 1e-9);
    EXPECT_LT((back.poses[i].matrix() - ref.poses[i].matrix()).norm(), 1e-8);
  }
  write_kitti_poses(ref, (dir / "k.txt").string());
  EXPECT_EQ(read_trajectory((dir / "k.txt").string()).size(), ref.size());
  std::ofstream((dir / "bad.txt").string()) << "# comment\n0 1 2 3 0 0 0 1\n1 2 3 x 0 0 0 1\n";
  try {
    read_tum((dir / "bad.txt").string());
    FAIL() << "malformed row accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.txt:3"), std::string::npos) << e.what();
  }
  std::ofstream((dir / "short.txt").string()) << "0 1 2 3 0 0 0\n";
  EXPECT_THROW(read_tum((dir / "short.txt").string()), std::runtime_error);
  // Association by time: no overlap is an error, not an empty result.
  Trajectory late = ref;
  for (auto& t : late.stamps) t += 100;
  EXPECT_THROW(associate(ref, late, 0.01), std::runtime_error);
}

// evo_ape --align (SE3 Umeyama) and evo_rpe --delta 10 --delta_unit m on KITTI 00, as
// archived in evo's test data (res_files/*.zip stats.json).
TEST(Eval, MatchesEvoOnKitti00) {
  AERIE_REQUIRE_DATA("trajectories/evo_KITTI_00/KITTI_00_gt.txt");
  const auto dir = aerie::test::shared_data("trajectories/evo_KITTI_00");
  const Trajectory gt = read_kitti_poses((dir / "KITTI_00_gt.txt").string());
  struct Case {
    const char* file;
    double ape_rmse, ape_mean, ape_max, rpe_rmse, rpe_mean;
    size_t rpe_pairs;
  };
  for (const Case& c : {Case{"KITTI_00_ORB.txt", 1.3034497145650266, 1.1569971285389768, 3.587949120678954,
                             0.22626134329310163, 0.16901737200653275, 353},
                        Case{"KITTI_00_SPTAM.txt", 3.738487907582613, 3.4909766330848684, 7.7689774065713175,
                             0.27607109043606004, 0.22284797909537604, 355}}) {
    SCOPED_TRACE(c.file);
    const Trajectory est = read_kitti_poses((dir / c.file).string());
    ASSERT_EQ(est.size(), gt.size());
    const Stats ape = statistics(ate_errors(gt, align(est, gt, Alignment::SE3)));
    EXPECT_NEAR(ape.rmse, c.ape_rmse, 1e-6);
    EXPECT_NEAR(ape.mean, c.ape_mean, 1e-6);
    EXPECT_NEAR(ape.max, c.ape_max, 1e-6);
    const Stats rpe = statistics(rpe_path(gt, est, 10.0).translation);
    EXPECT_EQ(rpe.count, c.rpe_pairs);
    EXPECT_NEAR(rpe.rmse, c.rpe_rmse, 1e-6);
    EXPECT_NEAR(rpe.mean, c.rpe_mean, 1e-6);
  }
}
