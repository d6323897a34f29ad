// aerie-map-simfeed: the simulator's ground truth as VO_POSE + VO_DEPTH, a stand-in for
// aerie-vo so that aerie-map (and the viewer) can run on the demo flight without VO.
#include <aerie/pose_t.hpp>
#include <spdlog/spdlog.h>

#include <opencv2/calib3d.hpp>

#include <chrono>
#include <thread>

#include "common/bus/bus.hpp"
#include "common/bus/node.hpp"
#include "common/sim/simulation.hpp"
#include "common/spherical/spherical_message.hpp"
#include "common/util/cli.hpp"

int main(int argc, char** argv) {
  CLI::App app{
      "aerie-map-simfeed: renders the simulator's demo flight and publishes its ground-truth pose (VO_POSE)\n"
      "and depth as spherical depth (VO_DEPTH, thesis eq. 4.17) - a stand-in for aerie-vo."};
  aerie::util::CommonOptions opts;
  aerie::util::add_common_options(app, opts, false);
  double rate = 20.0, bin_deg = 1.0;
  int stride = 1, max_frames = 0;
  std::string depth_source = "exact";
  app.add_option("--rate", rate, "frames per second of wall time (0 = as fast as possible)")->capture_default_str();
  app.add_option("--stride", stride, "publish every Nth frame of the 20 Hz flight")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--max-frames", max_frames, "stop after this many frames (0 = the whole flight)")->capture_default_str();
  app.add_option("--bin-deg", bin_deg, "spherical bin size (deg)")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--depth", depth_source, "exact (ground truth) or sgbm (OpenCV StereoSGBM on the rendered pair)")
      ->check(CLI::IsMember({"exact", "sgbm"}))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  aerie::util::init_logging("aerie-map-simfeed", opts.log_level);
  aerie::bus::install_stop_handlers();
  try {
    namespace sim = aerie::sim;
    namespace sp = aerie::spherical;
    const auto world = sim::World::room(sim::WorldConfig{});
    sim::StereoSimulation simulation(world, sim::RigConfig{}, sim::Trajectory::demo_flight(world), 20.0);
    const auto k = simulation.intrinsics();
    sp::EncoderConfig enc;
    enc.angular_resolution_rad = sp::deg_to_rad(static_cast<float>(bin_deg));
    const sp::SphericalEncoder encoder({k.fx, k.fy, k.cx, k.cy, k.baseline}, {k.width, k.height}, enc);
    auto sgbm = cv::StereoSGBM::create(0, 64, 5, 8 * 25, 32 * 25, 1, 0, 10, 100, 2);
    aerie::bus::Bus bus(opts.lcm_url);
    spdlog::info("demo flight: {} frames, publishing every {} on {}", simulation.frame_count(), stride, bus.url());
    int published = 0;
    auto next = std::chrono::steady_clock::now();
    for (int i = 0; i < simulation.frame_count() && !aerie::bus::stop_requested(); i += stride) {
      const auto f = simulation.frame(i);
      sp::SphericalDepth depth;
      if (depth_source == "sgbm") {
        cv::Mat disparity;
        sgbm->compute(f.left, f.right, disparity);
        depth = encoder.encode_disparity(disparity);
      } else {
        depth = encoder.encode_depth(f.depth);
      }
      aerie::pose_t pose{};
      pose.utime = f.utime;
      pose.seq = published;
      f.T_world_left.to_wxyz(pose.orientation);
      for (int j = 0; j < 3; ++j) pose.position[j] = f.T_world_left.translation()[j];
      pose.status = aerie::pose_t::OK;
      bus.publish("VO_POSE", pose);
      bus.publish("VO_DEPTH", sp::to_message(depth, f.utime, published, f.T_world_left));
      ++published;
      if (max_frames > 0 && published >= max_frames) break;
      if (rate > 0) {
        next += std::chrono::microseconds(static_cast<int64_t>(1e6 / rate));
        std::this_thread::sleep_until(next);
      }
    }
    spdlog::info("published {} frames", published);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
  return 0;
}
