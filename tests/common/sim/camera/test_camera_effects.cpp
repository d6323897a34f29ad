// The camera-effects stage against each effect's definition: the lens warp inverted by the
// pipeline's own undistortion and rectification, blur length, rolling-shutter skew, the
// auto-exposure loop, Poisson-Gaussian noise, JPEG, determinism, config refusals.
#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "common/camera/calibration_io.hpp"
#include "common/camera/rectification.hpp"
#include "common/sim/camera/camera_effects.hpp"
#include "common/sim/camera/camera_effects_config.hpp"

using namespace aerie;
using sim::CameraEffects;
using sim::CameraEffectsConfig;
using sim::CameraMotion;

namespace {

camera::CameraModel pinhole(int w, int h, double f) {
  camera::CameraModel m;
  m.width = w;
  m.height = h;
  m.fx = m.fy = f;
  m.cx = 0.5 * (w - 1);
  m.cy = 0.5 * (h - 1);
  return m;
}

// Gaussian blobs (sigma 1.5 px, peak 250) on black at the given centres.
cv::Mat blobs(const camera::CameraModel& m, const std::vector<cv::Point2d>& centres) {
  cv::Mat img(m.height, m.width, CV_32F, cv::Scalar(0));
  for (const auto& c : centres)
    for (int v = std::max(0, int(c.y) - 8); v <= std::min(m.height - 1, int(c.y) + 8); ++v)
      for (int u = std::max(0, int(c.x) - 8); u <= std::min(m.width - 1, int(c.x) + 8); ++u)
        img.at<float>(v, u) += 250.f * std::exp(-((u - c.x) * (u - c.x) + (v - c.y) * (v - c.y)) / (2 * 1.5 * 1.5));
  cv::Mat out;
  img.convertTo(out, CV_8U);
  return out;
}

// Intensity-weighted centroid in a 17x17 window around `near`.
cv::Point2d centroid(const cv::Mat& img, cv::Point2d near) {
  double s = 0, su = 0, sv = 0;
  for (int v = int(std::lround(near.y)) - 8; v <= int(std::lround(near.y)) + 8; ++v)
    for (int u = int(std::lround(near.x)) - 8; u <= int(std::lround(near.x)) + 8; ++u) {
      if (u < 0 || v < 0 || u >= img.cols || v >= img.rows) continue;
      const double w = img.at<uint8_t>(v, u);
      s += w;
      su += w * u;
      sv += w * v;
    }
  return {su / s, sv / s};
}

std::vector<cv::Point2d> grid(const camera::CameraModel& m, int margin, int step) {
  std::vector<cv::Point2d> g;
  for (int v = margin; v <= m.height - margin; v += step)
    for (int u = margin; u <= m.width - margin; u += step) g.emplace_back(u + 0.3, v - 0.2);
  return g;
}

CameraEffectsConfig lens_config(camera::Distortion d, std::vector<double> coeffs) {
  CameraEffectsConfig c;
  c.lens.enabled = true;
  c.lens.model.distortion = d;
  c.lens.model.coeffs = std::move(coeffs);
  return c;
}

// Distorts a grid of blobs, finds each in the distorted image and undistorts it with
// camera::CameraModel::unproject: back within 0.1 px of where the ideal image had it.
void expect_grid_round_trip(const CameraEffectsConfig& cfg, int margin) {
  const auto ideal = pinhole(752, 480, 400);
  CameraEffects fx(cfg, ideal, "test");
  const auto pts = grid(ideal, margin, 60);
  const cv::Mat out = fx.apply(blobs(ideal, pts), {}, {}, 0, 0);
  camera::CameraModel lens = ideal;
  lens.distortion = cfg.lens.model.distortion;
  lens.coeffs = cfg.lens.model.coeffs;
  double worst = 0;
  for (const auto& p : pts) {
    const Eigen::Vector2d d = lens.project({(p.x - ideal.cx) / ideal.fx, (p.y - ideal.cy) / ideal.fy, 1.0});
    const cv::Point2d c = centroid(out, {d.x(), d.y()});
    const Eigen::Vector3d ray = lens.unproject({c.x, c.y});
    worst = std::max(worst, std::hypot(ideal.fx * ray.x() + ideal.cx - p.x, ideal.fy * ray.y() + ideal.cy - p.y));
  }
  EXPECT_LT(worst, 0.1) << pts.size() << " blobs";
}

}  // namespace

