#include "air/capture/sim_source.hpp"

#include <cstdio>

#include "common/util/time.hpp"

namespace aerie::capture {

SimSource::SimSource(const SimSourceOptions& options, int width, int height, bool color, double fps)
    : opt_(options) {
  sim::WorldConfig wc;
  wc.seed = opt_.seed;
  const sim::World world = sim::World::room(wc);
  sim::RigConfig rig = opt_.trajectory == "landing" ? sim::landing_rig() : sim::RigConfig{};
  if (width > 0) rig.width = width;
  if (height > 0) rig.height = height;
  rig.color = color;
  rig.noise_sigma = opt_.noise_sigma;
  if (!(opt_.speed > 0)) throw std::invalid_argument("sim.speed must be positive");
  if (!(fps > 0)) throw std::invalid_argument("the simulator's frame rate (fps) must be positive");
  sim::Trajectory traj;
  if (opt_.trajectory == "demo") {
    traj = sim::Trajectory::demo_flight(world, opt_.speed);
  } else if (opt_.trajectory == "survey") {
    if (opt_.loops < 1) throw std::invalid_argument("sim.loops must be >= 1");
    traj = sim::Trajectory::survey_loops(world, opt_.loops, opt_.speed);
  } else if (opt_.trajectory == "landing") {
    traj = sim::Trajectory::landing(world, opt_.speed);
  } else {
    throw std::invalid_argument("unknown sim.trajectory '" + opt_.trajectory + "' (expected demo, survey or landing)");
  }
  const int64_t start = opt_.start_utime >= 0 ? opt_.start_utime : util::wall_utime();
  sim_ = std::make_unique<sim::StereoSimulation>(world, rig, std::move(traj), fps, start);
}

std::string SimSource::describe() const {
  const auto K = sim_->intrinsics();
  char buf[256];
  std::snprintf(buf, sizeof buf, "simulator (seed %llu, %s trajectory %.1f s, %d stereo frames at %.0f Hz, %dx%d)",
                static_cast<unsigned long long>(opt_.seed), opt_.trajectory.c_str(), sim_->trajectory().duration(),
                sim_->frame_count(), sim_->rate_hz(), K.width, K.height);
  return buf;
}

cv::Size SimSource::size() const {
  const auto K = sim_->intrinsics();
  return {K.width, K.height};
}

std::optional<camera::RectifiedStereo> SimSource::rectified() const {
  const auto K = sim_->intrinsics();
  return camera::RectifiedStereo{K.fx, K.fy, K.cx, K.cy, K.baseline, {K.width, K.height}};
}

bool SimSource::next(Frame& frame) {
  sim::StereoFrame sf;
  if (!sim_->next(sf)) return false;
  frame = Frame{};
  frame.index = sf.seq;
  frame.utime = sf.utime;
  frame.left = std::move(sf.left);
  frame.right = std::move(sf.right);
  frame.gt_pose = GroundTruthPose{sf.T_world_left, "sim"};
  frame.gt_box = GroundTruthBox{"helipad", sf.target_visible, sf.target_box, sf.target_corners};
  return true;
}

}  // namespace aerie::capture
