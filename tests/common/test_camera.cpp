#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "common/camera/calibration_io.hpp"
#include "common/camera/rectification.hpp"
#include "tests/support/test_support.hpp"

using namespace aerie::camera;
namespace fs = std::filesystem;

static const char* kEuroc = "stereo_seq/EuRoC_V1_01_easy_f000-094";
static const char* kKitti = "stereo_seq/KITTI_odom_06_f000-050";

// An undistorted rectified pair: focal length f, principal point at the centre, the right
// camera `baseline` metres to the left camera's right.
static StereoCalibration pinhole_pair(int width, int height, double f, double baseline) {
  StereoCalibration c;
  c.left = {width, height, f, f, width / 2.0, height / 2.0, Distortion::None, {}};
  c.right = c.left;
  c.T_right_left = aerie::geometry::SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-baseline, 0, 0));
  c.source = "test";
  return c;
}

TEST(Calibration, ReadsEurocSensorYaml) {
  AERIE_REQUIRE_DATA(kEuroc);
  const auto cam = read_euroc_camera(aerie::test::shared_data(kEuroc) / "mav0/cam0/sensor.yaml");
  EXPECT_EQ(cam.model.width, 752);
  EXPECT_EQ(cam.model.height, 480);
  EXPECT_DOUBLE_EQ(cam.model.fx, 458.654);
  EXPECT_DOUBLE_EQ(cam.model.cy, 248.375);
  EXPECT_EQ(cam.model.distortion, Distortion::RadTan);
  ASSERT_EQ(cam.model.coeffs.size(), 4u);
  EXPECT_DOUBLE_EQ(cam.model.coeffs[0], -0.28340811);
  EXPECT_NEAR(cam.T_body_sensor.translation().x(), -0.0216401454975, 1e-12);
}

TEST(Calibration, EurocStereoBaselineIs11cm) {
  AERIE_REQUIRE_DATA(kEuroc);
  const auto s = read_stereo_calibration(aerie::test::shared_data(kEuroc));
  EXPECT_NEAR(s.baseline(), 0.110, 0.001);
  // cam1 is to the right of cam0: in the left frame the right camera is at +x.
  EXPECT_GT(s.T_right_left.inverse().translation().x(), 0.10);
}

TEST(Calibration, ReadsKittiCalibTxt) {
  AERIE_REQUIRE_DATA(kKitti);
  const auto s = read_stereo_calibration(aerie::test::shared_data(kKitti) / "calib.txt", 1226, 370);
  EXPECT_DOUBLE_EQ(s.left.fx, 707.0912);
  EXPECT_DOUBLE_EQ(s.left.cx, 601.8873);
  EXPECT_NEAR(s.baseline(), 379.8145 / 707.0912, 1e-9);
  EXPECT_TRUE(StereoRectifier(s).is_identity());
}

TEST(Calibration, KittiWithLabelsAndExtraRows) {
  const auto dir = aerie::test::scratch_dir("kitti");
  std::ofstream(dir / "calib.txt") << "P0: 700 0 600 0 0 700 180 0 0 0 1 0\nP1: 700 0 600 -350 0 700 180 0 0 0 1 0\n"
                                      "P2: 1 0 0 0 0 1 0 0 0 0 1 0\nTr: 1 0 0 0 0 1 0 0 0 0 1 0\n";
  const auto s = read_kitti_stereo(dir / "calib.txt", 1200, 370);
  EXPECT_DOUBLE_EQ(s.baseline(), 0.5);
}

TEST(Calibration, OpenCvYamlRoundTrip) {
  StereoCalibration c;
  c.left = {640, 480, 500, 501, 320, 240, Distortion::RadTan, {0.1, -0.05, 0.001, 0.002}};
  c.right = {640, 480, 502, 503, 322, 238, Distortion::RadTan, {0.09, -0.04, 0.0, 0.001}};
  c.T_right_left = aerie::geometry::SE3::from_rotation_vector({0.01, -0.02, 0.005}, {-0.12, 0.001, 0.002});
  c.source = "test";
  const auto file = aerie::test::scratch_dir("yaml") / "stereo.yaml";
  write_opencv_stereo(c, file);
  const auto r = read_stereo_calibration(file);
  EXPECT_DOUBLE_EQ(r.right.fy, 503);
  EXPECT_EQ(r.left.coeffs, c.left.coeffs);
  EXPECT_LT((r.T_right_left.matrix() - c.T_right_left.matrix()).norm(), 1e-12);
}

