#include "common/flc/flc.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <set>
#include <stdexcept>

namespace aerie::flc {
namespace {

[[noreturn]] void fail(const std::string& what) { throw std::invalid_argument("FLC: " + what); }

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}

void validate_variable(const Variable& v, const char* role, int min_sets) {
  const std::string where = std::string(role) + " '" + v.name + "'";
  if (v.name.empty()) fail(std::string(role) + " variable has no name");
  if (v.size() < min_sets) fail(where + " needs at least " + std::to_string(min_sets) + " sets, has " + std::to_string(v.size()));
  if (v.sets.size() > static_cast<size_t>(kMaxSets))
    fail(where + " has " + std::to_string(v.sets.size()) + " sets, more than " + std::to_string(kMaxSets));
  if (v.positions.size() != v.sets.size())
    fail(where + " has " + std::to_string(v.sets.size()) + " set names but " + std::to_string(v.positions.size()) + " positions");
  if (!std::isfinite(v.min) || !std::isfinite(v.max) || !(v.min < v.max))
    fail(where + " range [" + num(v.min) + ", " + num(v.max) + "] is not a finite interval with min < max");
  if (!std::isfinite(v.scaling) || v.scaling == 0.0) fail(where + " scaling factor " + num(v.scaling) + " must be finite and non-zero");
  std::set<std::string> names;
  for (int k = 0; k < v.size(); ++k) {
    if (v.sets[k].empty()) fail(where + " set " + std::to_string(k) + " has no name");
    if (!names.insert(v.sets[k]).second) fail(where + " has two sets named '" + v.sets[k] + "'");
    const double p = v.positions[k];
    if (!std::isfinite(p) || p < v.min || p > v.max)
      fail(where + " set '" + v.sets[k] + "' position " + num(p) + " is outside the range [" + num(v.min) + ", " + num(v.max) + "]");
    if (k > 0 && !(p > v.positions[k - 1]))
      fail(where + " set '" + v.sets[k] + "' position " + num(p) + " must be greater than '" + v.sets[k - 1] + "' (" +
           num(v.positions[k - 1]) + "): positions are strictly increasing");
  }
}

// The sets of a variable that are active for x (already saturated to the range):
// at most two, with their memberships (Ruspini partition: they sum to 1 inside
// [c_0, c_n-1]).
struct Active {
  int k[2];
  double mu[2];
  int n;
};

inline Active active_sets(const Variable& v, double x) {
  const auto& c = v.positions;
  const int n = v.size();
  if (x <= c[0]) return {{0, 0}, {membership(v, 0, x), 0.0}, 1};
  if (x >= c[n - 1]) return {{n - 1, 0}, {membership(v, n - 1, x), 0.0}, 1};
  int k = 0;
  while (x >= c[k + 1]) ++k;  // c[k] <= x < c[k+1]; n <= 9, a linear scan is fastest
  const double width = c[k + 1] - c[k];
  // The two formulas are exactly those of a triangle's falling and rising edges.
  return {{k, k + 1}, {(c[k + 1] - x) / width, (x - c[k]) / width}, 2};
}

}  // namespace

int Variable::index_of(std::string_view set) const {
  for (int k = 0; k < size(); ++k)
    if (sets[k] == set) return k;
  return -1;
}

double membership(const Variable& v, int k, double x) {
  const auto& c = v.positions;
  const int n = v.size();
  // Triangle (a, b, c) with the outer foot of the end sets mirrored.
  const double b = c[k];
  const double a = k > 0 ? c[k - 1] : c[0] - (c[1] - c[0]);
  const double e = k < n - 1 ? c[k + 1] : c[n - 1] + (c[n - 1] - c[n - 2]);
  if (x < a || x > e) return 0.0;
  if (x == b) return 1.0;
  return x < b ? (x - a) / (b - a) : (e - x) / (e - b);
}

int64_t rule_table_cells(const std::array<int, kInputs>& sets) {
  int64_t cells = 1;
  std::string product;
  bool overflow = false;
  for (int n : sets) {
    if (n < 0) fail("a variable has a negative number of sets");
    overflow |= __builtin_mul_overflow(cells, int64_t{n}, &cells);
    product += (product.empty() ? "" : " x ") + std::to_string(n);
  }
  if (overflow || cells > kMaxRuleCells)
    fail("the rule table of " + product + " input sets" + (overflow ? "" : " = " + std::to_string(cells) + " cells") +
         " is larger than " + std::to_string(kMaxRuleCells) + " cells");
  return cells;
}

void FlcSpec::validate() const {
  // The table's size first: what a hostile controller would make us allocate.
  rule_table_cells({static_cast<int>(std::min<size_t>(inputs[0].sets.size(), INT32_MAX)),
                    static_cast<int>(std::min<size_t>(inputs[1].sets.size(), INT32_MAX)),
                    static_cast<int>(std::min<size_t>(inputs[2].sets.size(), INT32_MAX))});
  std::set<std::string> names;
  for (const auto& v : inputs) {
    validate_variable(v, "input", 2);
    if (!names.insert(v.name).second) fail("two variables are named '" + v.name + "'");
  }
  validate_variable(output, "output", 1);
  if (!names.insert(output.name).second) fail("two variables are named '" + output.name + "'");
  if (rules.empty()) fail("the rule base is empty");
  std::set<std::array<int, kInputs>> seen;
  for (size_t r = 0; r < rules.size(); ++r) {
    const Rule& rule = rules[r];
    const std::string where = "rule " + std::to_string(r + 1);
    for (int i = 0; i < kInputs; ++i)
      if (rule.in[i] < 0 || rule.in[i] >= inputs[i].size())
        fail(where + " refers to set " + std::to_string(rule.in[i]) + " of input '" + inputs[i].name + "', which has " +
             std::to_string(inputs[i].size()) + " sets");
    if (rule.out < 0 || rule.out >= output.size())
      fail(where + " refers to output set " + std::to_string(rule.out) + " of '" + output.name + "', which has " +
           std::to_string(output.size()) + " sets");
    if (!std::isfinite(rule.weight) || rule.weight < 0.0 || rule.weight > 1.0)
      fail(where + " weight " + num(rule.weight) + " is outside [0, 1]");
    if (!seen.insert(rule.in).second)
      fail(where + " repeats the antecedent (" + inputs[0].sets[rule.in[0]] + ", " + inputs[1].sets[rule.in[1]] + ", " +
           inputs[2].sets[rule.in[2]] + ") of an earlier rule");
  }
}

