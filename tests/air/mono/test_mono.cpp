// The monocular VO on frames rendered by common/sim (the stereo renderer's left view with its
// ground truth): model selection of the two-view initialisation, the trajectory after Sim(3)
// alignment, bit-identical repeated runs with the BA thread, a pure rotation that must not
// initialise, re-initialisation after blank frames, the input checks and the config reader.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "air/mono/mono_config.hpp"
#include "common/sim/simulation.hpp"
#include "common/sim/stereo_renderer.hpp"
#include "tests/support/test_support.hpp"
#include "tools/eval/metrics.hpp"

using namespace aerie;

namespace {

mono::MonoParams default_params() {
  return mono::mono_params_from_config(util::Config::load((test::source_dir() / "config/mono.yaml").string()),
                                       mono::kMonoNodeSections);
}

mono::PinholeCamera camera_of(const sim::Intrinsics& K) { return {K.fx, K.fy, K.cx, K.cy, K.width, K.height}; }

// Camera looking along `forward` (world), image y along `down`.
geometry::SE3 look(const Eigen::Vector3d& position, const Eigen::Vector3d& forward, const Eigen::Vector3d& down) {
  Eigen::Matrix3d R;
  const Eigen::Vector3d z = forward.normalized(), y = (down - down.dot(z) * z).normalized();
  R.col(0) = y.cross(z);
  R.col(1) = y;
  R.col(2) = z;
  return geometry::SE3(R, position);
}

struct MonoRun {
  std::vector<mono::MonoResult> results;
  eval::Trajectory est, gt;
};

// Renders `frames` views along pose(k) and runs the odometry on them.
MonoRun run_poses(const std::function<geometry::SE3(int)>& pose, int frames, const mono::MonoParams& params,
              const std::function<bool(int)>& blank = {}) {
  const sim::World world = sim::World::room(sim::WorldConfig{});
  sim::RigConfig rig;
  rig.noise_sigma = 1.0;
  const sim::StereoRenderer renderer(world, rig);
  mono::MonoOdometry vo(camera_of(renderer.intrinsics()), params);
  MonoRun run;
  for (int k = 0; k < frames; ++k) {
    const int64_t utime = 50000 * k;
    sim::StereoFrame f = renderer.render_mono(pose(k), utime, k);
    if (blank && blank(k)) f.left.setTo(0);
    run.results.push_back(vo.process(f.left, utime));
    run.est.push_back(utime * 1e-6, run.results.back().T_world_cam);
    run.gt.push_back(utime * 1e-6, f.T_world_left);
  }
  vo.flush();
  return run;
}

// The survey loop of tests/air/stereo's VO test (1 m/s, 20 Hz), its first `frames` frames.
MonoRun run_survey(int frames, const mono::MonoParams& params, const std::function<bool(int)>& blank = {}) {
  const sim::World world = sim::World::room(sim::WorldConfig{});
  sim::RigConfig rig;
  rig.noise_sigma = 1.0;
  sim::StereoSimulation simulation(world, rig, sim::Trajectory::survey_loops(world, 1, 1.0), 20.0);
  const sim::StereoRenderer renderer(world, rig);
  std::vector<geometry::SE3> poses;
  sim::StereoFrame f;
  for (int k = 0; k < frames; ++k) poses.push_back(simulation.frame(k).T_world_left);
  return run_poses([&](int k) { return poses[k]; }, frames, params, blank);
}

int first_ok(const MonoRun& r) {
  for (size_t i = 0; i < r.results.size(); ++i)
    if (r.results[i].status == mono::MonoStatus::Ok || r.results[i].status == mono::MonoStatus::Reset)
      return static_cast<int>(i);
  return -1;
}

}  // namespace

TEST(MonoInit, PlanarFloorUnderRotationAndTranslationPicksTheHomography) {
  // Looking straight down at the floor from 1.5 m, sliding sideways and yawing.
  const auto pose = [](int k) {
    const double yaw = 0.01 * k;
    return look(Eigen::Vector3d(-2.0 + 0.03 * k, 0.5, 1.5), Eigen::Vector3d(0, 0, -1),
                Eigen::Vector3d(std::sin(yaw), -std::cos(yaw), 0));
  };
  const MonoRun r = run_poses(pose, 30, default_params());
  const int k = first_ok(r);
  ASSERT_GE(k, 0) << r.results.back().message;
  EXPECT_EQ(r.results[k].init_model, mono::Model::Homography) << r.results[k].message;
  EXPECT_GT(r.results[k].init_ratio_h, 0.45);
}

