// Ground truth as users download it: TUM, EuRoC CSV and KITTI poses detected from the content,
// ATE against a known trajectory from each, the refusal of an unknown layout, the loop rule of
// the end-point drift, and --groundtruth (the readers' explicit file) on the shared sequences.
#include <gtest/gtest.h>

#include <fstream>
#include <iomanip>
#include <sstream>

#include "tests/support/test_support.hpp"
#include "tools/eval/report.hpp"
#include "tools/eval/stereo_dataset.hpp"

using aerie::geometry::SE3;
using namespace aerie::eval;

namespace {

// A 4 m x 2 m rectangle flown at 1.5 m height, yawing along it, stamped from t0 at 20 Hz.
Trajectory rectangle(double t0, bool closed) {
  Trajectory t;
  const int n = 40;
  for (int k = 0; k <= (closed ? n : n / 2); ++k) {
    const double s = 12.0 * k / n;  // arc length along the 12 m perimeter
    const Eigen::Vector3d p = s < 4 ? Eigen::Vector3d(s, 0, 1.5)
                              : s < 6 ? Eigen::Vector3d(4, s - 4, 1.5)
                              : s < 10 ? Eigen::Vector3d(10 - s, 2, 1.5)
                                       : Eigen::Vector3d(0, 12 - s, 1.5);
    t.push_back(t0 + 0.05 * k, SE3::from_rotation_vector(Eigen::Vector3d(0, 0, 0.1 * k), p));
  }
  return t;
}

void write_euroc_csv(const Trajectory& t, const std::string& path) {
  std::ofstream out(path);
  out << "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z [], "
         "v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], "
         "b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]\n"
      << std::setprecision(12);
  for (size_t i = 0; i < t.size(); ++i) {
    const auto& q = t.poses[i].rotation();
    const auto& p = t.poses[i].translation();
    out << std::llround(t.stamps[i] * 1e9) << ',' << p.x() << ',' << p.y() << ',' << p.z() << ',' << q.w() << ','
        << q.x() << ',' << q.y() << ',' << q.z() << ",0,0,0,0,0,0,0,0,0\n";
  }
}

void write_times(const Trajectory& t, const std::string& path) {
  std::ofstream out(path);
  out << std::fixed << std::setprecision(9);
  for (double s : t.stamps) out << s << '\n';
}

void expect_same(const Trajectory& a, const Trajectory& b, double stamp_tol) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_NEAR(a.stamps[i], b.stamps[i], stamp_tol) << i;
    EXPECT_LT((a.poses[i].matrix() - b.poses[i].matrix()).norm(), 1e-7) << i;
  }
}

}  // namespace

TEST(GroundTruth, EachFormatDetectedAndRead) {
  const auto dir = aerie::test::scratch_dir("formats");
  const Trajectory ref = rectangle(1403715273.262142976, true);  // EuRoC-like epoch stamps
  const std::string tum = (dir / "gt.txt").string(), csv = (dir / "data.csv").string(),
                    kitti = (dir / "poses.txt").string(), times = (dir / "times.txt").string();
  write_tum(ref, tum);
  write_euroc_csv(ref, csv);
  write_kitti_poses(ref, kitti);
  write_times(ref, times);

  TrajectoryFormat f;
  expect_same(read_trajectory(tum, "", &f), ref, 1e-6);
  EXPECT_EQ(f, TrajectoryFormat::Tum);
  expect_same(read_trajectory(csv, "", &f), ref, 1e-6);  // ns stamps: 1e-6 s after the double's rounding
  EXPECT_EQ(f, TrajectoryFormat::EurocCsv);
  expect_same(read_trajectory(kitti, times, &f), ref, 1e-6);
  EXPECT_EQ(f, TrajectoryFormat::KittiPoses);
  EXPECT_EQ(detect_trajectory_format(csv), TrajectoryFormat::EurocCsv);
  EXPECT_STREQ(format_name(TrajectoryFormat::KittiPoses), "KITTI poses");
  // Without times.txt the KITTI poses are numbered 0, 1, 2 ...
  const Trajectory numbered = read_trajectory(kitti);
  EXPECT_EQ(numbered.stamps[3], 3.0);

  // A motion-capture data.csv (8 columns, ns stamps) is EuRoC too, not TUM.
  std::ofstream((dir / "vicon.csv").string()) << "#timestamp [ns],p_x,p_y,p_z,q_w,q_x,q_y,q_z\n"
                                              << "1403715273262142976,1,2,3,1,0,0,0\n"
                                              << "1403715273312142976,1,2,4,1,0,0,0\n";
  const Trajectory vicon = read_trajectory((dir / "vicon.csv").string(), "", &f);
  EXPECT_EQ(f, TrajectoryFormat::EurocCsv);
  ASSERT_EQ(vicon.size(), 2u);
  EXPECT_NEAR(vicon.stamps[1] - vicon.stamps[0], 0.05, 1e-6);
  EXPECT_EQ(vicon.poses[1].translation(), Eigen::Vector3d(1, 2, 4));
}

