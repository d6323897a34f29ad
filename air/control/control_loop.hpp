#pragma once
// The onboard heading controller without LCM (thesis 5.1.2-5.1.3): heading
// measurements in, FLC yaw-rate commands out, with command limits, a controller that
// can be replaced at run time after validation, and a hover fallback when the input
// goes stale.
#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <string>

#include "common/flc/flc.hpp"
#include "common/flc/heading_loop.hpp"

namespace aerie::control {

enum class Mode : int8_t { kHover = 0, kActive = 1, kFallbackHover = 2 };  // = control_cmd_t constants

struct ControlConfig {
  double reference_deg = 90.0;        // heading reference (thesis: 90 deg, parallel to the wall)
  bool reference_relative = true;     // reference is relative to the first heading received
  double forward_speed_m_s = 0.0;     // forward speed commanded while active
  double stale_timeout_s = 0.5;       // no heading for longer than this -> fallback hover
  // A heading older than this when it arrives (its capture time against the node's clock)
  // -> fallback hover; 0 = off. The delayed-link study (docs/results/linkstudy.md §4): the
  // turn settles on headings 150 ms old, not on 200 ms; a gap-only timeout never fires
  // behind a steady delay.
  double max_input_age_s = 0.15;
  // > 0: the avoidance of thesis 5.1.2 — fly straight ahead (zero yaw rate) until the pose has
  // moved this far from the first one (the normal flight area), then turn to the reference.
  // 0: the reference applies from the first heading.
  double activation_distance_m = 0.0;
  flc::CommandLimits limits;
  void validate() const;              // throws std::invalid_argument
};

// Where the manoeuvre was anchored: the first heading's pose in the estimator's frame and the
// reference it set (thesis 5.1.2: straight for activation_distance_m from start, then turn
// to reference_deg). Kept so that a restarted aerie-control can resume it (control_node.hpp).
struct Anchor {
  int64_t utime = 0;                  // of the pose that anchored it
  Eigen::Vector3d start = Eigen::Vector3d::Zero();
  double reference_deg = 0.0;
};

struct Command {
  Mode mode = Mode::kHover;
  double yaw_rate_deg_s = 0.0;
  double forward_speed_m_s = 0.0;
  double heading_deg = 0.0, reference_deg = 0.0, error_deg = 0.0;
  int64_t source_utime = 0;           // utime of the heading the command derives from
  std::string controller_id;
};

class ControlLoop {
 public:
  ControlLoop(flc::FlcSpec controller, ControlConfig config);

  // A heading measurement: utime of its source frame (message time, drives the FLC's
  // derivative and integral) and the node-clock time it was received (for staleness: the wall
  // clock live, the simulation's in lock-step, the input clock in a replay).
  // Returns false (and ignores it) if it is not newer than the last one or not finite.
  // `position` (any fixed frame, m) is the pose's; activation_distance_m measures it.
  // `age_s` is the heading's age on arrival (util::message_age_s; nullopt when the clocks
  // differ): older than max_input_age_s, the manoeuvre's progress follows it but the FLC
  // never sees it and the commands are FALLBACK_HOVER until a fresh heading comes, as if it
  // had not come (after no fresh heading for stale_timeout_s, the FLC starts afresh).
  bool on_heading(int64_t utime, double heading_deg, int64_t receive_wall_us,
                  const std::optional<Eigen::Vector3d>& position = std::nullopt,
                  std::optional<double> age_s = std::nullopt);

  // The manoeuvre's anchor, once the first heading (with a position) has set it.
  std::optional<Anchor> anchor() const;
  // Takes up a manoeuvre anchored before (a restart): the next headings are flown against
  // its start and reference instead of anchoring anew.
  void resume(const Anchor& anchor);

  // The heading source re-synchronised to a new time base (restart, outage; util::MessageClock):
  // the next heading is taken whatever its utime, and the derivative and integral start afresh.
  void resync();

  // Replaces the controller if it is valid; otherwise keeps the current one and
  // returns the reason it was refused.
  std::optional<std::string> set_controller(const flc::FlcSpec& spec);

  // The command to send at wall-clock time now_us.
  Command command(int64_t now_us) const;

  const flc::FlcSpec& controller() const { return loop_.flc().spec(); }
  const ControlConfig& config() const { return cfg_; }
  bool stale(int64_t now_us) const;
  bool aged() const { return aged_; }  // the newest heading was older than max_input_age_s
  bool turning() const { return turning_; }  // past the activation distance (or none configured)

 private:
  ControlConfig cfg_;
  flc::HeadingLoop loop_;
  bool have_input_ = false, have_reference_ = false, have_time_ = false;
  double reference_ = 0.0;
  bool turning_ = false, aged_ = false;
  std::optional<Eigen::Vector3d> start_;  // the first pose's position
  int64_t anchor_utime_ = 0;
  int64_t last_utime_ = 0, last_receive_ = 0;
  Command active_;
};

}  // namespace aerie::control