TEST(MonoInit, ThreeDimensionalRoomPicksTheEssentialMatrix) {
  // Looking into a corner of the room (floor, two walls, obstacles), moving sideways.
  const auto pose = [](int k) {
    return look(Eigen::Vector3d(1.0 + 0.03 * k, -1.0 - 0.02 * k, 1.5), Eigen::Vector3d(1, 1, -0.2), Eigen::Vector3d(0, 0, -1));
  };
  const MonoRun r = run_poses(pose, 30, default_params());
  const int k = first_ok(r);
  ASSERT_GE(k, 0) << r.results.back().message;
  EXPECT_EQ(r.results[k].init_model, mono::Model::Essential) << r.results[k].message;
  EXPECT_LT(r.results[k].init_ratio_h, 0.45);
}

TEST(MonoInit, PureRotationDoesNotInitialise) {
  const auto pose = [](int k) {
    const double yaw = 0.02 * k;  // 1.1 deg per frame about the camera centre, 34 deg in all
    return look(Eigen::Vector3d(0, 0, 1.5), Eigen::Vector3d(std::cos(yaw), std::sin(yaw), -0.2), Eigen::Vector3d(0, 0, -1));
  };
  const MonoRun r = run_poses(pose, 30, default_params());
  for (const auto& res : r.results) {
    EXPECT_EQ(res.status, mono::MonoStatus::Initialising) << "frame " << res.frame << ": " << res.message;
    EXPECT_EQ(res.landmarks, 0);
  }
  EXPECT_NE(r.results.back().message.find("initialising"), std::string::npos) << r.results.back().message;
}

TEST(MonoVo, SurveyLoopWithinBoundAfterSim3Alignment) {
  mono::MonoParams p = default_params();
  p.ba_synchronous = true;
  const MonoRun r = run_survey(300, p);  // 15 s, ~14 m of the loop
  const int k = first_ok(r);
  ASSERT_GE(k, 0);
  int lost = 0, keyframes = 0;
  for (const auto& res : r.results) {
    lost += res.status == mono::MonoStatus::Lost;
    keyframes += res.keyframe;
  }
  std::printf("init frame %d: %s\nlast: %d kf %d lm %d tracks; keyframes made %d\n", k, r.results[k].message.c_str(),
              r.results.back().keyframes, r.results.back().landmarks, r.results.back().tracks, keyframes);
  EXPECT_EQ(lost, 0);
  // Scored from the initialisation on (before it the pose is the start pose by definition).
  eval::Trajectory est, gt;
  for (size_t i = k; i < r.results.size(); ++i) {
    est.push_back(r.est.stamps[i], r.est.poses[i]);
    gt.push_back(r.gt.stamps[i], r.gt.poses[i]);
  }
  eval::Similarity s;
  const auto aligned = eval::align(est, gt, eval::Alignment::Sim3, &s);
  const auto ate = eval::statistics(eval::ate_errors(gt, aligned));
  double length = 0;
  for (size_t i = 1; i < gt.size(); ++i) length += (gt.poses[i].translation() - gt.poses[i - 1].translation()).norm();
  std::printf("ATE rmse %.4f m over %.2f m, scale %.4f\n", ate.rmse, length, s.scale);
  EXPECT_GT(length, 10.0);
  EXPECT_LT(ate.rmse, 0.01 * length);
}

TEST(MonoVo, TwoRunsWithTheBaThreadGiveIdenticalPoses) {
  mono::MonoParams p = default_params();
  ASSERT_FALSE(p.ba_synchronous);  // the thread, its results applied at the next keyframe
  const MonoRun a = run_survey(160, p), b = run_survey(160, p);
  ASSERT_EQ(a.results.size(), b.results.size());
  int applied = 0;
  for (size_t i = 0; i < a.results.size(); ++i) {
    const auto& x = a.results[i].T_world_cam;
    const auto& y = b.results[i].T_world_cam;
    ASSERT_EQ(x.translation(), y.translation()) << "frame " << i;
    ASSERT_EQ(x.rotation().coeffs(), y.rotation().coeffs()) << "frame " << i;
    EXPECT_EQ(a.results[i].ba_applied, b.results[i].ba_applied);
    applied += a.results[i].ba_applied;
  }
  EXPECT_GT(applied, 2);  // the BA did change the poses
}

