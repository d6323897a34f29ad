#include "common/sim/simulation.hpp"

#include <cmath>
#include <stdexcept>
#include <vector>

namespace aerie::sim {

StereoSimulation::StereoSimulation(World world, RigConfig rig, Trajectory trajectory, double rate_hz,
                                   int64_t start_utime)
    : renderer_(world, rig),
      trajectory_(std::move(trajectory)),
      T_body_left_(body_to_left(rig)),
      rate_hz_(rate_hz),
      start_utime_(start_utime) {
  if (!(rate_hz > 0)) throw std::invalid_argument("sim::StereoSimulation: rate_hz must be > 0");
  frame_count_ = static_cast<int>(std::floor(trajectory_.duration() * rate_hz_ + 1e-9)) + 1;
}

int64_t StereoSimulation::utime_of(int k) const {
  return start_utime_ + static_cast<int64_t>(std::llround(time_of(k) * 1e6));
}

StereoFrame StereoSimulation::frame(int k) const {
  if (k < 0 || k >= frame_count_)
    throw std::out_of_range("sim::StereoSimulation::frame: " + std::to_string(k) + " not in [0, " +
                            std::to_string(frame_count_) + ")");
  const double t = time_of(k);
  const geometry::SE3 T_world_body = trajectory_.pose(t);
  std::vector<geometry::SE3> blur;
  const int n = renderer_.rig().motion_blur_samples;
  for (int i = 0; i < n && n > 1; ++i)  // poses spread over [t - exposure, t]
    blur.push_back(trajectory_.pose(t - renderer_.rig().exposure_time * (n - 1 - i) / (n - 1)) * T_body_left_);
  StereoFrame f = renderer_.render(T_world_body * T_body_left_, utime_of(k), k, blur);
  f.T_world_body = T_world_body;
  return f;
}

bool StereoSimulation::next(StereoFrame& f) {
  if (next_ >= frame_count_) return false;
  f = frame(next_++);
  return true;
}

RigConfig landing_rig() {
  RigConfig rig;
  rig.pitch_deg = 90.0;
  return rig;
}

StereoSimulation landing_simulation(const World& world, const RigConfig& rig, double rate_hz, int64_t start_utime) {
  return StereoSimulation(world, rig, Trajectory::landing(world), rate_hz, start_utime);
}

}  // namespace aerie::sim
