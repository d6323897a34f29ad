// Stereo renderer: ground truth (depth, poses, helipad box) consistent with the geometry
// and with the images; determinism; texture quality for feature tracking.
#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <vector>

#include "common/sim/simulation.hpp"
#include "tests/common/sim/sim_fixtures.hpp"

namespace aerie::sim {
namespace {

// Inverse depth is affine in the image on a plane, so its bilinear interpolation is exact
// when the 2x2 neighbourhood lies on one plane.
double depth_at(const cv::Mat& depth, double u, double v) {
  const int u0 = static_cast<int>(std::floor(u)), v0 = static_cast<int>(std::floor(v));
  if (u0 < 0 || v0 < 0 || u0 + 1 >= depth.cols || v0 + 1 >= depth.rows) return NAN;
  const double fu = u - u0, fv = v - v0;
  auto iz = [&](int x, int y) { return 1.0 / depth.at<float>(y, x); };
  const double a = iz(u0, v0) + fu * (iz(u0 + 1, v0) - iz(u0, v0));
  const double b = iz(u0, v0 + 1) + fu * (iz(u0 + 1, v0 + 1) - iz(u0, v0 + 1));
  return 1.0 / (a + fv * (b - a));
}

// Points on the world's surfaces: the helipad, the centres of the obstacles' side and top
// faces, a grid on the walls and the floor.
std::vector<Eigen::Vector3d> surface_points(const World& w) {
  std::vector<Eigen::Vector3d> pts{w.helipad().center};
  for (const auto& o : w.obstacles()) {
    const Eigen::Vector3d c = o.box.center();
    for (int a = 0; a < 3; ++a) {
      Eigen::Vector3d p = c;
      p[a] = o.box.max[a];
      pts.push_back(p);
      if (a < 2) {
        p[a] = o.box.min[a];
        pts.push_back(p);
      }
    }
  }
  const auto& b = w.bounds();
  for (double x = b.min.x() + 0.37; x < b.max.x() - 0.2; x += 0.83)
    for (double z = 0.21; z < b.max.z() - 0.2; z += 0.61) {
      pts.emplace_back(x, b.min.y(), z);
      pts.emplace_back(x, b.max.y(), z);
    }
  for (double y = b.min.y() + 0.29; y < b.max.y() - 0.2; y += 0.79)
    for (double z = 0.33; z < b.max.z() - 0.2; z += 0.57) {
      pts.emplace_back(b.min.x(), y, z);
      pts.emplace_back(b.max.x(), y, z);
    }
  for (double x = b.min.x() + 0.5; x < b.max.x(); x += 1.1)
    for (double y = b.min.y() + 0.5; y < b.max.y(); y += 0.9) pts.emplace_back(x, y, 0.0);
  return pts;
}

TEST(SimRender, IntrinsicsFollowTheFieldOfView) {
  const StereoRenderer r(test::light_world(), RigConfig{});
  const Intrinsics K = r.intrinsics();
  EXPECT_NEAR(K.fx, 188.0 / std::tan(49.0 * M_PI / 180.0), 1e-9);
  EXPECT_NEAR(K.fy, 120.0 / std::tan(36.5 * M_PI / 180.0), 1e-9);
  EXPECT_DOUBLE_EQ(K.cx, 187.5);
  EXPECT_DOUBLE_EQ(K.cy, 119.5);
  EXPECT_DOUBLE_EQ(K.baseline, 0.12);
  const auto calib = K.calibration();
  calib.validate();
  EXPECT_DOUBLE_EQ(calib.baseline(), 0.12);
  RigConfig bad;
  bad.hfov_deg = 0;
  EXPECT_THROW(StereoRenderer(test::light_world(), bad), std::invalid_argument);
}

TEST(SimRender, KnownPointsAreWhereTheDepthSays) {
  const World& w = test::light_world();
  StereoSimulation sim(w, RigConfig{}, Trajectory::demo_flight(w));
  const auto pts = surface_points(w);
  const Intrinsics K = sim.intrinsics();
  int checked = 0;
  for (int k = 0; k < sim.frame_count(); k += 60) {
    const StereoFrame f = sim.frame(k);
    const geometry::SE3 T_cam_world = f.T_world_left.inverse();
    const Eigen::Vector3d o = f.T_world_left.translation();
    for (const auto& X : pts) {
      const Eigen::Vector3d q = T_cam_world * X;
      if (q.z() < 0.2) continue;
      const double u = K.fx * q.x() / q.z() + K.cx, v = K.fy * q.y() / q.z() + K.cy;
      if (u < 2 || v < 2 || u > K.width - 3 || v > K.height - 3) continue;
      // Visible: nothing on the line of sight before the point.
      const auto hit = w.raycast(o, X - o);
      if (!hit || hit->t < 1.0 - 1e-6) continue;
      // Skip points within a pixel of an edge: the 2x2 patch must be one plane, where
      // inverse depth is affine (zero mixed second difference).
      const int u0 = static_cast<int>(u), v0 = static_cast<int>(v);
      auto iz = [&](int x, int y) { return 1.0 / f.depth.at<float>(y, x); };
      const double mixed = iz(u0, v0) + iz(u0 + 1, v0 + 1) - iz(u0 + 1, v0) - iz(u0, v0 + 1);
      const double du2 = iz(u0 - 1, v0) - 2 * iz(u0, v0) + iz(u0 + 1, v0);
      const double du2b = iz(u0, v0) - 2 * iz(u0 + 1, v0) + iz(u0 + 2, v0);
      const double dv2 = iz(u0, v0 - 1) - 2 * iz(u0, v0) + iz(u0, v0 + 1);
      const double dv2b = iz(u0, v0) - 2 * iz(u0, v0 + 1) + iz(u0, v0 + 2);
      const double tol = 1e-5 / q.z();
      if (std::max({std::abs(mixed), std::abs(du2), std::abs(du2b), std::abs(dv2), std::abs(dv2b)}) > tol) continue;
      EXPECT_NEAR(depth_at(f.depth, u, v), q.z(), 1e-3) << "frame " << k << " point " << X.transpose();
      ++checked;
    }
  }
  EXPECT_GT(checked, 200);
}

TEST(SimRender, DepthMatchesRayCastsEverywhere) {
  const World& w = test::light_world();
  StereoSimulation sim(w, RigConfig{}, Trajectory::demo_flight(w));
  const Intrinsics K = sim.intrinsics();
  const StereoFrame f = sim.frame(sim.frame_count() / 3);
  const Eigen::Matrix3d R = f.T_world_left.rotation_matrix();
  int valid = 0;
  for (int v = 0; v < K.height; v += 7)
    for (int u = 0; u < K.width; u += 7) {
      const Eigen::Vector3d ray((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
      const auto hit = w.raycast(f.T_world_left.translation(), R * ray);
      ASSERT_TRUE(hit);
      const float z = f.depth.at<float>(v, u);
      ASSERT_TRUE(std::isfinite(z));
      // Rays grazing an edge may pick the other surface in float; all others agree.
      if (std::abs(z - hit->t) < 1e-3 * hit->t) ++valid;
    }
  EXPECT_GT(valid, 0.995 * (K.height / 7 + 1) * (K.width / 7 + 1));
}

TEST(SimRender, RightImageMatchesLeftThroughDisparity) {
  const World& w = test::light_world();
  RigConfig rig;
  rig.disparity = true;
  StereoSimulation sim(w, rig, Trajectory::demo_flight(w));
  const Intrinsics K = sim.intrinsics();
  const double fb = K.fx * K.baseline;
  std::vector<double> nccs;
  for (int k : {100, 300, 500, 700}) {
    const StereoFrame f = sim.frame(k);
    cv::Mat left, right;
    f.left.convertTo(left, CV_32F);
    f.right.convertTo(right, CV_32F);
    const Eigen::Vector3d o_right = f.T_world_left * Eigen::Vector3d(K.baseline, 0, 0);
    for (int v = 8; v < K.height - 8; v += 11)
      for (int u = 30; u < K.width - 8; u += 11) {
        const float z = f.depth.at<float>(v, u);
        EXPECT_NEAR(f.disparity.at<float>(v, u), fb / z, 1e-3 * fb / z);
        // The point must be seen by the right camera too (no occlusion).
        const Eigen::Vector3d X = f.T_world_left * Eigen::Vector3d((u - K.cx) / K.fx * z, (v - K.cy) / K.fy * z, z);
        const auto hit = w.raycast(o_right, X - o_right);
        if (!hit || hit->t < 1.0 - 1e-3) continue;
        // 7x7 patch, each pixel warped by its own disparity.
        std::vector<double> a, b;
        for (int dv = -3; dv <= 3; ++dv)
          for (int du = -3; du <= 3; ++du) {
            const float zz = f.depth.at<float>(v + dv, u + du);
            const float ur = static_cast<float>(u + du - fb / zz);
            if (ur < 0 || ur > K.width - 2) continue;
            cv::Mat px;
            cv::getRectSubPix(right, {1, 1}, {ur, static_cast<float>(v + dv)}, px);
            a.push_back(left.at<float>(v + dv, u + du));
            b.push_back(px.at<float>(0, 0));
          }
        if (a.size() < 40) continue;
        cv::Scalar ma, sa, mb, sb;
        cv::meanStdDev(a, ma, sa);
        cv::meanStdDev(b, mb, sb);
        if (sa[0] < 4) continue;  // flat patch: NCC meaningless
        double c = 0;
        for (size_t i = 0; i < a.size(); ++i) c += (a[i] - ma[0]) * (b[i] - mb[0]);
        nccs.push_back(c / (a.size() * sa[0] * sb[0] + 1e-9));
      }
  }
  ASSERT_GT(nccs.size(), 500u);
  std::sort(nccs.begin(), nccs.end());
  EXPECT_GT(nccs[nccs.size() / 2], 0.97);   // median
  EXPECT_GT(nccs[nccs.size() / 10], 0.85);  // 90 % of the patches
}

TEST(SimRender, StereoMatchingRecoversTheDisparity) {
  // The textures must let a standard matcher (OpenCV SGBM) find the true disparity.
  const World& w = test::default_world();
  RigConfig rig;
  rig.disparity = true;
  rig.noise_sigma = 1.0;
  StereoSimulation sim(w, rig, Trajectory::demo_flight(w));
  auto sgbm = cv::StereoSGBM::create(0, 64, 5, 8 * 25, 32 * 25, 1, 0, 10, 100, 2, cv::StereoSGBM::MODE_SGBM);
  for (int k : {200, 450, 700}) {
    const StereoFrame f = sim.frame(k);
    cv::Mat disp16;
    sgbm->compute(f.left, f.right, disp16);
    int valid = 0, good = 0;
    for (int v = 0; v < disp16.rows; ++v)
      for (int u = 64; u < disp16.cols; ++u) {  // columns with the full search range
        const short d = disp16.at<short>(v, u);
        if (d < 0) continue;
        ++valid;
        good += std::abs(d / 16.0 - f.disparity.at<float>(v, u)) <= 1.0;
      }
    const double area = (disp16.cols - 64.0) * disp16.rows;
    EXPECT_GT(valid, 0.9 * area) << "frame " << k;
    EXPECT_GT(good, 0.95 * valid) << "frame " << k;
  }
}

TEST(SimRender, HelipadBoxIsTheProjectionOfItsCorners) {
  const World& w = test::light_world();
  StereoSimulation sim = landing_simulation(w, landing_rig());
  const Intrinsics K = sim.intrinsics();
  int visible = 0;
  for (int k = 0; k < sim.frame_count(); k += 5) {
    const StereoFrame f = sim.frame(k);
    const geometry::SE3 T = f.T_world_left.inverse();
    const auto corners = w.helipad().corners();
    double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
    bool in_front = true, inside = true;
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector3d q = T * corners[i];
      if (q.z() <= 0) {
        in_front = false;
        continue;
      }
      const double u = K.fx * q.x() / q.z() + K.cx, v = K.fy * q.y() / q.z() + K.cy;
      EXPECT_NEAR(f.target_corners[i].x, u, 1e-9);
      EXPECT_NEAR(f.target_corners[i].y, v, 1e-9);
      x0 = std::min(x0, u), x1 = std::max(x1, u), y0 = std::min(y0, v), y1 = std::max(y1, v);
      inside = inside && u >= -0.5 && v >= -0.5 && u <= K.width - 0.5 && v <= K.height - 0.5;
    }
    EXPECT_EQ(f.target_visible, in_front && inside) << "frame " << k;  // nothing occludes the pad
    if (!in_front) continue;
    EXPECT_NEAR(f.target_box.x, x0, 1e-9);
    EXPECT_NEAR(f.target_box.y, y0, 1e-9);
    EXPECT_NEAR(f.target_box.width, x1 - x0, 1e-9);
    EXPECT_NEAR(f.target_box.height, y1 - y0, 1e-9);
    if (!f.target_visible) continue;
    ++visible;
    // The painted marking is where the geometry says: the centre of the H's bar is white,
    // the pad between the ring and a corner is dark.
    const cv::Point2d c = 0.25 * (f.target_corners[0] + f.target_corners[1] + f.target_corners[2] + f.target_corners[3]);
    const cv::Point2d dark = c + 0.9 * (f.target_corners[0] - c) ;
    if (f.target_box.width > 40) {
      EXPECT_GT(f.left.at<uint8_t>(cvRound(c.y), cvRound(c.x)), 180) << "frame " << k;
      EXPECT_LT(f.left.at<uint8_t>(cvRound(dark.y), cvRound(dark.x)), 90) << "frame " << k;
    }
  }
  EXPECT_GT(visible, 10);
}

TEST(SimRender, DeterministicForASeed) {
  WorldConfig wc;
  wc.texels_per_metre = 60;
  RigConfig rig;
  rig.noise_sigma = 2.0;
  const World w1 = World::room(wc), w2 = World::room(wc);
  const geometry::SE3 pose = Trajectory::demo_flight(w1).pose(20.0) * body_to_left(rig);
  const StereoFrame a = StereoRenderer(w1, rig).render(pose, 0, 7);
  const StereoFrame b = StereoRenderer(w2, rig).render(pose, 0, 7);
  EXPECT_EQ(cv::norm(a.left, b.left, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.right, b.right, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.depth, b.depth, cv::NORM_INF), 0.0);
  // Noise changes from frame to frame, textures with the world seed.
  const StereoFrame c = StereoRenderer(w1, rig).render(pose, 0, 8);
  EXPECT_GT(cv::norm(a.left, c.left, cv::NORM_L1) / a.left.total(), 0.5);
  wc.seed = 2;
  wc.n_obstacles = 0;  // same geometry as below, different textures
  const World w3 = World::room(wc);
  wc.seed = 1;
  const World w4 = World::room(wc);
  rig.noise_sigma = 0;
  const StereoFrame d = StereoRenderer(w3, rig).render(pose, 0, 7);
  const StereoFrame e = StereoRenderer(w4, rig).render(pose, 0, 7);
  EXPECT_EQ(cv::norm(d.depth, e.depth, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(d.left, e.left, cv::NORM_L1) / d.left.total(), 10.0);
}

TEST(SimRender, PhotometricOptions) {
  const World& w = test::light_world();
  RigConfig rig;
  const geometry::SE3 pose = Trajectory::demo_flight(w).pose(20.0) * body_to_left(rig);
  const StereoFrame base = StereoRenderer(w, rig).render(pose, 0, 0);
  rig.exposure = 0.5;
  const StereoFrame dim = StereoRenderer(w, rig).render(pose, 0, 0);
  EXPECT_NEAR(cv::mean(dim.left)[0], 0.5 * cv::mean(base.left)[0], 1.0);
  rig.exposure = 1.0;
  rig.color = true;
  const StereoFrame col = StereoRenderer(w, rig).render(pose, 0, 0);
  EXPECT_EQ(col.left.type(), CV_8UC3);
  EXPECT_EQ(col.right.type(), CV_8UC3);
  rig.color = false;
  rig.exposure = 0.5;  // no saturation below
  rig.illumination_amplitude = 0.3;
  rig.illumination_period = 4.0;
  const StereoFrame bright = StereoRenderer(w, rig).render(pose, 1'000'000, 0);  // sin = 1
  EXPECT_NEAR(cv::mean(bright.left)[0], 1.3 * cv::mean(dim.left)[0], 1.0);
}

TEST(SimRender, MotionBlurSmoothsTheImagesNotTheGroundTruth) {
  const World& w = test::light_world();
  RigConfig rig;
  const Trajectory demo = Trajectory::demo_flight(w);
  const StereoSimulation sharp(w, rig, demo);
  rig.motion_blur_samples = 8;
  rig.exposure_time = 0.05;
  const StereoSimulation blurred(w, rig, demo);
  const int k = 400;  // cruising along the survey loop
  const StereoFrame a = sharp.frame(k), b = blurred.frame(k);
  EXPECT_EQ(cv::norm(a.depth, b.depth, cv::NORM_INF), 0.0);
  EXPECT_EQ(a.target_box, b.target_box);
  auto gradient_energy = [](const cv::Mat& img) {
    cv::Mat gx;
    cv::Sobel(img, gx, CV_32F, 1, 0);
    return cv::norm(gx, cv::NORM_L1);
  };
  EXPECT_LT(gradient_energy(b.left), 0.95 * gradient_energy(a.left));
  EXPECT_LT(gradient_energy(b.right), 0.95 * gradient_energy(a.right));
  EXPECT_NEAR(cv::mean(b.left)[0], cv::mean(a.left)[0], 2.0);  // same light
}

TEST(SimRender, TexturesGiveFastCornersEverywhere) {
  const World& w = test::default_world();
  StereoSimulation sim(w, RigConfig{}, Trajectory::demo_flight(w));
  auto fast = cv::FastFeatureDetector::create(20);
  int cells = 0, good = 0;
  for (int k = 60; k < sim.frame_count(); k += 120) {
    const StereoFrame f = sim.frame(k);
    std::vector<cv::KeyPoint> kps;
    fast->detect(f.left, kps);
    // 4x4 buckets: each should hold corners for a bucketed feature tracker.
    int count[4][4] = {};
    for (const auto& kp : kps)
      ++count[std::min(3, static_cast<int>(4 * kp.pt.y / f.left.rows))][std::min(3, static_cast<int>(4 * kp.pt.x / f.left.cols))];
    for (auto& row : count)
      for (int c : row) {
        ++cells;
        good += c >= 5;
      }
    EXPECT_GT(kps.size(), 300u) << "frame " << k;
  }
  EXPECT_GT(good, 0.85 * cells);
}

}  // namespace
}  // namespace aerie::sim
