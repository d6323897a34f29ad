// Spherical depth (thesis eq. 4.17): conversion round-trips, binning, encoders, VO_DEPTH message.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

// lcm-gen's decode() reads its hash through an out-parameter that GCC cannot follow.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <aerie/spherical_depth_t.hpp>
#pragma GCC diagnostic pop

#include "common/spherical/spherical_depth.hpp"
#include "common/spherical/spherical_message.hpp"

namespace sp = aerie::spherical;
using Eigen::Vector3f;

namespace {
constexpr float kPi = std::numbers::pi_v<float>;
// The 376x240 demo camera (about 72 x 50 degrees).
const sp::Intrinsics kCam{260.0, 260.0, 187.5, 119.5, 0.12};
const cv::Size kSize(376, 240);

// Depth (z) image of a sphere of radius R around the camera: every pixel has range R.
cv::Mat sphere_depth(float R) {
  cv::Mat depth(kSize, CV_32F);
  for (int v = 0; v < kSize.height; ++v)
    for (int u = 0; u < kSize.width; ++u) {
      const Vector3f ray(static_cast<float>((u - kCam.cx) / kCam.fx), static_cast<float>((v - kCam.cy) / kCam.fy), 1.f);
      depth.at<float>(v, u) = R / ray.norm();
    }
  return depth;
}
}  // namespace

TEST(Spherical, Eq417KnownValues) {
  const auto s = sp::to_spherical({3.f, 4.f, 0.f});
  EXPECT_FLOAT_EQ(s.r, 5.f);
  EXPECT_FLOAT_EQ(s.polar, kPi / 2);
  EXPECT_FLOAT_EQ(s.azimuth, std::atan2(4.f, 3.f));
  EXPECT_FLOAT_EQ(sp::to_spherical({-1.f, 0.f, 0.f}).azimuth, kPi);        // tan^-1 in all four quadrants
  EXPECT_FLOAT_EQ(sp::to_spherical({0.f, -2.f, 0.f}).azimuth, -kPi / 2);
  EXPECT_NEAR(sp::to_spherical({1.f, 0.f, 1.f}).polar, kPi / 4, 1e-6);
  const auto origin = sp::to_spherical({0.f, 0.f, 0.f});
  EXPECT_EQ(origin.r, 0.f);
  EXPECT_EQ(origin.polar, 0.f);
  EXPECT_EQ(origin.azimuth, 0.f);
}

TEST(Spherical, RoundTripIncludingThePoles) {
  for (float r : {0.05f, 1.f, 37.5f}) {
    const auto north = sp::to_spherical({0.f, 0.f, r});
    EXPECT_FLOAT_EQ(north.polar, 0.f);
    EXPECT_FLOAT_EQ(north.azimuth, 0.f);
    const auto south = sp::to_spherical({0.f, 0.f, -r});
    EXPECT_FLOAT_EQ(south.polar, kPi);
    EXPECT_FLOAT_EQ(south.azimuth, 0.f);
    EXPECT_LT((sp::to_cartesian(north) - Vector3f(0, 0, r)).norm(), 1e-6f * r);
    EXPECT_LT((sp::to_cartesian(south) - Vector3f(0, 0, -r)).norm(), 1e-6f * r);
    // Just off the poles the azimuth is still recovered.
    const Vector3f near_pole(1e-4f * r, -1e-4f * r, r);
    EXPECT_LT((sp::to_cartesian(sp::to_spherical(near_pole)) - near_pole).norm(), 1e-6f * r);
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-20.f, 20.f);
  for (int i = 0; i < 2000; ++i) {
    const Vector3f p(u(rng), u(rng), u(rng));
    const auto s = sp::to_spherical(p);
    ASSERT_GE(s.polar, 0.f);
    ASSERT_LE(s.polar, kPi);
    ASSERT_GT(s.azimuth, -kPi - 1e-6f);
    ASSERT_LE(s.azimuth, kPi);
    ASSERT_LT((sp::to_cartesian(s) - p).norm(), 1e-5f * (1.f + p.norm())) << p.transpose();
  }
}

