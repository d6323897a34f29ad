// The VO on real and simulated sequences, against the targets: the static EuRoC
// excerpt (drift < 1 cm), the KITTI 06 chunk (ATE <= 0.10 m, per-frame RPE <= 1 %) and a
// simulated survey loop (end-point drift <= 0.5 % of the distance). Also the keyframe BA
// on synthetic data.
#include <gtest/gtest.h>

#include <random>

#include "air/stereo/vo/vo_config.hpp"
#include "common/sim/simulation.hpp"
#include "tests/support/test_support.hpp"
#include "tools/eval/report.hpp"
#include "tools/eval/stereo_dataset.hpp"

using namespace aerie;
using stereo::StereoCamera;

namespace {

stereo::VoParams params_from(const std::string& config) {
  stereo::VoParams p = stereo::vo_params_from_config(util::Config::load((test::source_dir() / config).string()),
                                                     stereo::kNodeSections);
  p.ba_synchronous = true;  // reproducible
  return p;
}

eval::Trajectory run(eval::StereoSequence& seq, const stereo::VoParams& params, int* lost = nullptr) {
  const auto& rig = seq.rig();
  stereo::StereoOdometry vo({rig.fx, rig.fy, rig.cx, rig.cy, rig.baseline, rig.size.width, rig.size.height}, params);
  eval::Trajectory est;
  cv::Mat l, r;
  for (size_t i = 0; i < seq.size(); ++i) {
    seq.load(i, l, r);
    const auto res = vo.process(l, r, seq.utime(i));
    if (lost) *lost += res.status == stereo::VoStatus::Lost;
    est.push_back(static_cast<double>(seq.utime(i)) * 1e-6, res.T_world_cam);
  }
  vo.flush();
  return est;
}

}  // namespace

TEST(Vo, EurocStaticExcerptDriftsLessThan1cm) {
  AERIE_REQUIRE_DATA("stereo_seq/EuRoC_V1_01_easy_f000-094");
  auto seq = eval::open_euroc(test::shared_data("stereo_seq/EuRoC_V1_01_easy_f000-094").string());
  ASSERT_EQ(seq->size(), 95u);
  int lost = 0;
  const eval::Trajectory est = run(*seq, params_from("config/vo.yaml"), &lost);
  EXPECT_EQ(lost, 0);
  // The MAV stands on the ground: every estimated position stays within 1 cm of the first.
  double worst = 0;
  for (const auto& T : est.poses) worst = std::max(worst, (T.translation() - est.poses[0].translation()).norm());
  EXPECT_LT(worst, 0.01);
  EXPECT_LT(eval::end_point_drift({}, est).loop_closure_m, 0.01);
}

TEST(Vo, KittiChunkWithinTargets) {
  AERIE_REQUIRE_DATA("stereo_seq/KITTI_odom_06_f000-050");
  auto seq = eval::open_kitti(test::shared_data("stereo_seq/KITTI_odom_06_f000-050").string());
  int lost = 0;
  const eval::Trajectory est = run(*seq, params_from("config/vo_kitti.yaml"), &lost);
  EXPECT_EQ(lost, 0);
  eval::ReportOptions ro;
  ro.max_dt = 0.002;
  const eval::Report r = eval::evaluate(seq->ground_truth(), est, ro);
  ASSERT_EQ(r.matched, 51u);
  EXPECT_LT(r.ate.rmse, 0.10);
  EXPECT_LT(r.rpe_trans_percent, 1.0);
  EXPECT_LT(r.rpe_rot.rmse, 0.2);  // degrees per frame
}

TEST(Vo, SimulatedSurveyLoopReturnsWithinHalfPercent) {
  sim::WorldConfig wc;
  const sim::World world = sim::World::room(wc);
  sim::RigConfig rig;  // 376 x 240, baseline 0.12 m, 98 x 73 deg
  rig.noise_sigma = 1.0;
  // One loop (~29 m) at 2 m/s and 20 Hz keeps the test short (bench/vo flies ten at 1 m/s).
  sim::StereoSimulation simulation(world, rig, sim::Trajectory::survey_loops(world, 1, 2.0), 20.0);
  const auto K = simulation.intrinsics();
  stereo::VoParams p = params_from("config/vo.yaml");
  stereo::StereoOdometry vo({K.fx, K.fy, K.cx, K.cy, K.baseline, K.width, K.height}, p);
  eval::Trajectory est, gt;
  sim::StereoFrame f;
  int lost = 0;
  while (simulation.next(f)) {
    const auto res = vo.process(f.left, f.right, f.utime);
    lost += res.status == stereo::VoStatus::Lost;
    est.push_back(static_cast<double>(f.utime) * 1e-6, res.T_world_cam);
    gt.push_back(static_cast<double>(f.utime) * 1e-6, f.T_world_left);
  }
  vo.flush();
  EXPECT_EQ(lost, 0);
  const eval::Drift d = eval::end_point_drift(gt, est);
  EXPECT_GT(d.distance_m, 25.0);
  EXPECT_LT(d.percent(), 0.5);
  // The loop closes on the start pose: the estimate's own end point is as close.
  EXPECT_LT(d.loop_closure_m, 0.005 * d.distance_m);
  const auto aligned = eval::align(est, gt, eval::Alignment::SE3);
  EXPECT_LT(eval::statistics(eval::ate_errors(gt, aligned)).rmse, 0.10);
}

