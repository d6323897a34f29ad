#include "ground/ceopt/flc_problem.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>

namespace aerie::ceopt {

double run_cost(const sim::AvoidanceResult& r, const TrainingOptions& opt) {
  double c = r.itse;
  if (r.entered_dangerous) c += opt.penalty_dangerous * (1.0 + std::max(0.0, r.max_y_m - opt.scenario.scene.dangerous_from()));
  if (!r.completed || !r.activated) c += opt.penalty_incomplete;
  return c;
}

sim::AvoidanceResult fly(const flc::Flc& flc, const sim::AvoidanceConfig& scenario, double speed, uint64_t seed,
                         const flc::CommandLimits& limits, bool record) {
  sim::AvoidanceConfig cfg = scenario;
  cfg.speed_m_s = speed;
  cfg.record = record;
  flc::HeadingLoop loop(flc, limits);
  return sim::run_avoidance(
      cfg, [&loop](double t, double heading, double ref) { return loop.update(t, heading, ref); }, seed);
}

FlcTuningProblem::FlcTuningProblem(flc::FlcSpec base, std::vector<std::string> names, TrainingOptions options)
    : base_(std::move(base)), names_(std::move(names)), opt_(std::move(options)) {
  base_.validate();
  if (names_.empty()) throw std::invalid_argument("FLC tuning: no parameters to optimise");
  for (const auto& n : names_) (void)base_.parameter(n);  // throws on an unknown name
  if (opt_.speeds.empty() || opt_.runs_per_speed < 1) throw std::invalid_argument("FLC tuning: needs speeds and runs_per_speed >= 1");
}

std::vector<double> FlcTuningProblem::initial() const {
  std::vector<double> x;
  for (const auto& n : names_) x.push_back(base_.parameter(n));
  return x;
}

void FlcTuningProblem::repair(std::vector<double>& x) const {
  // Free positions per variable: variable name -> (set index, index into x).
  std::map<std::string, std::vector<std::pair<int, size_t>>> free;
  for (size_t j = 0; j < names_.size(); ++j) {
    const auto dot = names_[j].find('.');
    const std::string set = dot == std::string::npos ? "" : names_[j].substr(dot + 1);
    if (dot == std::string::npos || set == "scaling") {
      if (std::abs(x[j]) < 1e-9) x[j] = std::copysign(1e-9, x[j]);
      continue;
    }
    const flc::Variable& v = base_.variable(names_[j].substr(0, dot));
    int k = v.index_of(set);
    if (k >= v.size() / 2) {  // a right-side name: work on its left mirror
      k = v.size() - 1 - k;
      x[j] = -x[j];
    }
    free[v.name].emplace_back(k, j);
  }
  for (auto& entry : free) {  // not a structured binding: the lambda below captures `sets` (clang 14)
    const flc::Variable& v = base_.variable(entry.first);
    auto& sets = entry.second;
    const double gap = kMinGapFraction * (v.max - v.min);
    std::vector<double> pos(v.positions.begin(), v.positions.begin() + v.size() / 2);  // left side
    std::vector<double> values;
    for (const auto& [k, j] : sets) values.push_back(x[j]);
    std::sort(values.begin(), values.end());
    std::sort(sets.begin(), sets.end());
    for (size_t s = 0; s < sets.size(); ++s) pos[static_cast<size_t>(sets[s].first)] = values[s];
    // Left side of a symmetric variable: min <= p0 < p1 < ... < (0 or the mirror).
    const double top = v.size() % 2 ? -gap : -gap / 2;
    const auto is_free = [&](size_t k) {
      return std::any_of(sets.begin(), sets.end(), [&](const auto& s) { return static_cast<size_t>(s.first) == k; });
    };
    for (size_t k = 0; k < pos.size(); ++k)
      if (is_free(k)) pos[k] = std::max(pos[k], k ? pos[k - 1] + gap : v.min);
    for (size_t k = pos.size(); k-- > 0;)
      if (is_free(k)) pos[k] = std::min(pos[k], k + 1 < pos.size() ? pos[k + 1] - gap : top);
    for (const auto& [k, j] : sets) x[j] = pos[static_cast<size_t>(k)];
  }
}

flc::FlcSpec FlcTuningProblem::controller(const std::vector<double>& x) const {
  if (x.size() != names_.size()) throw std::invalid_argument("FLC tuning: candidate has the wrong size");
  flc::FlcSpec s = base_;
  for (size_t j = 0; j < names_.size(); ++j) s.set_parameter(names_[j], x[j]);
  s.validate();
  return s;
}

double FlcTuningProblem::cost(const std::vector<double>& x) const {
  std::optional<flc::Flc> flc;
  try {
    flc.emplace(controller(x));
  } catch (const std::invalid_argument&) {
    return std::numeric_limits<double>::infinity();
  }
  return controller_cost(*flc, opt_);
}

double controller_cost(const flc::Flc& flc, const TrainingOptions& opt) {
  double sum = 0.0;
  int k = 0;
  for (double speed : opt.speeds)
    for (int r = 0; r < opt.runs_per_speed; ++r, ++k)
      sum += run_cost(fly(flc, opt.scenario, speed, opt.seed + static_cast<uint64_t>(k), opt.limits), opt);
  return sum / k;
}

}  // namespace aerie::ceopt