const Variable& FlcSpec::variable(std::string_view name) const {
  for (const auto& v : inputs)
    if (v.name == name) return v;
  if (output.name == name) return output;
  fail("no variable named '" + std::string(name) + "'");
}

Variable& FlcSpec::variable(std::string_view name) {
  return const_cast<Variable&>(static_cast<const FlcSpec*>(this)->variable(name));
}

namespace {

constexpr std::array<std::string_view, 4> kScalingNames = {"Kp", "Kd", "Ki", "Ku"};

// Resolves a parameter name to (variable, set index or -1 for the scaling factor).
std::pair<Variable*, int> resolve(FlcSpec& spec, std::string_view name) {
  for (int i = 0; i < 4; ++i)
    if (name == kScalingNames[i]) return {i < kInputs ? &spec.inputs[i] : &spec.output, -1};
  const auto dot = name.find('.');
  if (dot == std::string_view::npos)
    fail("parameter '" + std::string(name) + "' is neither Kp/Kd/Ki/Ku nor <variable>.<set|scaling>");
  Variable& v = spec.variable(name.substr(0, dot));
  const auto set = name.substr(dot + 1);
  if (set == "scaling") return {&v, -1};
  const int k = v.index_of(set);
  if (k < 0) fail("variable '" + v.name + "' has no set '" + std::string(set) + "' (parameter '" + std::string(name) + "')");
  return {&v, k};
}

}  // namespace

std::vector<std::string> FlcSpec::parameter_names() const {
  std::vector<std::string> names(kScalingNames.begin(), kScalingNames.end());
  auto add = [&](const Variable& v) {
    for (int k = 0; k < v.size() / 2; ++k) names.push_back(v.name + "." + v.sets[k]);
  };
  for (const auto& v : inputs) add(v);
  add(output);
  return names;
}

double FlcSpec::parameter(std::string_view name) const {
  auto [v, k] = resolve(const_cast<FlcSpec&>(*this), name);
  return k < 0 ? v->scaling : v->positions[k];
}

void FlcSpec::set_parameter(std::string_view name, double value) {
  auto [v, k] = resolve(*this, name);
  if (k < 0) {
    v->scaling = value;
    return;
  }
  const int mirror = v->size() - 1 - k;
  if (mirror == k) fail("set '" + v->sets[k] + "' of '" + v->name + "' is the middle set, fixed at 0 by symmetry");
  v->positions[k] = value;
  v->positions[mirror] = -value;
}

Flc::Flc(FlcSpec spec) : spec_(std::move(spec)) {
  spec_.validate();
  const auto& in = spec_.inputs;
  const auto cells = static_cast<size_t>(rule_table_cells({in[0].size(), in[1].size(), in[2].size()}));
  stride_ = {in[1].size() * in[2].size(), in[2].size(), 1};  // < kMaxRuleCells: no overflow
  rule_out_.assign(cells, -1);
  rule_weight_.assign(cells, 0.0);
  for (const Rule& r : spec_.rules) {
    const size_t cell = static_cast<size_t>(r.in[0] * stride_[0] + r.in[1] * stride_[1] + r.in[2]);
    rule_out_[cell] = r.out;
    rule_weight_[cell] = r.weight;
  }
}

Evaluation Flc::evaluate_detail(double error, double derivative, double integral) const {
  Evaluation ev;
  const double x[kInputs] = {error, derivative, integral};
  Active act[kInputs];
  for (int i = 0; i < kInputs; ++i) {
    const Variable& v = spec_.inputs[i];
    const double s = v.scaling * x[i];
    if (std::isnan(s)) {
      ev.output = s;
      return ev;
    }
    ev.scaled_inputs[i] = std::clamp(s, v.min, v.max);
    act[i] = active_sets(v, ev.scaled_inputs[i]);
  }
  // eq. 5.1 over the rules whose antecedent sets are all active (product t-norm).
  const auto& peaks = spec_.output.positions;
  double num = 0.0, den = 0.0;
  for (int a = 0; a < act[0].n; ++a)
    for (int b = 0; b < act[1].n; ++b)
      for (int c = 0; c < act[2].n; ++c) {
        const size_t cell = static_cast<size_t>(act[0].k[a] * stride_[0] + act[1].k[b] * stride_[1] + act[2].k[c]);
        const int out = rule_out_[cell];
        if (out < 0) continue;
        const double degree = rule_weight_[cell] * act[0].mu[a] * act[1].mu[b] * act[2].mu[c];
        if (degree <= 0.0) continue;
        num += degree * peaks[out];
        den += degree;
        ++ev.fired_rules;
      }
  ev.output = den > 0.0 ? spec_.output.scaling * (num / den) : 0.0;
  return ev;
}

}  // namespace aerie::flc