TEST(Vo, BundleAdjustmentPullsPerturbedKeyframesBack) {
  StereoCamera cam{400, 400, 188, 120, 0.12, 376, 240};
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> g(0, 0.3);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 300; ++i) points.emplace_back(4 * u(rng), 2 * u(rng), 8 + 4 * u(rng));
  std::vector<stereo::Keyframe> kfs;
  std::vector<geometry::SE3> truth, init;
  for (int k = 0; k < 6; ++k) {
    const geometry::SE3 T = geometry::SE3::from_rotation_vector(Eigen::Vector3d(0, 0.02 * k, 0),
                                                                Eigen::Vector3d(0.1 * k, 0, 0.4 * k));
    truth.push_back(T);
    stereo::Keyframe kf;
    kf.id = k;
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d Xc = T.inverse() * points[i];
      const Eigen::Vector2d uv = cam.project(Xc) + Eigen::Vector2d(g(rng), g(rng));
      if (uv.x() < 0 || uv.x() >= cam.width || uv.y() < 0 || uv.y() >= cam.height) continue;
      kf.observations.push_back({static_cast<int64_t>(i), uv, cam.disparity(Xc.z()) + g(rng)});
    }
    kfs.push_back(kf);
    // Odometry error: 3 cm and 0.3 degrees per keyframe, accumulating.
    init.push_back(k == 0 ? T
                          : T * geometry::SE3::from_rotation_vector(Eigen::Vector3d(0.005 * k, 0, 0),
                                                                    Eigen::Vector3d(0.03 * k, -0.02 * k, 0.03 * k)));
  }
  stereo::BaParams bp;
  const stereo::BaResult r = stereo::bundle_adjust(kfs, init, cam, bp);
  ASSERT_EQ(r.window.size(), kfs.size());
  EXPECT_GT(r.landmarks, 200);  // points seen by at least two keyframes
  EXPECT_LT(r.final_rms_px, r.initial_rms_px);
  for (size_t k = 1; k < kfs.size(); ++k) {
    const geometry::SE3 E = truth[k].inverse() * r.window[k].second;
    EXPECT_LT(E.translation().norm(), 0.01) << "keyframe " << k;
    EXPECT_LT(geometry::rotation_angle(E.rotation_matrix()) * 180 / M_PI, 0.05) << "keyframe " << k;
  }
}

TEST(Vo, RejectsWrongImagesAndBadConfig) {
  stereo::StereoOdometry vo(StereoCamera{163, 163, 188, 120, 0.12, 376, 240}, stereo::VoParams{});
  const cv::Mat small(100, 100, CV_8UC1, cv::Scalar(0)), ok(240, 376, CV_8UC1, cv::Scalar(0));
  EXPECT_THROW(vo.process(small, small, 0), std::invalid_argument);
  EXPECT_THROW(vo.process(ok, cv::Mat(240, 376, CV_8UC3), 0), std::invalid_argument);
  // A featureless pair: no crash, initialising then lost/reset, pose stays at the origin.
  const auto r0 = vo.process(ok, ok, 0);
  EXPECT_EQ(r0.status, stereo::VoStatus::Initialising);
  const auto r1 = vo.process(ok, ok, 50000);
  EXPECT_EQ(r1.status, stereo::VoStatus::Lost);
  EXPECT_FALSE(r1.message.empty());
  const auto r2 = vo.process(ok, ok, 100000);
  EXPECT_EQ(r2.status, stereo::VoStatus::Reset);
  EXPECT_LT(r2.T_world_cam.translation().norm(), 1e-12);
  try {
    stereo::vo_params_from_config(util::Config::parse("features:\n  bucket_x: 6\n", "typo.yaml"));
    FAIL() << "unknown key accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("features.bucket_x"), std::string::npos) << e.what();
  }
  EXPECT_THROW(stereo::vo_params_from_config(util::Config::parse("depth:\n  every: 0\n", "bad.yaml")),
               std::runtime_error);
}