TEST(GroundTruth, AteAgainstKnownTrajectoryFromEveryFormat) {
  const auto dir = aerie::test::scratch_dir("ate");
  const Trajectory ref = rectangle(1403715273.0, true);
  write_tum(ref, (dir / "gt.txt").string());
  write_euroc_csv(ref, (dir / "gt.csv").string());
  write_kitti_poses(ref, (dir / "poses.txt").string());
  write_times(ref, (dir / "times.txt").string());
  // The estimate: the reference 0.3 m east and 0.4 m up of it (ATE 0.5 m unaligned, 0 aligned).
  Trajectory est;
  const SE3 shift = SE3::from_rotation_vector(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.3, 0, 0.4));
  for (size_t i = 0; i < ref.size(); ++i) est.push_back(ref.stamps[i], shift * ref.poses[i]);
  for (const auto& [file, times] : {std::pair{"gt.txt", ""}, std::pair{"gt.csv", ""}, std::pair{"poses.txt", "times.txt"}}) {
    const Trajectory gt = read_trajectory((dir / file).string(), *times ? (dir / times).string() : "");
    ReportOptions opt;
    opt.alignment = Alignment::None;
    Report r = evaluate(gt, est, opt);
    EXPECT_EQ(r.matched, ref.size()) << file;
    EXPECT_NEAR(r.ate.rmse, 0.5, 1e-6) << file;
    opt.alignment = Alignment::SE3;
    r = evaluate(gt, est, opt);
    EXPECT_LT(r.ate.rmse, 1e-6) << file;
  }
}

TEST(GroundTruth, UnknownFormatNamesFileAndLine) {
  const auto dir = aerie::test::scratch_dir("unknown");
  const std::string path = (dir / "odd.txt").string();
  std::ofstream(path) << "# x y z yaw\n\n1.0 2.0 3.0 0.5 9\n2.0 2.0 3.0 0.5 9\n";
  for (auto read : {+[](const std::string& p) { read_trajectory(p); },
                    +[](const std::string& p) { detect_trajectory_format(p); }}) {
    try {
      read(path);
      FAIL() << "5 numbers a row accepted";
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("odd.txt:3: 5 numbers"), std::string::npos) << what;
      EXPECT_NE(what.find("TUM"), std::string::npos) << what;
      EXPECT_NE(what.find("EuRoC CSV"), std::string::npos) << what;
      EXPECT_NE(what.find("KITTI"), std::string::npos) << what;
    }
  }
  // A EuRoC CSV whose row lost its columns: the file and line again.
  std::ofstream((dir / "cut.csv").string()) << "#t\n1403715273262142976,1,2,3,1,0,0,0\n1403715273312142976,1,2\n";
  const std::string e = aerie::test::refusal([](const std::string& p) { read_trajectory(p); },
                                             (dir / "cut.csv").string());
  EXPECT_NE(e.find("cut.csv:3: 3 numbers; a EuRoC CSV row has 8"), std::string::npos) << e;
}

