#pragma once
// Steps a Trajectory at a fixed frame rate and renders each frame:
// frame k has t = k / rate_hz and utime = start_utime + round(t * 1e6).
#include <cstdint>

#include "common/sim/stereo_renderer.hpp"
#include "common/sim/trajectory.hpp"
#include "common/sim/world.hpp"

namespace aerie::sim {

class StereoSimulation {
 public:
  StereoSimulation(World world, RigConfig rig, Trajectory trajectory, double rate_hz = 20.0,
                   int64_t start_utime = 0);

  // Renders the next frame; false once the trajectory is exhausted.
  bool next(StereoFrame& frame);
  // Renders frame k (0 <= k < frame_count()) without changing the stepping position.
  StereoFrame frame(int k) const;
  void seek(int k) { next_ = k; }

  int frame_count() const { return frame_count_; }
  double rate_hz() const { return rate_hz_; }
  double time_of(int k) const { return k / rate_hz_; }
  int64_t utime_of(int k) const;

  const World& world() const { return renderer_.world(); }
  const Trajectory& trajectory() const { return trajectory_; }
  const StereoRenderer& renderer() const { return renderer_; }
  Intrinsics intrinsics() const { return renderer_.intrinsics(); }
  const geometry::SE3& T_body_left() const { return T_body_left_; }

 private:
  StereoRenderer renderer_;
  Trajectory trajectory_;
  geometry::SE3 T_body_left_;
  double rate_hz_;
  int64_t start_utime_;
  int frame_count_;
  int next_ = 0;
};

// The helipad-landing tracking sequence: the approach and descent of the demo flight seen
// by a downward-looking camera (rig pitch 90 deg by default); use frame.left and
// frame.target_box / target_corners / target_visible.
RigConfig landing_rig();
StereoSimulation landing_simulation(const World& world, const RigConfig& rig = landing_rig(),
                                    double rate_hz = 20.0, int64_t start_utime = 0);

}  // namespace aerie::sim
