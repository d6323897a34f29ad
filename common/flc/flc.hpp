#pragma once
// The PID-like fuzzy logic controller of thesis 5.1.3: three inputs (heading error,
// its derivative, its integral), one output (yaw-rate command), a scaling factor per
// variable (Kp, Kd, Ki and the output's), triangular membership functions, a rule
// base of up to 5x5x5 rules (Tables 5.1-5.5), product t-norm and the weighted height
// defuzzification of eq. 5.1.
//
// Membership functions are parametrised by the positions (peaks) of their sets: set k
// of a variable is the triangle (c[k-1], c[k], c[k+1]) — a Ruspini partition, so moving
// one set moves the feet of its neighbours, as the thesis' "position" optimisation
// does. The outermost sets mirror their inner foot (c[0] - (c[1] - c[0]), ...) and the
// scaled inputs are saturated to the variable's range. Output sets enter eq. 5.1
// through their peaks only (the height method).
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace aerie::flc {

inline constexpr int kInputs = 3;  // error, derivative, integral
// Bounds of a controller from outside (FLC_PARAMS, FLL and YAML files), checked by
// FlcSpec::validate() before anything is allocated: the thesis uses 5 x 5 x 5 rules.
inline constexpr int kMaxSets = 64;                        // sets of one variable
inline constexpr int64_t kMaxRuleCells = int64_t{1} << 18;  // input sets multiplied (the rule table)
// Cells of the dense rule table (input set counts multiplied, checked 64-bit arithmetic);
// throws std::invalid_argument naming the product when it exceeds kMaxRuleCells.
int64_t rule_table_cells(const std::array<int, kInputs>& sets);

// One linguistic variable: ordered sets with strictly increasing positions.
struct Variable {
  std::string name;
  std::string unit;
  double min = 0.0, max = 0.0;       // range (after scaling) the input saturates to
  double scaling = 1.0;              // Kp / Kd / Ki for inputs, output factor for the output
  std::vector<std::string> sets;     // set (term) names, left to right
  std::vector<double> positions;     // peak of each set, strictly increasing

  int size() const { return static_cast<int>(sets.size()); }
  int index_of(std::string_view set) const;  // -1 when absent
};

// One rule: "if error is in[0] and derivative is in[1] and integral is in[2] then
// output is out with weight".
struct Rule {
  std::array<int, kInputs> in{};
  int out = 0;
  double weight = 1.0;  // rule weight w of eq. 5.1, in [0, 1]
};

// The controller as plain data: what YAML and FLL files hold and what CE changes.
struct FlcSpec {
  std::string id;
  std::array<Variable, kInputs> inputs;
  Variable output;
  std::vector<Rule> rules;

  // Throws std::invalid_argument naming the variable/set/rule and what is expected.
  void validate() const;

  // Named parameters (thesis 5.1.5): "<input>.scaling" / "<output>.scaling" (Kp, Kd,
  // Ki and the output factor; "Kp", "Kd", "Ki", "Ku" are accepted too) and
  // "<variable>.<set>" for the position of a set. Positions are symmetric: setting a
  // set on one side sets its mirror (-value) on the other, so CE optimises one side.
  std::vector<std::string> parameter_names() const;  // scaling factors, then left-side positions
  double parameter(std::string_view name) const;     // throws std::invalid_argument
  void set_parameter(std::string_view name, double value);

  const Variable& variable(std::string_view name) const;  // inputs then output; throws
  Variable& variable(std::string_view name);
};

// Breakdown of one evaluation (for plots, the node's status and tests).
struct Evaluation {
  double output = 0.0;                           // scaled output (deg/s)
  std::array<double, kInputs> scaled_inputs{};   // after scaling and saturation
  int fired_rules = 0;
};

// The compiled controller: a dense rule lookup so that evaluate() visits only the (at
// most 2^3) rules whose sets are active for the input.
class Flc {
 public:
  explicit Flc(FlcSpec spec);  // validates; throws std::invalid_argument

  // eq. 5.1: y = K_u * sum_l ybar_l w_l prod_i mu_il(K_i x_i) / sum_l w_l prod_i mu_il(K_i x_i).
  // Returns 0 when no rule fires (fuzzylite's "default: 0"). NaN input -> NaN.
  double evaluate(double error, double derivative, double integral) const {
    return evaluate_detail(error, derivative, integral).output;
  }
  Evaluation evaluate_detail(double error, double derivative, double integral) const;

  const FlcSpec& spec() const { return spec_; }

 private:
  FlcSpec spec_;
  std::array<int, kInputs> stride_{};
  std::vector<int32_t> rule_out_;     // dense [e][d][i] -> output set, -1 = no rule
  std::vector<double> rule_weight_;   // dense [e][d][i] -> weight
};

// Membership of x in set k of v (unscaled position units) — the triangle described above.
double membership(const Variable& v, int k, double x);

}  // namespace aerie::flc