TEST(Calibration, BadInputsNameTheFileAndField) {
  const auto dir = aerie::test::scratch_dir("bad");
  try {
    read_stereo_calibration((dir / "missing.yaml").string());
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.yaml"), std::string::npos);
  }
  std::ofstream(dir / "sensor.yaml") << "%YAML:1.0\ncamera_model: pinhole\nresolution: [752, 480]\n"
                                         "intrinsics: [458, 457, 367]\nT_BS: {data: [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]}\n";
  try {
    read_euroc_camera((dir / "sensor.yaml").string());
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("intrinsics"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "calib.txt") << "700 0 600 0 0 700 180 0 0 0 1\n";
  EXPECT_THROW(read_kitti_stereo((dir / "calib.txt").string(), 100, 100), std::runtime_error);
  // A resolution that is no image size (the fuzzer's 4.4e56 was cast to int: undefined).
  for (const char* res : {"[752, 4.4e56]", "[-752, 480]", "[752.5, 480]", "[0, 480]"}) {
    std::ofstream(dir / "sensor.yaml") << "%YAML:1.0\ncamera_model: pinhole\nresolution: " << res
                                       << "\nintrinsics: [458, 457, 367, 248]\n"
                                          "T_BS: {data: [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]}\n";
    try {
      read_euroc_camera((dir / "sensor.yaml").string());
      FAIL() << "resolution " << res << " accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("resolution must be two whole numbers"), std::string::npos) << e.what();
    }
  }
}

TEST(Calibration, ProjectUnprojectRoundTrip) {
  for (auto model : {CameraModel{752, 480, 458, 457, 367, 248, Distortion::RadTan, {-0.28, 0.07, 0.0002, 0.00002}},
                     CameraModel{752, 480, 300, 300, 376, 240, Distortion::Equidistant, {0.01, -0.002, 0.001, 0.0}}}) {
    const Eigen::Vector3d p(0.4, -0.3, 2.0);
    const Eigen::Vector2d uv = model.project(p);
    const Eigen::Vector3d ray = model.unproject(uv);
    EXPECT_LT((ray - p / p.z()).norm(), 1e-6) << to_string(model.distortion);
  }
}

// Rectification of the raw EuRoC pair brings the same scene points to the same row.
TEST(Rectification, EurocPairRowsAlignWithinHalfPixel) {
  AERIE_REQUIRE_DATA(kEuroc);
  const fs::path mav0 = aerie::test::shared_data(kEuroc) / "mav0";
  const auto calib = read_euroc_stereo(mav0.string());
  const StereoRectifier rect(calib);
  std::vector<fs::path> frames;
  for (const auto& e : fs::directory_iterator(mav0 / "cam0/data")) frames.push_back(e.path().filename());
  std::sort(frames.begin(), frames.end());
  ASSERT_FALSE(frames.empty());
  const cv::Mat l_raw = cv::imread((mav0 / "cam0/data" / frames[10]).string(), cv::IMREAD_GRAYSCALE);
  const cv::Mat r_raw = cv::imread((mav0 / "cam1/data" / frames[10]).string(), cv::IMREAD_GRAYSCALE);
  cv::Mat l, r;
  rect.rectify(l_raw, r_raw, l, r);

  auto orb = cv::ORB::create(2000);
  std::vector<cv::KeyPoint> kl, kr;
  cv::Mat dl, dr;
  orb->detectAndCompute(l, cv::noArray(), kl, dl);
  orb->detectAndCompute(r, cv::noArray(), kr, dr);
  cv::BFMatcher matcher(cv::NORM_HAMMING, true);
  std::vector<cv::DMatch> matches;
  matcher.match(dl, dr, matches);
  std::vector<double> dy;
  for (const auto& m : matches) {
    const auto& a = kl[m.queryIdx].pt;
    const auto& b = kr[m.trainIdx].pt;
    const double disparity = a.x - b.x;
    if (m.distance < 30 && disparity > 0 && disparity < 100 && std::abs(a.y - b.y) < 5) dy.push_back(std::abs(a.y - b.y));
  }
  ASSERT_GT(dy.size(), 100u);
  std::nth_element(dy.begin(), dy.begin() + dy.size() / 2, dy.end());
  EXPECT_LT(dy[dy.size() / 2], 0.5);

  // Without rectification the same check fails: the raw pair is not row-aligned.
  EXPECT_NEAR(rect.rectified().baseline, 0.110, 0.001);
  EXPECT_THROW(rect.rectify(l_raw(cv::Rect(0, 0, 100, 100)), r_raw, l, r), std::invalid_argument);
}

TEST(Calibration, MalformedOpenCvYamlIsRefusedNotHung) {
  // Fuzzing (fuzz/regressions/calibration/): OpenCV 4.6's FileStorage never returned on this
  // 566-byte file, and allocated the 48 GB a corrupt `cols` declared. Read with yaml-cpp now.
  for (const char* f : {"opencv_filestorage_open_hangs.yaml", "opencv_yaml_matrix_cols_garbage_48GB.yaml",
                        "opencv_yaml_matrix_without_data.yaml", "opencv_yaml_not_a_map.yaml"}) {
    const std::string path = std::string(AERIE_SOURCE_DIR) + "/fuzz/regressions/calibration/" + f;
    try {
      read_stereo_calibration(path);
      ADD_FAILURE() << f << " was accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what();
    }
  }
}

TEST(Calibration, ImageSizesNoCameraHasAreRefused) {
  // The reader bounds its ints, but the rectifier allocates maps per pixel: 65535 x 65535 would
  // ask for tens of GB on a calibration file alone.
  const auto dir = aerie::test::scratch_dir("huge");
  for (const auto& [w, h] : {std::pair{16385, 100}, std::pair{100, 65535}, std::pair{9000, 8000}}) {
    write_opencv_stereo(pinhole_pair(w, h, 500, 0.1), dir / "stereo.yaml");
    try {
      read_stereo_calibration((dir / "stereo.yaml").string());
      FAIL() << w << "x" << h << " accepted";
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find("resolution " + std::to_string(w) + "x" + std::to_string(h) + " exceeds"),
                std::string::npos)
          << e.what();
    }
  }
  EXPECT_NO_THROW(pinhole_pair(8192, 8192, 500, 0.1).validate());  // 2^26 pixels: the largest accepted
}

TEST(Calibration, OpenCvYamlWithoutDistortionRoundTrips) {
  const StereoCalibration c = pinhole_pair(376, 240, 300, 0.11);
  const auto file = aerie::test::scratch_dir("yaml") / "plain.yaml";
  write_opencv_stereo(c, file);
  const auto r = read_stereo_calibration(file);
  EXPECT_EQ(r.left.distortion, Distortion::None);
  for (double k : r.left.coeffs) EXPECT_EQ(k, 0.0);
  EXPECT_NEAR(r.baseline(), 0.11, 1e-12);
}
