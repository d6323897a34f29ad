#pragma once
// Smooth, time-parametrised vehicle trajectories through a World. pose(t) is the body pose
// T_world_body (body: x forward, y left, z up); the body yaws to face its direction of
// travel. Speed ramps smoothly from and to rest, so position, velocity and yaw are continuous.
#include <memory>
#include <string>
#include <vector>

#include "common/geometry/se3.hpp"
#include "common/sim/world.hpp"

namespace aerie::sim {

class Trajectory {
 public:
  struct Phase {
    std::string name;
    double t_begin, t_end;
  };
  // Any piece of motion: a duration, a pose function on [0, duration] and its path length.
  struct Segment {
    virtual ~Segment() = default;
    virtual double duration() const = 0;
    virtual double length() const = 0;
    virtual geometry::SE3 pose(double t) const = 0;
  };

  // Take-off from the route's home point, one survey loop around the room, approach to
  // above the helipad and descent onto it (phases "takeoff", "survey", "turn", "approach",
  // "descent"). speed in m/s.
  static Trajectory demo_flight(const World& world, double speed = 0.8);
  // `loops` survey loops from rest at the cruise altitude back to exactly the start pose,
  // with a gentle altitude wave, for visual odometry drift tests.
  static Trajectory survey_loops(const World& world, int loops, double speed = 1.0);
  // The helipad-landing piece of demo_flight (approach + descent) on its own.
  static Trajectory landing(const World& world, double speed = 0.8);

  geometry::SE3 pose(double t) const;   // clamped to [0, duration]
  double duration() const { return duration_; }
  double length() const { return length_; }
  const std::vector<Phase>& phases() const { return phases_; }

  // Building blocks.
  void append(std::shared_ptr<const Segment> segment, const std::string& phase);
  Trajectory slice(double t_begin, double t_end) const;

 private:
  std::vector<std::shared_ptr<const Segment>> segments_;
  std::vector<double> starts_;  // start time of each segment
  std::vector<Phase> phases_;
  double duration_ = 0.0;
  double length_ = 0.0;
};

}  // namespace aerie::sim
