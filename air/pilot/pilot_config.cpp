#include "air/pilot/pilot_config.hpp"

#include "common/flc/flc_io.hpp"
#include "common/util/section_reader.hpp"

namespace aerie::pilot {

const char* landing_flc_yaml();  // landing_yaml.cpp (generated)

flc::FlcSpec landing_flc() { return flc::parse_yaml(landing_flc_yaml(), "config/flc/landing.yaml (compiled in)"); }

namespace {

AxisGains load_gains(const util::Config& c) {
  AxisGains g;
  util::SectionReader<AxisGains>(c, g)("kp", &AxisGains::kp)("ki", &AxisGains::ki)("kd", &AxisGains::kd)(
      "ku", &AxisGains::ku)("integral_limit", &AxisGains::integral_limit)("output_limit", &AxisGains::output_limit)
      .finish();
  return g;
}

}  // namespace

PilotConfig load_pilot_config(const util::Config& cfg) {
  PilotConfig p;
  using P = PilotConfig;
  util::SectionReader<P>(cfg, p)("controller", &P::controller)
      .known("fuzzy_rules")("camera_pitch_deg", &P::camera_pitch_deg)("wait_for_start", &P::wait_for_start)(
          "takeoff_time_s", &P::takeoff_time_s)("takeoff_min_s", &P::takeoff_min_s)("acquire_timeout_s", &P::acquire_timeout_s)(
          "control_period_s", &P::control_period_s)
      .known("survey")
      .known("approach")
      .known("descent")
      .known("hold")
      .known("abort")
      .known("gains")
      .known("message_time")
      .known("feedforward")
      .finish();
  p.message_time = util::MessageClockConfig::from_config(cfg.section("message_time"), p.message_time);
  const std::string rules = cfg.get<std::string>("fuzzy_rules", "");
  p.fuzzy_base = rules.empty() ? landing_flc() : flc::load_controller(rules);

  const util::Config survey = cfg.section("survey");
  util::SectionReader<P>(survey, p)("speed_m_s", &P::survey_speed_m_s).known("legs").finish();
  if (survey.has("legs")) {
    p.survey_legs.clear();
    for (const auto& leg : survey.get<std::vector<std::vector<double>>>("legs", {})) {
      if (leg.size() != 2) throw std::runtime_error(survey.origin() + ": each of legs must be [forward_m, left_m]");
      p.survey_legs.emplace_back(leg[0], leg[1]);
    }
  }
  util::SectionReader<P>(cfg.section("approach"), p)("height_m", &P::approach_height_m)(
      "tolerance_m", &P::approach_tolerance_m)("yaw_tolerance_deg", &P::yaw_tolerance_deg)(
      "height_tolerance_m", &P::height_tolerance_m)("settle_frames", &P::settle_frames)
      .finish();
  util::SectionReader<P>(cfg.section("descent"), p)("speed_m_s", &P::descent_speed_m_s)("gate_m", &P::descent_gate_m)(
      "touchdown_height_m", &P::touchdown_height_m)("handover_tolerance_m", &P::handover_tolerance_m)(
      "handover_frames", &P::handover_frames)("touchdown_time_s", &P::touchdown_time_s)
      .finish();
  util::SectionReader<P>(cfg.section("hold"), p)("stale_timeout_s", &P::stale_timeout_s)(
      "max_input_age_s", &P::max_input_age_s)("loss_frames", &P::loss_frames)("timeout_s", &P::hold_timeout_s)(
      "climb_m_s", &P::hold_climb_m_s)("climb_max_s", &P::hold_climb_max_s)
      .finish();
  using F = PilotConfig::FeedForward;
  const util::Config ff = cfg.section("feedforward");
  util::SectionReader<F>(ff, p.feedforward)("enabled", &F::enabled)("min_speed_m_s", &F::min_speed_m_s)(
      "max_speed_m_s", &F::max_speed_m_s)("touchdown_speed_m_s", &F::touchdown_speed_m_s)(
      "touchdown_margin_s", &F::touchdown_margin_s)
      .known("alpha")
      .known("vehicle_time_constant_s")
      .known("max_gap_s")
      .known("min_updates")
      .finish();
  using E = PadVelocityConfig;
  util::SectionReader<E>(ff, p.feedforward.estimator)("alpha", &E::alpha)(
      "vehicle_time_constant_s", &E::vehicle_time_constant_s)("max_gap_s", &E::max_gap_s)("min_updates", &E::min_updates);
  util::SectionReader<P>(cfg.section("abort"), p)("climb_m_s", &P::abort_climb_m_s)("climb_s", &P::abort_climb_s)
      .finish();

  // Gains of the chosen controller kind, per axis.
  const util::Config gains = cfg.section("gains");
  struct Kinds {};
  Kinds k;
  util::SectionReader<Kinds>(gains, k).known("fuzzy").known("pid").finish();
  const util::Config axes = gains.section(p.controller);
  util::SectionReader<Kinds>(axes, k).known("forward").known("left").known("up").known("yaw").finish();
  p.forward = load_gains(axes.section("forward"));
  p.left = load_gains(axes.section("left"));
  p.up = load_gains(axes.section("up"));
  p.yaw = load_gains(axes.section("yaw"));
  p.validate();
  return p;
}

}  // namespace aerie::pilot
