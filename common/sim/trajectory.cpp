#include "common/sim/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace aerie::sim {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRampTime = 1.5;       // s to reach cruise speed from rest
constexpr double kYawRate = 0.8;        // rad/s for turns on the spot
constexpr double kGroundHeight = 0.1;   // body origin above the floor when landed (m)

geometry::SE3 pose_from(const Eigen::Vector3d& p, double yaw) {
  return {Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())), p};
}

// Rest-to-rest travel of `length` at cruise `speed`: cosine-shaped acceleration over
// kRampTime, so velocity is continuous and zero at both ends; s(duration) == length.
class SpeedProfile {
 public:
  SpeedProfile(double length, double speed) : L_(length), v_(speed), Ta_(kRampTime) {
    if (!(speed > 0)) throw std::invalid_argument("sim::Trajectory: speed must be > 0");
    if (L_ < v_ * Ta_) v_ = L_ / Ta_;  // short move: never reaches the cruise speed
    T_ = L_ > 0 ? L_ / v_ + Ta_ : 0.0;
  }
  double duration() const { return T_; }
  double s(double t) const {
    if (T_ <= 0) return 0.0;
    if (t <= 0) return 0.0;
    if (t >= T_) return L_;
    if (t < Ta_) return ramp(t);
    if (t > T_ - Ta_) return L_ - ramp(T_ - t);
    return 0.5 * v_ * Ta_ + v_ * (t - Ta_);
  }

 private:
  double ramp(double t) const { return 0.5 * v_ * (t - Ta_ / kPi * std::sin(kPi * t / Ta_)); }
  double L_, v_, Ta_, T_ = 0;
};

// Straight flight from a to b, yaw interpolated along the way.
class Line : public Trajectory::Segment {
 public:
  Line(Eigen::Vector3d a, Eigen::Vector3d b, double yaw_a, double yaw_b, double speed)
      : a_(a), b_(b), yaw_a_(yaw_a), yaw_b_(yaw_b), profile_((b - a).norm(), speed) {}
  double duration() const override { return profile_.duration(); }
  double length() const override { return (b_ - a_).norm(); }
  geometry::SE3 pose(double t) const override {
    const double L = length();
    const double f = L > 0 ? profile_.s(t) / L : 1.0;
    if (f >= 1.0) return pose_from(b_, yaw_b_);
    return pose_from(a_ + f * (b_ - a_), yaw_a_ + f * (yaw_b_ - yaw_a_));
  }

 private:
  Eigen::Vector3d a_, b_;
  double yaw_a_, yaw_b_;
  SpeedProfile profile_;
};

// Yaw on the spot.
class Turn : public Trajectory::Segment {
 public:
  Turn(Eigen::Vector3d p, double yaw_a, double yaw_b) : p_(p), a_(yaw_a), b_(yaw_b) {
    T_ = std::max(0.5, 1.5 * std::abs(b_ - a_) / kYawRate);
  }
  double duration() const override { return T_; }
  double length() const override { return 0.0; }
  geometry::SE3 pose(double t) const override {
    const double f = std::clamp(t / T_, 0.0, 1.0);
    const double smooth = 0.5 - 0.5 * std::cos(kPi * f);  // zero yaw rate at both ends
    return pose_from(p_, f >= 1.0 ? b_ : a_ + smooth * (b_ - a_));
  }

 private:
  Eigen::Vector3d p_;
  double a_, b_, T_;
};

// Counter-clockwise loops (seen from above) of the route's rounded rectangle, starting and
// ending at rest at the route's home point at cruise altitude, facing along the route.
// Altitude follows z = altitude + wave * sin(2 pi * 2 s / perimeter) (zero at the start).
class Loops : public Trajectory::Segment {
 public:
  Loops(const World::Route& r, int loops, double speed, double wave)
      : r_(r), wave_(wave), profile_(0, 1) {
    if (loops < 1) throw std::invalid_argument("sim::Trajectory: loops must be >= 1");
    const double w = r.x_max - r.x_min - 2 * r.corner_radius, h = r.y_max - r.y_min - 2 * r.corner_radius;
    const double y_mid = r.home.y();
    // Pieces from home: west edge south half, SW arc, south edge, SE arc, east edge, NE arc,
    // north edge, NW arc, west edge north half.
    pieces_ = {{y_mid - (r.y_min + r.corner_radius), false}, {0.5 * kPi * r.corner_radius, true},
               {w, false}, {0.5 * kPi * r.corner_radius, true},
               {h, false}, {0.5 * kPi * r.corner_radius, true},
               {w, false}, {0.5 * kPi * r.corner_radius, true},
               {r.y_max - r.corner_radius - y_mid, false}};
    perimeter_ = 0;
    for (const auto& p : pieces_) perimeter_ += p.length;
    profile_ = SpeedProfile(loops * perimeter_, speed);
    // 3D length including the altitude wave (numerically).
    const int n = 2000;
    double len = 0;
    for (int i = 0; i < n; ++i) {
      const double dz = wave_ * std::sin(4 * kPi * (i + 1.0) / n) - wave_ * std::sin(4 * kPi * i / n);
      len += std::hypot(perimeter_ / n, dz);
    }
    length_ = loops * len;
  }
  double duration() const override { return profile_.duration(); }
  double length() const override { return length_; }
  geometry::SE3 pose(double t) const override {
    double s = profile_.s(t);
    s -= perimeter_ * std::floor(s / perimeter_);
    if (perimeter_ - s < 1e-9) s = 0.0;  // back at home: exactly the start pose
    const double z = r_.altitude + wave_ * std::sin(4 * kPi * s / perimeter_);
    // Walk the pieces; heading starts at -pi/2 (south) and turns left at each arc.
    double x = r_.x_min, y = r_.home.y(), heading = -0.5 * kPi;
    for (const auto& p : pieces_) {
      const double l = std::min(s, p.length);
      if (!p.arc) {
        x += l * std::cos(heading);
        y += l * std::sin(heading);
      } else {
        const double a = l / r_.corner_radius;
        // centre of the arc is to the left of the heading
        const double cx = x - r_.corner_radius * std::sin(heading), cy = y + r_.corner_radius * std::cos(heading);
        heading += a;
        x = cx + r_.corner_radius * std::sin(heading);
        y = cy - r_.corner_radius * std::cos(heading);
      }
      s -= l;
      if (s <= 0) break;
    }
    return pose_from({x, y, z}, heading);
  }

