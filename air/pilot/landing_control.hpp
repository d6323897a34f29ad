#pragma once
// The landing controllers of the flight manager: one controller per axis (forward, left,
// up, yaw) turning an error into a velocity or yaw-rate command. Two kinds, chosen in
// config/pilot.yaml:
//  * fuzzy: the PID-type FLC of thesis 5.1.3 on the project's FLC engine (common/flc),
//    fed with the error, its derivative and its integral, each scaled by the axis' Kp,
//    Kd, Ki, the output by Ku (the rule base is config/flc/landing.yaml);
//  * pid: a plain PID with the same inputs, for comparison.
// Both integrate with anti-windup (the integral is clamped) and run on message time.
#include <memory>
#include <string>

#include "common/flc/flc.hpp"

namespace aerie::pilot {

struct AxisGains {
  double kp = 0, ki = 0, kd = 0;  // PID gains; for the FLC the scaling factors of e, ie, de
  double ku = 1;                  // FLC output factor (unused by the PID)
  double integral_limit = 1;      // |integral of the error| <= this (anti-windup)
  double output_limit = 1;        // |command| <= this
  // Finite; kp, ki, kd >= 0; ku, integral_limit, output_limit > 0.
  bool valid() const;
};

class AxisController {
 public:
  virtual ~AxisController() = default;
  // Command for the error at time t_s (seconds, message time). The first call after
  // reset() has no derivative; a time that does not advance changes neither the
  // derivative nor the integral.
  double update(double t_s, double error);
  void reset() { started_ = false; integral_ = 0; derivative_ = 0; }
  double integral() const { return integral_; }

 protected:
  explicit AxisController(const AxisGains& g);
  virtual double law(double error, double derivative, double integral) const = 0;
  AxisGains g_;

 private:
  bool started_ = false;
  double t_ = 0, error_ = 0, integral_ = 0, derivative_ = 0;
};

class PidAxis final : public AxisController {
 public:
  explicit PidAxis(const AxisGains& g) : AxisController(g) {}

 private:
  double law(double e, double de, double ie) const override { return g_.kp * e + g_.kd * de + g_.ki * ie; }
};

class FuzzyAxis final : public AxisController {
 public:
  // `base` is the normalised controller (config/flc/landing.yaml); the axis sets its
  // scaling factors Kp, Kd, Ki, Ku from the gains.
  FuzzyAxis(const flc::FlcSpec& base, const AxisGains& g);

 private:
  static flc::FlcSpec scaled(flc::FlcSpec spec, const AxisGains& g);
  double law(double e, double de, double ie) const override { return flc_.evaluate(e, de, ie); }
  flc::Flc flc_;
};

// "fuzzy" or "pid"; throws std::invalid_argument for another kind or bad gains.
std::unique_ptr<AxisController> make_axis(const std::string& kind, const flc::FlcSpec& fuzzy_base, const AxisGains& g);

}  // namespace aerie::pilot