TEST(Spherical, CameraFrameMapsOntoTheEquator) {
  const Vector3f forward_c(0.f, 0.f, 2.f), up_c(0.f, -1.f, 0.f), left_c(-1.f, 0.f, 0.f);
  EXPECT_FLOAT_EQ(sp::to_spherical(sp::camera_to_sensor(forward_c)).polar, kPi / 2);
  EXPECT_FLOAT_EQ(sp::to_spherical(sp::camera_to_sensor(forward_c)).azimuth, 0.f);
  EXPECT_FLOAT_EQ(sp::to_spherical(sp::camera_to_sensor(up_c)).polar, 0.f);
  EXPECT_FLOAT_EQ(sp::to_spherical(sp::camera_to_sensor(left_c)).azimuth, kPi / 2);
  const Vector3f p(0.3f, -1.2f, 4.f);
  EXPECT_EQ(sp::sensor_to_camera(sp::camera_to_sensor(p)), p);
}

TEST(Spherical, FullSphereGridCoversThePoles) {
  const auto g = sp::AngularGrid::full_sphere(sp::deg_to_rad(1.f));
  EXPECT_EQ(g.n_polar, 180);
  EXPECT_EQ(g.n_azimuth, 360);
  EXPECT_EQ(g.bin(0.f, 0.f), 180);                  // north pole: first polar row
  EXPECT_EQ(g.bin(kPi, kPi), g.size() - 1);         // south pole, azimuth pi: the last bin
  EXPECT_EQ(g.bin(kPi / 2, -kPi), 90 * 360);
  EXPECT_EQ(g.bin(-0.01f, 0.f), -1);
  EXPECT_EQ(g.bin(std::numeric_limits<float>::quiet_NaN(), 0.f), -1);
  // A point at the pole survives encoding and decoding.
  const std::vector<Vector3f> poles{sp::sensor_to_camera({0.f, 0.f, 2.f}), sp::sensor_to_camera({0.f, 0.f, -3.f})};
  const auto d = sp::encode_points(poles, g);
  ASSERT_EQ(d.size(), 2u);
  const auto back = d.decode();
  const float tol = 3.f * sp::deg_to_rad(1.f);  // within one bin (centre offset)
  EXPECT_NEAR(sp::camera_to_sensor(back[0]).z(), 2.f, 1e-3f);
  EXPECT_LT(sp::camera_to_sensor(back[0]).head<2>().norm(), tol * 2.f);
  EXPECT_NEAR(sp::camera_to_sensor(back[1]).z(), -3.f, 1e-3f);
  EXPECT_LT(sp::camera_to_sensor(back[1]).head<2>().norm(), tol * 3.f);
}

TEST(Spherical, CameraGridCoversEveryPixel) {
  sp::EncoderConfig cfg;
  cfg.angular_resolution_rad = sp::deg_to_rad(0.5f);
  const sp::SphericalEncoder enc(kCam, kSize, cfg);
  const auto& g = enc.grid();
  EXPECT_FLOAT_EQ(g.polar_step, sp::deg_to_rad(0.5f));
  // Horizontal field of view 2 atan(188 / 260) ~ 71.7 deg -> about 144 bins of 0.5 deg.
  EXPECT_GE(g.n_azimuth, 144);
  EXPECT_LE(g.n_azimuth, 148);
  EXPECT_GE(g.n_polar, 97);
  EXPECT_LE(g.n_polar, 101);
  const auto d = enc.encode_depth(sphere_depth(4.f));
  // Every pixel lands in the grid: the bins hit are the bins the pixel rays fall in;
  // the image covers most of the grid (the corners of the angular box are outside).
  EXPECT_GT(static_cast<double>(d.size()), 0.85 * g.size());
}

TEST(Spherical, SphereAroundTheCameraDecodesAtItsRadius) {
  for (auto reduction : {sp::Reduction::Median, sp::Reduction::Nearest}) {
    sp::EncoderConfig cfg;
    cfg.reduction = reduction;
    const sp::SphericalEncoder enc(kCam, kSize, cfg);
    const auto d = enc.encode_depth(sphere_depth(4.f));
    d.validate();
    for (const auto& p : d.decode()) ASSERT_NEAR(p.norm(), 4.f, 0.5f * cfg.range_scale_m + 1e-5f);
  }
}

