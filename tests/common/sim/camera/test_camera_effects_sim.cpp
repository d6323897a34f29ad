// The camera-effects stage in the flight simulator: off by default (today's frames, byte for
// byte, also with `effects: ideal`), deterministic in lock-step with every effect on, and the
// pad's ground truth follows the lens.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <fstream>

#include "common/sim/flight/flight_config.hpp"
#include "common/sim/flight/flight_sim.hpp"

using namespace aerie;
using namespace aerie::sim;

namespace {

FlightSimConfig small_room(const std::string& yaml = "") {
  FlightSimConfig c = load_flight_config(util::Config::parse(
      "seed: 5\nstereo: true\nworld: {n_obstacles: 0, texels_per_metre: 100}\n"
      "placement: {start_distance_min_m: 0.0, start_distance_max_m: 0.0, clearance_radius_m: 1.0}\n" + yaml,
      "flight.yaml"));
  return c;
}

// Takes off and flies sideways and turning (the camera moves during its exposures).
std::vector<FlightFrame> fly(const FlightSimConfig& c, int frames) {
  FlightSim sim(c);
  std::vector<FlightFrame> out;
  for (int k = 0; k < frames; ++k) {
    CommandInput cmd;
    cmd.mode = k < 40 ? 3 : 1;
    cmd.velocity = {0.8, 0.5, 0.0};
    cmd.yaw_rate_deg_s = 30;
    sim.command(cmd);
    out.push_back(sim.step());
  }
  return out;
}

double diff(const cv::Mat& a, const cv::Mat& b) { return cv::norm(a, b, cv::NORM_INF); }

const char* kReal =
    "camera_effects:\n"
    "  down:\n"
    "    part: rpi-camera-module-3\n"
    "    lens: {enabled: true, model: radial-tangential, coeffs: [-0.12, 0.02, 0.0005, -0.0003]}\n"
    "    jpeg: {enabled: true, quality: 85}\n"
    "  stereo:\n"
    "    part: ov9281\n"
    "    lens: {enabled: true, model: equidistant, coeffs: [-0.01, 0.02, -0.01, 0.003]}\n";

}  // namespace

TEST(FlightSimCameraEffects, OffByDefaultAndIdealGiveTodaysFramesByteForByte) {
  EXPECT_FALSE(FlightSimConfig{}.down_effects.any());
  EXPECT_FALSE(FlightSimConfig{}.stereo_effects.any());
  const auto today = fly(small_room(), 50);
  const auto ideal = fly(small_room("camera_effects:\n  down: {part: rpi-camera-module-3, effects: ideal}\n"
                                    "  stereo: {part: ov9281, noise: {enabled: false}, effects: ideal}\n"),
                         50);
  ASSERT_EQ(today.size(), ideal.size());
  for (size_t k = 0; k < today.size(); ++k) {
    EXPECT_EQ(diff(today[k].down.left, ideal[k].down.left), 0.0) << "frame " << k;
    EXPECT_EQ(diff(today[k].stereo->left, ideal[k].stereo->left), 0.0) << "frame " << k;
    EXPECT_EQ(diff(today[k].stereo->right, ideal[k].stereo->right), 0.0) << "frame " << k;
  }
}

TEST(FlightSimCameraEffects, EveryEffectOnIsDeterministicInLockStep) {
  const auto a = fly(small_room(kReal), 50), b = fly(small_room(kReal), 50);
  const auto today = fly(small_room(), 50);
  int changed = 0;
  for (size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(diff(a[k].down.left, b[k].down.left), 0.0) << "frame " << k;
    ASSERT_EQ(diff(a[k].stereo->left, b[k].stereo->left), 0.0) << "frame " << k;
    ASSERT_EQ(diff(a[k].stereo->right, b[k].stereo->right), 0.0) << "frame " << k;
    EXPECT_EQ(a[k].down.left.size(), today[k].down.left.size());
    changed += diff(a[k].down.left, today[k].down.left) > 0;
  }
  EXPECT_EQ(changed, 50);
  // The vehicle flies the same (the effects change the images only).
  EXPECT_EQ(a.back().vehicle.position, today.back().vehicle.position);
  // A different flight seed: different noise.
  auto other = small_room(kReal);
  other.seed = 6;
  EXPECT_GT(diff(FlightSim(other).step().down.left, FlightSim(small_room(kReal)).step().down.left), 0.0);
}

TEST(FlightSimCameraEffects, ThePadsTruthFollowsTheLens) {
  // Hovering over the pad: each ground-truth corner of the distorted frame is the lens'
  // projection of the corner's ray, and its published intrinsics are the real camera's.
  auto c = small_room(kReal);
  c.placement.start_height_m = 2.0;
  c.placement.start_x_m = c.placement.start_y_m = 0.0;
  c.world.helipad_x = 0.0;
  c.world.helipad_y = 0.0;
  FlightSim sim(c);
  const FlightFrame f = sim.step();
  ASSERT_TRUE(f.down.target_visible);
  const Intrinsics rig = StereoRenderer(sim.world(), FlightSimConfig::down_rig()).intrinsics();
  camera::CameraModel lens = rig.calibration().left;
  lens.distortion = camera::Distortion::RadTan;
  lens.coeffs = {-0.12, 0.02, 0.0005, -0.0003};
  const geometry::SE3 T_cam_world = f.T_world_down.inverse();
  const auto corners = sim.world().helipad().corners();
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector2d p = lens.project(T_cam_world * corners[i]);
    EXPECT_NEAR(f.down.target_corners[i].x, p.x(), 1e-6);
    EXPECT_NEAR(f.down.target_corners[i].y, p.y(), 1e-6);
  }
  EXPECT_GT(sim.down_intrinsics().fx, 0);
  EXPECT_LT(sim.down_intrinsics().fx, rig.fx);  // the ideal frames are wider than the lens' pinhole
  EXPECT_NEAR(sim.down_calibration().fx, rig.fx, 0.05 * rig.fx);  // published: the real camera's, with its error
}

TEST(FlightSimCameraEffects, TheCommentedBlockOfTheLandingConfigsTurnsThemOn) {
  // config/sim/landing_{room,field}.yaml carry a disabled camera_effects block: as shipped it
  // changes nothing; uncommented, it is a valid config with the real down camera on.
  for (const std::string name : {"landing_room.yaml", "landing_field.yaml"}) {
    const std::string path = std::string(AERIE_SOURCE_DIR) + "/config/sim/" + name;
    EXPECT_FALSE(load_flight_config(util::Config::load(path)).down_effects.any()) << name;
    std::ifstream in(path);
    std::string text, line;
    bool block = false;
    while (std::getline(in, line)) {
      if (line.rfind("# camera_effects:", 0) == 0) block = true;
      if (block && line.rfind("# ", 0) == 0) line = line.substr(2);
      text += line + "\n";
    }
    ASSERT_TRUE(block) << name;
    const FlightSimConfig on = load_flight_config(util::Config::parse(text, path));
    EXPECT_EQ(on.down_effects.part, "rpi-camera-module-3");
    EXPECT_TRUE(on.down_effects.motion.rolling_shutter);
    EXPECT_TRUE(on.down_effects.noise.enabled);
    EXPECT_FALSE(on.down_effects.lens.enabled);
    EXPECT_EQ(on.stereo_effects.part, "ov9281");
    EXPECT_FALSE(on.stereo_effects.motion.rolling_shutter);
  }
}