TEST(MonoVo, BlankFramesLoseTheMapAndANewOneIsMade) {
  mono::MonoParams p = default_params();
  p.ba_synchronous = true;
  const int first_blank = 80, blanks = p.max_skipped_frames + 3;
  const MonoRun r = run_survey(200, p, [&](int k) { return k >= first_blank && k < first_blank + blanks; });
  int lost_at = -1, reset_at = -1;
  for (const auto& res : r.results) {
    if (res.frame >= first_blank && res.frame < first_blank + blanks) {
      EXPECT_TRUE(res.skipped);
      EXPECT_EQ(res.input_problem, "blank");
    }
    if (lost_at < 0 && res.status == mono::MonoStatus::Lost) lost_at = static_cast<int>(res.frame);
    if (lost_at >= 0 && reset_at < 0 && res.status == mono::MonoStatus::Reset) reset_at = static_cast<int>(res.frame);
  }
  ASSERT_EQ(r.results[first_blank - 1].status, mono::MonoStatus::Ok);
  EXPECT_EQ(lost_at, first_blank + p.max_skipped_frames) << r.results[first_blank + p.max_skipped_frames].message;
  ASSERT_GT(reset_at, first_blank + blanks) << r.results.back().message;
  EXPECT_NE(r.results[reset_at].message.find("new map after a loss"), std::string::npos) << r.results[reset_at].message;
  EXPECT_GT(r.results[reset_at].scale_generation, r.results[first_blank - 1].scale_generation);
  // Tracking goes on in the new map to the end.
  for (size_t i = reset_at + 1; i < r.results.size(); ++i) EXPECT_EQ(r.results[i].status, mono::MonoStatus::Ok) << i;
  EXPECT_GT(r.results.back().landmarks, 50);
}

TEST(MonoVo, FrozenAndWrongInputAreRefusedWithAReason) {
  const sim::World world = sim::World::room(sim::WorldConfig{});
  const sim::StereoRenderer renderer(world, sim::RigConfig{});
  mono::MonoOdometry vo(camera_of(renderer.intrinsics()), default_params());
  const auto f = renderer.render_mono(look(Eigen::Vector3d(0, 0, 1.5), Eigen::Vector3d(1, 0, -0.2), Eigen::Vector3d(0, 0, -1)), 0, 0);
  EXPECT_FALSE(vo.process(f.left, 0).skipped);
  const auto again = vo.process(f.left.clone(), 50000);
  EXPECT_TRUE(again.skipped);
  EXPECT_EQ(again.input_problem, "frozen");
  EXPECT_NE(again.message.find("frozen camera"), std::string::npos);
  const auto white = vo.process(cv::Mat(f.left.size(), CV_8UC1, cv::Scalar(255)), 100000);
  EXPECT_EQ(white.input_problem, "blank");
  try {
    vo.process(cv::Mat(100, 100, CV_8UC1, cv::Scalar(3)), 150000);
    FAIL() << "a wrong size was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("100x100"), std::string::npos) << e.what();
  }
  EXPECT_THROW(vo.process(cv::Mat(f.left.size(), CV_8UC3), 200000), std::invalid_argument);
}

TEST(MonoConfig, ShippedConfigIsTheDefaults) {
  const mono::MonoParams p = default_params();
  const mono::MonoParams d;
  EXPECT_EQ(p.init.homography_ratio, d.init.homography_ratio);
  EXPECT_EQ(p.init.min_parallax_deg, d.init.min_parallax_deg);
  EXPECT_EQ(p.keyframe_parallax_deg, d.keyframe_parallax_deg);
  EXPECT_EQ(p.ba.window, d.ba.window);
  EXPECT_EQ(p.klt_window, d.klt_window);
  EXPECT_EQ(p.klt_levels, d.klt_levels);
  EXPECT_EQ(p.tracking, mono::TrackingMode::Klt);
  EXPECT_EQ(p.ba_synchronous, false);
}

TEST(MonoConfig, UnknownKeysAndBadValuesAreRefused) {
  auto message = [](const std::string& yaml) {
    try {
      mono::mono_params_from_config(util::Config::parse(yaml, "mono_test.yaml"), mono::kMonoNodeSections);
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string unknown = message("init:\n  min_parralax_deg: 2\n");
  EXPECT_NE(unknown.find("mono_test.yaml"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("init.min_parralax_deg"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("line 2"), std::string::npos) << unknown;
  const std::string ratio = message("init:\n  homography_ratio: 1.5\n");
  EXPECT_NE(ratio.find("init.homography_ratio"), std::string::npos) << ratio;
  EXPECT_NE(message("tracking:\n  mode: sift\n").find("tracking.mode must be klt or brief"), std::string::npos);
  EXPECT_NE(message("ba:\n  window: 2\n").find("ba.window"), std::string::npos);
  EXPECT_NE(message("ba:\n  apply: later\n").find("ba.apply"), std::string::npos);
  EXPECT_NE(message("pnp:\n  lost_min_inliers: two\n").find("pnp.lost_min_inliers"), std::string::npos);
  EXPECT_EQ(message("node:\n  input: CAM_LEFT\n"), "accepted");  // the node's section is read by the node
}