TEST(Spherical, PlaneDecodesOntoThePlane) {
  sp::EncoderConfig cfg;
  cfg.angular_resolution_rad = sp::deg_to_rad(0.5f);
  const sp::SphericalEncoder enc(kCam, kSize, cfg);
  const float z = 3.f;
  const auto d = enc.encode_depth(cv::Mat(kSize, CV_32F, cv::Scalar(z)));
  ASSERT_GT(d.size(), 10000u);
  // The decoded direction is the bin centre: the range spread inside a 0.5 deg bin on a
  // plane seen at up to ~40 deg incidence bounds the error to a few centimetres.
  double worst = 0;
  for (const auto& p : d.decode()) worst = std::max(worst, static_cast<double>(std::abs(p.z() - z)));
  EXPECT_LT(worst, 0.05);
  // Finer bins, smaller error.
  sp::EncoderConfig fine;
  fine.angular_resolution_rad = sp::deg_to_rad(0.1f);
  const auto df = sp::SphericalEncoder(kCam, kSize, fine).encode_depth(cv::Mat(kSize, CV_32F, cv::Scalar(z)));
  double worst_fine = 0;
  for (const auto& p : df.decode()) worst_fine = std::max(worst_fine, static_cast<double>(std::abs(p.z() - z)));
  EXPECT_LT(worst_fine, worst / 3);
}

TEST(Spherical, DisparityGivesTheSameBinsAsDepth) {
  const sp::SphericalEncoder enc(kCam, kSize);
  cv::Mat depth = sphere_depth(5.f);
  cv::Mat disp32 = kCam.fx * kCam.baseline / depth;
  cv::Mat disp16;
  disp32.convertTo(disp16, CV_16S, 16.0);
  const auto a = enc.encode_depth(depth);
  const auto b = enc.encode_disparity(disp32);
  const auto c = enc.encode_disparity(disp16);
  EXPECT_EQ(a.bins, b.bins);
  EXPECT_EQ(a.bins, c.bins);
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_NEAR(a.range(i), b.range(i), 2e-3f);
    // x16 fixed point: 1/16 px at ~6 px disparity is ~1% of the range.
    ASSERT_NEAR(a.range(i), c.range(i), 0.06f);
  }
}

TEST(Spherical, InvalidPixelsAndOutOfRangeAreDropped) {
  sp::EncoderConfig cfg;
  cfg.max_range_m = 10.f;
  const sp::SphericalEncoder enc(kCam, kSize, cfg);
  cv::Mat depth(kSize, CV_32F, cv::Scalar(0.f));  // no depth anywhere
  depth.at<float>(10, 10) = std::numeric_limits<float>::quiet_NaN();
  depth.at<float>(11, 10) = std::numeric_limits<float>::infinity();
  depth.at<float>(12, 10) = -2.f;
  depth.at<float>(13, 10) = 50.f;   // beyond max_range
  depth.at<float>(14, 10) = 0.05f;  // nearer than min_range
  EXPECT_EQ(enc.encode_depth(depth).size(), 0u);
  depth.at<float>(120, 188) = 2.f;
  const auto d = enc.encode_depth(depth);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_NEAR(d.decode()[0].z(), 2.f, 0.01f);
}

TEST(Spherical, OneRangePerBinMedianOrNearest) {
  const auto g = sp::AngularGrid::full_sphere(sp::deg_to_rad(2.f));
  // Five points along (almost) the same ray: one bin; and two points in another bin.
  std::vector<Vector3f> pts;
  for (float r : {3.f, 1.f, 10.f, 2.f, 2.5f}) pts.push_back(Vector3f(0.001f, 0.f, 1.f).normalized() * r);
  for (float r : {4.f, 6.f}) pts.push_back(Vector3f(1.f, 0.f, 1.f).normalized() * r);
  sp::EncoderConfig cfg;
  cfg.reduction = sp::Reduction::Median;
  auto d = sp::encode_points(pts, g, cfg);
  ASSERT_EQ(d.size(), 2u);
  // Bins ascend with the azimuth: the bin at azimuth -45 deg (camera x = z) comes first.
  EXPECT_FLOAT_EQ(d.range(0), 4.f);  // lower median of 4, 6
  EXPECT_FLOAT_EQ(d.range(1), 2.5f);  // median of 1, 2, 2.5, 3, 10
  cfg.reduction = sp::Reduction::Nearest;
  d = sp::encode_points(pts, g, cfg);
  EXPECT_FLOAT_EQ(d.range(0), 4.f);
  EXPECT_FLOAT_EQ(d.range(1), 1.f);
  cfg.min_points_per_bin = 3;
  d = sp::encode_points(pts, g, cfg);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_FLOAT_EQ(d.range(0), 1.f);
}