TEST(GroundTruth, LoopDriftOnlyForLoops) {
  const Trajectory loop = rectangle(0, true), line = rectangle(0, false);
  EXPECT_TRUE(is_loop(loop));
  EXPECT_FALSE(is_loop(line));  // ends 4.5 m (corner to corner) from its start after 6 m
  // The rule: within max(0.5 m, 10 % of the path) of the start.
  Trajectory hop;
  hop.push_back(0, SE3());
  hop.push_back(1, SE3::from_rotation_vector(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.5, 0, 0)));
  EXPECT_TRUE(is_loop(hop));
  hop.poses[1] = SE3::from_rotation_vector(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.51, 0, 0));
  EXPECT_FALSE(is_loop(hop));

  for (const auto* ref : {&loop, &line}) {
    ReportOptions opt;
    const Report r = evaluate(*ref, *ref, opt);
    std::ostringstream text;
    print(text, r, opt);
    const std::string json = to_json(r, opt);
    const bool closed = ref == &loop;
    EXPECT_EQ(r.drift.loop, closed);
    EXPECT_EQ(text.str().find("loop drift") != std::string::npos, closed) << text.str();
    EXPECT_EQ(json.find("\"loop_drift_m\"") != std::string::npos, closed) << json;
    EXPECT_NE(json.find(closed ? "\"loop\": true" : "\"loop\": false"), std::string::npos) << json;
  }
}

TEST(GroundTruth, ExplicitFileReplacesTheFoldersOwn) {
  AERIE_REQUIRE_DATA("stereo_seq/KITTI_odom_06_f000-050");
  const auto kitti_dir = aerie::test::shared_data("stereo_seq/KITTI_odom_06_f000-050").string();
  const auto dir = aerie::test::scratch_dir("explicit");
  const auto own = open_kitti(kitti_dir);
  ASSERT_EQ(own->ground_truth().size(), own->size());

  // KITTI poses: one line a frame, stamped with the sequence's times.txt.
  Trajectory moved;
  const SE3 up = SE3::from_rotation_vector(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, -2, 0));
  for (size_t i = 0; i < own->size(); ++i) moved.push_back(i, up * own->ground_truth().poses[i]);
  write_kitti_poses(moved, (dir / "poses.txt").string());
  const auto seq = open_sequence("kitti:" + kitti_dir, (dir / "poses.txt").string());
  ASSERT_EQ(seq->ground_truth().size(), own->size());
  for (size_t i = 0; i < own->size(); ++i) {
    EXPECT_DOUBLE_EQ(seq->ground_truth().stamps[i], own->ground_truth().stamps[i]);
    EXPECT_NEAR(seq->ground_truth().poses[i].translation().y(), own->ground_truth().poses[i].translation().y() - 2,
                1e-6);
  }
  // TUM with its own stamps (seconds of times.txt): taken as written.
  Trajectory part;
  for (size_t i = 0; i < 10; ++i) part.push_back(own->ground_truth().stamps[i], own->ground_truth().poses[i]);
  write_tum(part, (dir / "gt.txt").string());
  expect_same(open_kitti(kitti_dir, (dir / "gt.txt").string())->ground_truth(), part, 1e-9);
  // Too few KITTI poses for the frames: refused, naming the file and the counts.
  write_kitti_poses(part, (dir / "short.txt").string());
  const std::string e = aerie::test::refusal([&](const std::string& p) { open_kitti(kitti_dir, p); },
                                             (dir / "short.txt").string());
  EXPECT_NE(e.find("short.txt: 10 KITTI poses for 51 images"), std::string::npos) << e;

  AERIE_REQUIRE_DATA("stereo_seq/EuRoC_V1_01_easy_f000-094");
  const auto euroc_dir = aerie::test::shared_data("stereo_seq/EuRoC_V1_01_easy_f000-094").string();
  // The body's poses as a EuRoC CSV: the sequence's ground truth is the rectified left camera's,
  // one pose a row of the file.
  const Trajectory body = rectangle(1403715273.262142976, true);
  write_euroc_csv(body, (dir / "data.csv").string());
  const auto euroc = open_euroc(euroc_dir, (dir / "data.csv").string());
  ASSERT_EQ(euroc->ground_truth().size(), body.size());
  const auto euroc_own = open_euroc(euroc_dir);
  EXPECT_GT(euroc_own->ground_truth().size(), body.size());  // the folder's groundtruth/V101_gt.txt
  EXPECT_NE(aerie::test::refusal([&](const std::string& p) { open_euroc(euroc_dir, p); },
                                 (dir / "poses.txt").string())
                .find("KITTI poses have no timestamps"),
            std::string::npos);
}