TEST(CameraEffects, RadTanDistortedGridUndistortsWithin0p1Px) {
  expect_grid_round_trip(lens_config(camera::Distortion::RadTan, {-0.28, 0.07, 1e-3, -5e-4}), 40);
}

TEST(CameraEffects, EquidistantDistortedGridUndistortsWithin0p1Px) {
  expect_grid_round_trip(lens_config(camera::Distortion::Equidistant, {-0.013, 0.02, -0.01, 0.003}), 40);
}

TEST(CameraEffects, TheDistortionIsTheCameraModelsProjection) {
  // A pixel of the distorted image shows what the ideal image has at the ideal projection
  // of its ray: a dot rendered at the ideal pixel of lens.unproject(p) appears at p.
  const auto ideal = pinhole(376, 240, 188);
  auto cfg = lens_config(camera::Distortion::RadTan, {-0.2, 0.03, 0, 0});
  CameraEffects fx(cfg, ideal, "test");
  camera::CameraModel lens = ideal;
  lens.distortion = camera::Distortion::RadTan;
  lens.coeffs = {-0.2, 0.03, 0, 0};
  const cv::Point2d p(300.0, 200.0);
  const Eigen::Vector3d ray = lens.unproject({p.x, p.y});
  const cv::Point2d q(ideal.fx * ray.x() + ideal.cx, ideal.fy * ray.y() + ideal.cy);
  EXPECT_GT(std::hypot(q.x - p.x, q.y - p.y), 5.0);  // the lens moves it noticeably
  const cv::Mat out = fx.apply(blobs(ideal, {q}), {}, {}, 0, 0);
  const cv::Point2d c = centroid(out, p);
  EXPECT_NEAR(c.x, p.x, 0.1);
  EXPECT_NEAR(c.y, p.y, 0.1);
}

TEST(CameraEffects, TheStereoRectifierStraightensSimulatedDistortedFrames) {
  // A distorted stereo calibration of the OpenCV YAML the project reads: the lens stage
  // distorts each ideal view with its camera, the pipeline's StereoRectifier undoes it; each
  // blob then sits at the rectified projection of its ray (the rig has no rotation, so the
  // rectified frame is the cameras' own).
  const auto ideal = pinhole(752, 480, 400);
  camera::StereoCalibration calib;
  calib.left = ideal;
  calib.left.distortion = camera::Distortion::RadTan;
  calib.left.coeffs = {-0.25, 0.06, 0.0, 0.0};
  calib.right = calib.left;
  calib.T_right_left = geometry::SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-0.1, 0, 0));
  calib.source = "test";
  const auto file = std::filesystem::temp_directory_path() / "aerie_sim_camera_stereo.yaml";
  camera::write_opencv_stereo(calib, file.string());
  const auto read = camera::read_stereo_calibration(file.string());

  CameraEffectsConfig cfg;
  cfg.lens.enabled = true;
  cfg.lens.model = read.left;
  CameraEffects fx(cfg, ideal, "test");
  const auto pts = grid(ideal, 90, 60);
  const cv::Mat raw = fx.apply(blobs(ideal, pts), {}, {}, 0, 0);
  const camera::StereoRectifier rect(read);
  ASSERT_NEAR((Eigen::Matrix3d(Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(rect.R_left().val)) -
               Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-9);
  cv::Mat left, right;
  rect.rectify(raw, raw, left, right);
  const auto& r = rect.rectified();
  double worst = 0;
  int found = 0;
  for (const auto& p : pts) {
    const cv::Point2d q(r.fx * (p.x - ideal.cx) / ideal.fx + r.cx, r.fy * (p.y - ideal.cy) / ideal.fy + r.cy);
    if (q.x < 10 || q.y < 10 || q.x > left.cols - 10 || q.y > left.rows - 10) continue;
    const cv::Point2d c = centroid(left, q);
    worst = std::max(worst, std::hypot(c.x - q.x, c.y - q.y));
    ++found;
  }
  EXPECT_GT(found, 20);
  EXPECT_LT(worst, 0.1);
}