TEST(Spherical, BadInputsAreRejectedWithAClearMessage) {
  const sp::SphericalEncoder enc(kCam, kSize);
  auto message_of = [](auto&& f) {
    try {
      f();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  EXPECT_NE(message_of([&] { enc.encode_depth(cv::Mat(kSize, CV_64F, cv::Scalar(1.0))); }).find("CV_32FC1"),
            std::string::npos);
  EXPECT_NE(message_of([&] { enc.encode_depth(cv::Mat(10, 10, CV_32F, cv::Scalar(1.0))); }).find("10x10"),
            std::string::npos);
  sp::Intrinsics no_baseline = kCam;
  no_baseline.baseline = 0;
  EXPECT_NE(message_of([&] {
              sp::SphericalEncoder(no_baseline, kSize).encode_disparity(cv::Mat(kSize, CV_32F, cv::Scalar(1.f)));
            }).find("baseline"),
            std::string::npos);
  sp::EncoderConfig too_far;
  too_far.max_range_m = 100.f;  // 100 m / 1 mm does not fit int16
  EXPECT_NE(message_of([&] { sp::SphericalEncoder(kCam, kSize, too_far); }).find("32767"), std::string::npos);
  EXPECT_THROW(sp::SphericalEncoder(sp::Intrinsics{}, kSize), std::invalid_argument);
}

TEST(SphericalMessage, SparseAndDenseRoundTripThroughLcmBytes) {
  const sp::SphericalEncoder enc(kCam, kSize);
  cv::Mat depth = sphere_depth(3.f);
  const auto dense = enc.encode_depth(depth);
  cv::Mat sparse_depth(kSize, CV_32F, cv::Scalar(0.f));
  depth(cv::Rect(100, 100, 30, 20)).copyTo(sparse_depth(cv::Rect(100, 100, 30, 20)));
  const auto sparse = enc.encode_depth(sparse_depth);
  const auto pose = aerie::geometry::SE3::from_rotation_vector({0.1, -0.2, 0.3}, {1.0, 2.0, -0.5});
  for (const auto* d : {&dense, &sparse}) {
    const auto msg = sp::to_message(*d, 123456, 7, pose);
    EXPECT_EQ(msg.nbins == 0, d == &dense) << "layout";
    std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
    ASSERT_EQ(msg.encode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
    aerie::spherical_depth_t back_msg;
    ASSERT_EQ(back_msg.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
    const auto back = sp::from_message(back_msg);
    EXPECT_EQ(back.grid, d->grid);
    EXPECT_EQ(back.bins, d->bins);
    EXPECT_EQ(back.range_q, d->range_q);
    EXPECT_FLOAT_EQ(back.focal_px, 260.f);
    EXPECT_FLOAT_EQ(back.baseline_m, 0.12f);
    EXPECT_EQ(back_msg.utime, 123456);
    const auto p = sp::pose_of(back_msg);
    ASSERT_TRUE(p.has_value());
    EXPECT_LT((p->translation() - pose.translation()).norm(), 1e-12);
    EXPECT_LT(p->rotation().angularDistance(pose.rotation()), 1e-9);
  }
  EXPECT_LT(sp::to_message(sparse, 0, 0, pose).getEncodedSize(), sp::to_message(dense, 0, 0, pose).getEncodedSize());
  EXPECT_FALSE(sp::pose_of(sp::to_message(sparse, 0, 0, std::nullopt)).has_value());
}

TEST(SphericalMessage, MalformedMessagesAreRejected) {
  const auto g = sp::AngularGrid::full_sphere(sp::deg_to_rad(10.f));
  const auto d = sp::encode_points({Vector3f(0.f, 0.f, 2.f)}, g);
  auto good = sp::to_message(d, 1, 1, aerie::geometry::SE3::identity());
  ASSERT_GT(good.nbins, 0);
  auto what = [](const aerie::spherical_depth_t& m) {
    try {
      sp::from_message(m);
      (void)sp::pose_of(m);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(what(good), "accepted");
  auto m = good;
  m.nrange = 0;
  m.range.clear();
  EXPECT_NE(what(m).find("nrange"), std::string::npos);
  m = good;
  m.bin[0] = g.size() + 5;
  EXPECT_NE(what(m).find("outside the grid"), std::string::npos);
  m = good;
  m.range[0] = -3;
  EXPECT_NE(what(m).find("not positive"), std::string::npos);
  m = good;
  m.n_polar = 0;
  EXPECT_NE(what(m).find("n_polar"), std::string::npos);
  m = good;
  m.orientation[0] = 0.5;
  EXPECT_NE(what(m).find("unit quaternion"), std::string::npos);
  m = good;
  m.position[1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(what(m).find("not finite"), std::string::npos);
}