 private:
  struct Piece {
    double length;
    bool arc;
  };
  World::Route r_;
  double wave_;
  std::vector<Piece> pieces_;
  double perimeter_ = 0, length_ = 0;
  SpeedProfile profile_;
};

// A time window of another trajectory, re-based to start at 0.
class Slice : public Trajectory::Segment {
 public:
  Slice(Trajectory parent, double t0, double t1) : parent_(std::move(parent)), t0_(t0), t1_(t1) {
    const int n = std::max(2, static_cast<int>((t1 - t0) * 100));
    for (int i = 0; i < n; ++i)
      length_ += (parent_.pose(t0 + (t1 - t0) * (i + 1) / n).translation() -
                  parent_.pose(t0 + (t1 - t0) * i / n).translation()).norm();
  }
  double duration() const override { return t1_ - t0_; }
  double length() const override { return length_; }
  geometry::SE3 pose(double t) const override { return parent_.pose(t0_ + std::clamp(t, 0.0, t1_ - t0_)); }

 private:
  Trajectory parent_;
  double t0_, t1_, length_ = 0;
};

}  // namespace

void Trajectory::append(std::shared_ptr<const Segment> segment, const std::string& phase) {
  starts_.push_back(duration_);
  phases_.push_back({phase, duration_, duration_ + segment->duration()});
  duration_ += segment->duration();
  length_ += segment->length();
  segments_.push_back(std::move(segment));
}

geometry::SE3 Trajectory::pose(double t) const {
  if (segments_.empty()) throw std::logic_error("sim::Trajectory::pose on an empty trajectory");
  // Last segment starting at or before t.
  const auto it = std::upper_bound(starts_.begin(), starts_.end(), t);
  const size_t i = it == starts_.begin() ? 0 : static_cast<size_t>(it - starts_.begin()) - 1;
  return segments_[i]->pose(t - starts_[i]);
}

Trajectory Trajectory::slice(double t_begin, double t_end) const {
  if (!(t_begin >= 0 && t_end <= duration_ + 1e-9 && t_begin < t_end))
    throw std::invalid_argument("sim::Trajectory::slice: need 0 <= t_begin < t_end <= duration (" +
                                std::to_string(duration_) + " s)");
  Trajectory out;
  out.append(std::make_shared<Slice>(*this, t_begin, t_end), "slice");
  // Keep the parent's phase names inside the window.
  out.phases_.clear();
  for (const auto& p : phases_)
    if (p.t_end > t_begin && p.t_begin < t_end)
      out.phases_.push_back({p.name, std::max(p.t_begin, t_begin) - t_begin, std::min(p.t_end, t_end) - t_begin});
  return out;
}

Trajectory Trajectory::demo_flight(const World& world, double speed) {
  const auto& r = world.route();
  const auto& pad = world.helipad();
  const Eigen::Vector3d ground(r.home.x(), r.home.y(), kGroundHeight);
  const Eigen::Vector3d home(r.home.x(), r.home.y(), r.altitude);
  const Eigen::Vector3d above_pad(pad.center.x(), pad.center.y(), r.altitude);
  const Eigen::Vector3d on_pad(pad.center.x(), pad.center.y(), pad.center.z() + kGroundHeight);  // the pad may be on an object
  const double yaw_loop = -0.5 * kPi;
  const double yaw_pad = std::atan2(above_pad.y() - home.y(), above_pad.x() - home.x());
  Trajectory t;
  t.append(std::make_shared<Line>(ground, home, yaw_loop, yaw_loop, 0.5 * speed), "takeoff");
  t.append(std::make_shared<Loops>(r, 1, speed, 0.0), "survey");
  t.append(std::make_shared<Turn>(home, yaw_loop, yaw_pad), "turn");
  t.append(std::make_shared<Line>(home, above_pad, yaw_pad, yaw_pad, speed), "approach");
  // Descent with a slow 45 deg yaw, as a real landing rarely keeps its heading.
  t.append(std::make_shared<Line>(above_pad, on_pad, yaw_pad, yaw_pad + 0.25 * kPi, 0.4 * speed), "descent");
  return t;
}

Trajectory Trajectory::survey_loops(const World& world, int loops, double speed) {
  Trajectory t;
  t.append(std::make_shared<Loops>(world.route(), loops, speed, 0.3), "survey");
  return t;
}

Trajectory Trajectory::landing(const World& world, double speed) {
  const Trajectory demo = demo_flight(world, speed);
  double t0 = 0, t1 = demo.duration();
  for (const auto& p : demo.phases()) {
    if (p.name == "approach") t0 = p.t_begin;
    if (p.name == "descent") t1 = p.t_end;
  }
  return demo.slice(t0, t1);
}

}  // namespace aerie::sim