TEST(CameraEffects, ACalibrationOfAnotherSizeIsRefusedNamingBoth) {
  CameraEffectsConfig cfg;
  cfg.lens.enabled = true;
  cfg.lens.model = pinhole(752, 480, 400);
  cfg.lens.model.distortion = camera::Distortion::RadTan;
  cfg.lens.model.coeffs = {-0.2, 0.03, 0, 0};
  try {
    CameraEffects fx(cfg, pinhole(376, 240, 188), "camera_effects.down");
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("camera_effects.down"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("752x480"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("376x240"), std::string::npos) << e.what();
  }
}

TEST(CameraEffects, ImageFlowIsTheMotionOfTheProjection) {
  // Finite difference of the projection of a static point under the camera's motion.
  const double f = 300, cx = 200, cy = 120, dt = 1e-6;
  CameraMotion m;
  m.velocity = {0.7, -0.3, 0.5};
  m.angular_velocity = {0.2, -0.4, 0.9};
  const Eigen::Vector3d P(0.4, -0.2, 2.5);
  // Camera pose at dt: R = exp(w dt), centre v dt; the point in the new frame R^T (P - v dt).
  const Eigen::Matrix3d R = Eigen::AngleAxisd(m.angular_velocity.norm() * dt, m.angular_velocity.normalized()).toRotationMatrix();
  const Eigen::Vector3d Q = R.transpose() * (P - m.velocity * dt);
  auto proj = [&](const Eigen::Vector3d& X) { return Eigen::Vector2d(f * X.x() / X.z() + cx, f * X.y() / X.z() + cy); };
  const Eigen::Vector2d expected = (proj(Q) - proj(P)) / dt;
  const Eigen::Vector2d p = proj(P);
  const Eigen::Vector2d got = sim::image_flow(m, f, f, cx, cy, p.x(), p.y(), P.z());
  EXPECT_NEAR(got.x(), expected.x(), 1e-3 * expected.norm());
  EXPECT_NEAR(got.y(), expected.y(), 1e-3 * expected.norm());
}

namespace {

// A vertical step edge: 0 left of column `col`, 200 from it.
cv::Mat step_edge(const camera::CameraModel& m, int col) {
  cv::Mat img(m.height, m.width, CV_8U, cv::Scalar(0));
  img.colRange(col, m.width).setTo(200);
  return img;
}

// Edge position (centroid of the row's derivative) and spread (its variance) of one row.
std::pair<double, double> edge_of_row(const cv::Mat& img, int row) {
  double s = 0, s1 = 0, s2 = 0;
  for (int u = 0; u + 1 < img.cols; ++u) {
    const double d = double(img.at<uint8_t>(row, u + 1)) - img.at<uint8_t>(row, u);
    s += d;
    s1 += d * (u + 0.5);
    s2 += d * (u + 0.5) * (u + 0.5);
  }
  const double mu = s1 / s;
  return {mu, s2 / s - mu * mu};
}

// The down camera kFloorZ over a flat floor, moving kSpeed along image x, sees step_edge.
constexpr double kFloorZ = 2.0, kSpeed = 5.0;
cv::Mat moving_edge(const CameraEffectsConfig& cfg, const camera::CameraModel& ideal) {
  CameraEffects fx(cfg, ideal, "test");
  CameraMotion m;
  m.velocity = {kSpeed, 0, 0};
  const cv::Mat depth(ideal.height, ideal.width, CV_32F, cv::Scalar(kFloorZ));
  return fx.apply(step_edge(ideal, 180), depth, m, 0, 0);
}

}  // namespace

TEST(CameraEffects, BlurLengthEqualsTheMotionDuringTheExposure) {
  // The scene moves fx * v / z px/s, so an edge spreads over fx * v * T / z px, a box whose
  // variance is L^2 / 12 (plus 1/6 px^2 of the bilinear sampling of a step).
  const auto ideal = pinhole(376, 240, 188);
  const double T = 0.02;
  CameraEffectsConfig cfg;
  cfg.motion.motion_blur = true;
  cfg.motion.max_blur_samples = 64;
  cfg.exposure.exposure_time_s = T;
  const cv::Mat out = moving_edge(cfg, ideal);
  const double L = ideal.fx * kSpeed * T / kFloorZ;  // 9.4 px
  for (int row : {0, 120, 239}) {
    const auto [mu, var] = edge_of_row(out, row);
    EXPECT_NEAR(mu, 179.5, 0.05);  // global shutter: centred on the frame time
    EXPECT_NEAR(std::sqrt(12 * (var - 1.0 / 6)), L, 0.2) << "row " << row;
  }
  // Twice the exposure, twice the length.
  cfg.exposure.exposure_time_s = 2 * T;
  const double var2 = edge_of_row(moving_edge(cfg, ideal), 120).second;
  EXPECT_NEAR(std::sqrt(12 * (var2 - 1.0 / 6)), 2 * L, 0.3);
}

TEST(CameraEffects, RollingShutterSkewEqualsLineDelayTimesImageSpeed) {
  const auto ideal = pinhole(376, 240, 188);
  const double line_delay = 50e-6;
  CameraEffectsConfig cfg;
  cfg.motion.rolling_shutter = true;
  cfg.motion.line_delay_s = line_delay;
  const cv::Mat out = moving_edge(cfg, ideal);
  // Least-squares slope of the edge's column over the rows.
  double sr = 0, sc = 0, srr = 0, src = 0;
  const int n = ideal.height;
  for (int r = 0; r < n; ++r) {
    const double c = edge_of_row(out, r).first;
    sr += r;
    sc += c;
    srr += double(r) * r;
    src += r * c;
  }
  const double slope = (n * src - sr * sc) / (n * srr - sr * sr);
  const double speed = -ideal.fx * kSpeed / kFloorZ;  // px/s: the scene moves against the camera
  EXPECT_NEAR(slope, speed * line_delay, 0.01 * std::abs(speed * line_delay));
  EXPECT_NEAR(edge_of_row(out, 120).first, 179.5 + speed * line_delay * (120 - 119.5), 0.05);
  // A global shutter: no skew.
  cfg.motion.rolling_shutter = false;
  cfg.motion.motion_blur = true;
  const cv::Mat g = moving_edge(cfg, ideal);
  EXPECT_NEAR(edge_of_row(g, 0).first, edge_of_row(g, 239).first, 0.02);
}

TEST(CameraEffects, AutoExposureFollowsTheSceneWithAFirstOrderLag) {
  const auto ideal = pinhole(376, 240, 188);
  CameraEffectsConfig cfg;
  cfg.exposure.auto_exposure = true;
  cfg.exposure.exposure_time_s = 0.004;
  cfg.exposure.min_exposure_time_s = 1e-4;
  cfg.exposure.max_exposure_time_s = 0.008;
  cfg.exposure.max_gain = 8;
  cfg.exposure.target_mean = 0.4;
  cfg.exposure.time_constant_s = 0.2;
  CameraEffects fx(cfg, ideal, "test");
  const cv::Mat dim(ideal.height, ideal.width, CV_8U, cv::Scalar(40));
  const double dt = 0.05, a = 1 - std::exp(-dt / 0.2);
  double logE = std::log(0.004), logWanted = std::log(0.004 * 0.4 * 255 / 40);
  for (int k = 0; k < 40; ++k) {
    const cv::Mat out = fx.apply(dim, {}, {}, int64_t(k * dt * 1e6), k);
    EXPECT_NEAR(std::log(fx.exposure_time_s() * fx.gain()), logE, 0.02) << "frame " << k;
    logE += a * (logWanted - logE);
    if (k == 39) {
      EXPECT_NEAR(cv::mean(out)[0] / 255, 0.4, 0.01);
    }
  }
  EXPECT_NEAR(fx.exposure_time_s(), 0.008, 1e-9);  // time first (up to its limit), then gain
  EXPECT_NEAR(fx.gain(), 0.4 * 255 / 40 / 2, 0.02);
  // A darker scene: the time is at its limit, the gain makes up the rest.
  const cv::Mat darker(ideal.height, ideal.width, CV_8U, cv::Scalar(20));
  cv::Mat out;
  for (int k = 40; k < 120; ++k) out = fx.apply(darker, {}, {}, int64_t(k * dt * 1e6), k);
  EXPECT_NEAR(fx.exposure_time_s(), 0.008, 1e-9);
  EXPECT_NEAR(fx.gain(), 0.4 * 255 / 20 / 2, 0.1);
  EXPECT_NEAR(cv::mean(out)[0] / 255, 0.4, 0.01);
}

TEST(CameraEffects, ShotAndReadNoiseArePoissonGaussianInElectrons) {
  const auto ideal = pinhole(752, 480, 400);
  CameraEffectsConfig cfg;
  cfg.noise.enabled = true;
  cfg.noise.full_well_e = 6000;
  cfg.noise.read_noise_e = 3;
  for (double gain : {1.0, 4.0}) {
    cfg.exposure.gain = cfg.exposure.max_gain = gain;
    CameraEffects fx(cfg, ideal, "test");
    const double level = 120 / gain;  // same output level: 4x fewer electrons at gain 4
    const cv::Mat flat(ideal.height, ideal.width, CV_8U, cv::Scalar(level));
    const cv::Mat out = fx.apply(flat, {}, {}, 0, 7);
    cv::Scalar mean, sd;
    cv::meanStdDev(out, mean, sd);
    const double e = std::round(level) / 255 * 6000, k = gain * 255 / 6000;
    const double var = k * k * (e + 9) + 1.0 / 12;  // Poisson + read noise, then quantisation
    EXPECT_NEAR(mean[0], k * e, 0.05) << "gain " << gain;
    EXPECT_NEAR(sd[0] * sd[0], var, 0.05 * var) << "gain " << gain;
  }
}

TEST(CameraEffects, TheSameSeedGivesTheSameBytesAndSeqChangesTheNoise) {
  const auto ideal = pinhole(376, 240, 188);
  CameraEffectsConfig cfg = sim::camera_effects_preset("rpi-camera-module-3");
  cfg.jpeg.enabled = true;
  const cv::Mat depth(ideal.height, ideal.width, CV_32F, cv::Scalar(3.0));
  CameraMotion m;
  m.velocity = {1, 0.5, -0.2};
  m.angular_velocity = {0.1, 0.2, 0.3};
  const cv::Mat img = blobs(ideal, grid(ideal, 20, 30)) + 40;
  CameraEffects a(cfg, ideal, "a"), b(cfg, ideal, "b");
  for (int k = 0; k < 3; ++k) {
    const cv::Mat fa = a.apply(img, depth, m, k * 50000, k), fb = b.apply(img, depth, m, k * 50000, k);
    EXPECT_EQ(cv::norm(fa, fb, cv::NORM_INF), 0.0) << "frame " << k;
  }
  CameraEffects c(cfg, ideal, "c");
  EXPECT_GT(cv::norm(c.apply(img, depth, m, 0, 1), CameraEffects(cfg, ideal, "d").apply(img, depth, m, 0, 2),
                     cv::NORM_L1), 0.0);
  cfg.noise.seed = 99;
  EXPECT_GT(cv::norm(CameraEffects(cfg, ideal, "e").apply(img, depth, m, 0, 1),
                     CameraEffects(sim::camera_effects_preset("rpi-camera-module-3"), ideal, "f").apply(img, depth, m, 0, 1),
                     cv::NORM_L1), 0.0);
}

TEST(CameraEffects, JpegCodesAtTheGivenQuality) {
  const auto ideal = pinhole(376, 240, 188);
  const cv::Mat img = blobs(ideal, grid(ideal, 20, 30)) + 40;
  auto psnr = [&](int q) {
    CameraEffectsConfig cfg;
    cfg.jpeg.enabled = true;
    cfg.jpeg.quality = q;
    return cv::PSNR(CameraEffects(cfg, ideal, "t").apply(img, {}, {}, 0, 0), img);
  };
  const double high = psnr(95), low = psnr(20);
  EXPECT_GT(high, 40);
  EXPECT_LT(low, high - 5);
  EXPECT_LT(high, 99);  // coded, not passed through
}

TEST(CameraEffects, AllEffectsOffReturnsTheFrameUntouched) {
  const auto ideal = pinhole(376, 240, 188);
  const cv::Mat img = blobs(ideal, grid(ideal, 20, 30));
  CameraEffects fx(CameraEffectsConfig{}, ideal, "t");
  const cv::Mat out = fx.apply(img, {}, {}, 0, 0);
  EXPECT_EQ(out.data, img.data);
  const auto cfg = sim::load_camera_effects(util::Config::parse("part: rpi-camera-module-3\neffects: ideal\n", "t.yaml"));
  EXPECT_FALSE(cfg.any());
  EXPECT_EQ(cfg.part, "rpi-camera-module-3");
}

TEST(CameraEffectsConfig, PartsAndKeysAreReadAndBadOnesNamed) {
  const auto c = sim::load_camera_effects(util::Config::parse(
      "part: rpi-camera-module-3\nnoise:\n  read_noise_e: 5\njpeg:\n  enabled: true\n  quality: 80\n", "cam.yaml"));
  EXPECT_TRUE(c.motion.rolling_shutter);
  EXPECT_NEAR(c.motion.readout_time_s, 1 / 56.03, 1e-9);
  EXPECT_EQ(c.noise.read_noise_e, 5);
  EXPECT_TRUE(c.jpeg.enabled);
  EXPECT_EQ(c.jpeg.quality, 80);
  CameraEffects fx(c, pinhole(376, 240, 188), "t");
  EXPECT_NEAR(fx.line_delay_s(), 1 / 56.03 / 240, 1e-12);
  EXPECT_FALSE(sim::load_camera_effects(util::Config()).any());

  auto refused = [](const std::string& yaml, const std::vector<std::string>& words) {
    try {
      sim::load_camera_effects(util::Config::parse(yaml, "cam.yaml"));
      ADD_FAILURE() << "accepted: " << yaml;
    } catch (const std::runtime_error& e) {
      for (const auto& w : words) EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << e.what();
    }
  };
  refused("part: gopro\n", {"cam.yaml", "part", "gopro", "ov9281", "line 1"});
  refused("noise:\n  enabld: true\n", {"cam.yaml", "enabld"});
  refused("jpeg:\n  quality: 0\n", {"cam.yaml", "jpeg.quality", "line 2"});
  refused("lens:\n  enabled: true\n  calibration: /nonexistent/cam.yaml\n",
          {"cam.yaml", "lens.calibration", "/nonexistent/cam.yaml", "line 3"});
  refused("lens:\n  enabled: true\n  model: fisheye\n  coeffs: [0.1, 0.2]\n", {"lens.coeffs", "got 2"});
  refused("lens:\n  enabled: true\n  model: pinhole-x\n", {"lens.model", "pinhole-x"});
  refused("rolling_shutter:\n  enabled: true\n", {"cam.yaml", "line_delay_s"});
  refused("effects: realistic\n", {"effects", "realistic"});
}
