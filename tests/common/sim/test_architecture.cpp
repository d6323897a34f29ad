// The simulator draws the same world on every architecture. A call's arguments are evaluated
// in an unspecified order (x86-64 GCC right to left, arm64 left to right), so two random draws
// in one call gave arm64 other worlds, textures and IMU noise than x86 (issue 50, section 5).
// The values below are x86-64's; scripts/arm.sh runs this test on arm64. Tolerances allow for
// the last bits of floating point (arm64 contracts a*b+c into one rounding), not for another
// draw, which moves a box by decimetres and a mark by pixels.
#include <gtest/gtest.h>

#include <array>

#include <opencv2/imgproc.hpp>

#include "common/sim/flight/imu.hpp"
#include "common/sim/simulation.hpp"
#include "tests/common/sim/sim_fixtures.hpp"

namespace aerie::sim {
namespace {

void expect_near(const Eigen::Vector3d& v, const std::array<double, 3>& want, double tol, const char* what) {
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(v[i], want[i], tol) << what << "[" << i << "]";
}

TEST(SimArchitecture, RoomAndFieldLayoutsAreTheX86Ones) {
  const World& room = test::default_world();
  ASSERT_GE(room.obstacles().size(), 2u);
  expect_near(room.obstacles()[0].box.min, {2.803269317091, 1.168766973002, 0.0}, 1e-9, "room obstacle 0 min");
  expect_near(room.obstacles()[1].box.max, {-0.492605636767, -1.791927664873, 1.633058302791}, 1e-9, "room obstacle 1 max");
  WorldConfig fc;
  fc.kind = "field";  // small and coarse, placed by the seed
  fc.field_x = 20;
  fc.field_y = 16;
  fc.field_texels_per_metre = 40;
  fc.vehicle_texels_per_metre = 300;
  fc.cruise_altitude = 3.0;
  const World field = World::field(fc);
  ASSERT_GE(field.obstacles().size(), 2u);
  expect_near(field.obstacles()[0].box.min, {-2.709032794915, -0.738346735193, 0.0}, 1e-9, "field obstacle 0 min");
  expect_near(field.obstacles().back().box.max, {3.980845553897, 5.404652525017, 6.598104051577}, 1e-9, "field last obstacle max");
}

TEST(SimArchitecture, ImuNoiseIsTheX86One) {
  Imu imu(ImuParams{}, 42);
  ImuSample s;
  for (int i = 0; i < 50; ++i)
    s = imu.sample(0.005 * i, Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.1, 0.2, 0.3),
                   Eigen::Vector3d(0.5, 0, 0));
  expect_near(s.gyro, {0.095421087694, 0.202253734665, 0.300051269894}, 1e-9, "gyro");
  expect_near(s.accel, {0.511687813685, -0.084831380833, 9.815415517762}, 1e-9, "accel");
}

// The textures: 8 x 8 block means of a rendered view (a mark drawn elsewhere moves them).
TEST(SimArchitecture, RenderedViewIsTheX86One) {
  const World& w = test::light_world();
  const RigConfig rig;
  const geometry::SE3 pose = Trajectory::demo_flight(w).pose(20.0) * body_to_left(rig);
  const cv::Mat left = StereoRenderer(w, rig).render(pose, 0, 0).left;
  cv::Mat blocks;
  cv::resize(left, blocks, cv::Size(8, 8), 0, 0, cv::INTER_AREA);
  const std::array<int, 64> want{149, 133, 101, 168, 188, 137, 157, 146, 135, 144, 127, 169, 177, 172, 165, 162,
                                 99,  120, 126, 184, 151, 170, 178, 164, 92,  104, 110, 139, 146, 128, 149, 137,
                                 141, 123, 112, 124, 118, 101, 96,  107, 146, 117, 110, 120, 120, 92,  92,  109,
                                 126, 114, 125, 104, 131, 93,  70,  88,  92,  103, 133, 141, 135, 136, 88,  77};
  for (int i = 0; i < 64; ++i) EXPECT_NEAR(blocks.at<uint8_t>(i / 8, i % 8), want[i], 1) << "block " << i;
}

}  // namespace
}  // namespace aerie::sim
