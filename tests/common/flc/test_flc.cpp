// The FLC engine against hand-computed values, the thesis' rule tables, YAML/FLL
// round trips, fuzzylite as the reference engine, and the set/rule pruning of 5.1.5.
#include <fl/Headers.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <memory>
#include <random>

#include "common/flc/flc.hpp"
#include "common/flc/flc_io.hpp"
#include "common/flc/pid_inputs.hpp"
#include "common/flc/prune.hpp"
#include "tests/support/test_support.hpp"

using namespace aerie::flc;

namespace {

const Rule* find_rule(const FlcSpec& s, const std::string& e, const std::string& d, const std::string& i) {
  const std::array<int, 3> in = {s.inputs[0].index_of(e), s.inputs[1].index_of(d), s.inputs[2].index_of(i)};
  for (const auto& r : s.rules)
    if (r.in == in) return &r;
  return nullptr;
}

std::string consequent(const FlcSpec& s, const std::string& e, const std::string& d, const std::string& i) {
  const Rule* r = find_rule(s, e, d, i);
  return r ? s.output.sets[r->out] : "(none)";
}

// The controller the thesis reports after both CE stages (5.1.5).
FlcSpec thesis_optimised() {
  FlcSpec s = thesis_initial();
  s.id = "thesis-sfmf";
  s.set_parameter("Kp", 4.6739);
  s.set_parameter("Kd", 0.03);
  s.set_parameter("Ki", -0.5003);
  s.set_parameter("error.Left", -89.6960);
  s.set_parameter("derivative.Negative", -8.1166);
  s.set_parameter("integral.Negative", -9.9782);
  s.set_parameter("yaw_rate.BigLeft", -88.974);
  s.set_parameter("yaw_rate.Left", -88.191);
  s.set_parameter("yaw_rate.LittleLeft", -74.952);
  return s;
}

// fuzzylite evaluating an FLL text. fuzzylite compares floating-point numbers with a
// tolerance (macheps, 1e-6 by default): it skips rules activated below it and snaps
// inputs within it of a vertex. Eq. 5.1 has no such tolerance, so the reference is run
// with exact comparisons.
struct Fuzzylite {
  std::unique_ptr<fl::Engine> engine;
  explicit Fuzzylite(const std::string& fll) {
    fl::fuzzylite::setMachEps(0.0);
    fl::fuzzylite::setDecimals(17);
    fl::FllImporter importer;
    engine.reset(importer.fromString(fll));
    std::string status;
    if (!engine->isReady(&status)) throw std::runtime_error("fuzzylite: engine not ready: " + status);
  }
  double operator()(double e, double d, double i) {
    engine->getInputVariable(0)->setValue(e);
    engine->getInputVariable(1)->setValue(d);
    engine->getInputVariable(2)->setValue(i);
    engine->process();
    return engine->getOutputVariable(0)->getValue();
  }
};

void expect_same_as_fuzzylite(const FlcSpec& spec, uint64_t seed) {
  const Flc flc(spec);
  Fuzzylite ref(to_fll(spec));
  std::mt19937_64 rng(seed);
  // Raw inputs over 1.5x the raw ranges, so saturation is exercised too.
  std::array<std::uniform_real_distribution<double>, 3> dist;
  for (int i = 0; i < 3; ++i) {
    const auto& v = spec.inputs[i];
    const double half = 0.75 * (v.max - v.min) / std::abs(v.scaling);
    dist[i] = std::uniform_real_distribution<double>(-half, half);
  }
  double worst = 0.0;
  for (int n = 0; n < 10000; ++n) {
    const double e = dist[0](rng), d = dist[1](rng), i = dist[2](rng);
    const double ours = flc.evaluate(e, d, i), theirs = ref(e, d, i);
    ASSERT_TRUE(std::isfinite(theirs)) << "fuzzylite gave " << theirs << " at " << e << ", " << d << ", " << i;
    ASSERT_NEAR(ours, theirs, 1e-9) << "at (" << e << ", " << d << ", " << i << ")";
    worst = std::max(worst, std::abs(ours - theirs));
  }
  ::testing::Test::RecordProperty("max_abs_difference_" + spec.id, std::to_string(worst));
}

}  // namespace

TEST(Membership, TriangleValuesByHand) {
  const Variable v = thesis_initial().inputs[0];  // peaks -90 -45 0 45 90
  EXPECT_DOUBLE_EQ(membership(v, 1, -67.5), 0.5);
  EXPECT_DOUBLE_EQ(membership(v, 1, -45.0), 1.0);
  EXPECT_DOUBLE_EQ(membership(v, 2, 10.0), 35.0 / 45.0);
  EXPECT_DOUBLE_EQ(membership(v, 3, 10.0), 10.0 / 45.0);
  EXPECT_DOUBLE_EQ(membership(v, 3, -10.0), 0.0);
  EXPECT_DOUBLE_EQ(membership(v, 0, -90.0), 1.0);
  EXPECT_DOUBLE_EQ(membership(v, 0, -100.0), 35.0 / 45.0);  // mirrored outer foot at -135
  EXPECT_DOUBLE_EQ(membership(v, 4, 200.0), 0.0);
  // Ruspini partition: memberships sum to one inside the range.
  for (double x = -90; x <= 90; x += 0.37) {
    double sum = 0;
    for (int k = 0; k < v.size(); ++k) sum += membership(v, k, x);
    EXPECT_NEAR(sum, 1.0, 1e-12) << x;
  }
}

TEST(Defuzzification, WeightedHeightByHand) {
  FlcSpec s = thesis_initial();
  {
    const Flc flc(s);
    // error 22.5: Zero 0.5, Right 0.5; rules (Zero|Right, Zero, Zero) -> Zero (0), LittleRight (22.5).
    EXPECT_DOUBLE_EQ(flc.evaluate(22.5, 0, 0), 11.25);
    // error 30 (Zero 1/3, Right 2/3), derivative 5 (Zero 1/2, Positive 1/2), integral -2.5
    // (Negative 1/2, Zero 1/2): eight rules, sum of degrees 1, sum of degree*peak 450/12.
    const auto ev = flc.evaluate_detail(30, 5, -2.5);
    EXPECT_NEAR(ev.output, 37.5, 1e-12);
    EXPECT_EQ(ev.fired_rules, 8);
  }
  // Rule weight 0.5 on (Right, Positive, Negative) -> BigRight (67.5): its degree 1/6 halves.
  for (auto& r : s.rules)
    if (r.in == std::array<int, 3>{3, 3, 1}) r.weight = 0.5;
  EXPECT_NEAR(Flc(s).evaluate(30, 5, -2.5), (450.0 / 12 - 67.5 / 12) / (11.0 / 12), 1e-12);
  // Scaling factors: Kp = 2 maps a raw 15 to 30; the output factor scales the result.
  s = thesis_initial();
  s.set_parameter("Kp", 2.0);
  s.set_parameter("Kd", 0.5);
  s.set_parameter("Ku", 2.0);
  EXPECT_NEAR(Flc(s).evaluate(15, 10, -2.5), 75.0, 1e-12);
  // Saturation: beyond the range the end set holds membership 1.
  EXPECT_DOUBLE_EQ(Flc(thesis_initial()).evaluate(1e6, 0, 0), Flc(thesis_initial()).evaluate(90, 0, 0));
  EXPECT_TRUE(std::isnan(Flc(thesis_initial()).evaluate(NAN, 0, 0)));
}

TEST(RuleBase, TablesTranscribedFromTheThesis) {
  const FlcSpec s = thesis_initial();
  ASSERT_EQ(s.rules.size(), 125u);
  // Spot checks, one or more per table (thesis Tables 5.1-5.5).
  EXPECT_EQ(consequent(s, "BigLeft", "BigNegative", "Zero"), "GreatLeft");        // 5.1
  EXPECT_EQ(consequent(s, "Right", "Zero", "Zero"), "LittleRight");               // 5.1
  EXPECT_EQ(consequent(s, "BigRight", "BigNegative", "Zero"), "Zero");            // 5.1
  EXPECT_EQ(consequent(s, "Zero", "Zero", "Negative"), "LittleRight");            // 5.2
  EXPECT_EQ(consequent(s, "BigRight", "BigPositive", "Negative"), "GreatRight");  // 5.2
  EXPECT_EQ(consequent(s, "BigLeft", "Zero", "BigNegative"), "Zero");             // 5.3
  EXPECT_EQ(consequent(s, "Left", "BigPositive", "BigNegative"), "BigRight");     // 5.3
  EXPECT_EQ(consequent(s, "Zero", "Zero", "Positive"), "LittleLeft");             // 5.4
  EXPECT_EQ(consequent(s, "Left", "BigNegative", "Positive"), "GreatLeft");       // 5.4
  EXPECT_EQ(consequent(s, "Zero", "BigNegative", "BigPositive"), "GreatLeft");    // 5.5
  EXPECT_EQ(consequent(s, "BigRight", "BigPositive", "BigPositive"), "Right");    // 5.5
  // The whole cube follows one law, out = clamp(error + derivative - integral) in set
  // steps, and is antisymmetric: (-e, -d, -i) -> -out.
  for (const Rule& r : s.rules) {
    const int law = std::clamp(r.in[0] + r.in[1] - r.in[2] - 2, -4, 4) + 4;
    EXPECT_EQ(r.out, law) << s.inputs[0].sets[r.in[0]] << "/" << s.inputs[1].sets[r.in[1]] << "/" << s.inputs[2].sets[r.in[2]];
    const Rule* m = find_rule(s, s.inputs[0].sets[4 - r.in[0]], s.inputs[1].sets[4 - r.in[1]], s.inputs[2].sets[4 - r.in[2]]);
    ASSERT_NE(m, nullptr);
    EXPECT_EQ(m->out, 8 - r.out);
    EXPECT_EQ(r.weight, 1.0);
  }
  // The controller is odd: f(-x) = -f(x), for the initial and the thesis' optimised one.
  for (const FlcSpec& spec : {thesis_initial(), thesis_optimised()}) {
    const Flc flc(spec);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-100, 100);
    for (int n = 0; n < 1000; ++n) {
      const double e = u(rng), d = u(rng) / 4, i = u(rng) / 8;
      EXPECT_NEAR(flc.evaluate(-e, -d, -i), -flc.evaluate(e, d, i), 1e-12);
    }
  }
}

TEST(Parameters, SymmetricNamedParameters) {
  FlcSpec s = thesis_initial();
  const auto names = s.parameter_names();
  const std::vector<std::string> expected = {"Kp", "Kd", "Ki", "Ku",
                                             "error.BigLeft", "error.Left",
                                             "derivative.BigNegative", "derivative.Negative",
                                             "integral.BigNegative", "integral.Negative",
                                             "yaw_rate.GreatLeft", "yaw_rate.BigLeft", "yaw_rate.Left", "yaw_rate.LittleLeft"};
  EXPECT_EQ(names, expected);
  s.set_parameter("error.Left", -60);
  EXPECT_EQ(s.inputs[0].positions[1], -60);
  EXPECT_EQ(s.inputs[0].positions[3], 60);
  s.set_parameter("yaw_rate.LittleRight", 30);  // a right-side name mirrors to the left
  EXPECT_EQ(s.output.positions[3], -30);
  EXPECT_EQ(s.parameter("yaw_rate.LittleLeft"), -30);
  s.set_parameter("Ki", -0.5);
  EXPECT_EQ(s.inputs[2].scaling, -0.5);
  EXPECT_EQ(s.parameter("integral.scaling"), -0.5);
  EXPECT_THROW(s.set_parameter("error.Zero", 1), std::invalid_argument);
  EXPECT_THROW(s.set_parameter("error.Huge", 1), std::invalid_argument);
  EXPECT_THROW(s.set_parameter("Kq", 1), std::invalid_argument);
  EXPECT_THROW(s.parameter("pitch.Left"), std::invalid_argument);
}

TEST(Validation, RefusesMalformedControllersWithAReason) {
  auto refuses = [](const FlcSpec& s, const std::string& reason) {
    try {
      Flc f(s);
      ADD_FAILURE() << "accepted; expected: " << reason;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
    }
  };
  FlcSpec s = thesis_initial();
  s.set_parameter("error.Left", -95);  // beyond BigLeft at -90 and the range
  refuses(s, "outside the range");
  s = thesis_initial();
  s.inputs[1].positions[0] = -5;  // BigNegative right of Negative (-10)
  refuses(s, "strictly increasing");
  s = thesis_initial();
  s.set_parameter("Kd", 0.0);
  refuses(s, "non-zero");
  s = thesis_initial();
  s.set_parameter("Kp", NAN);
  refuses(s, "finite");
  s = thesis_initial();
  s.rules[3].weight = 1.5;
  refuses(s, "weight");
  s = thesis_initial();
  s.rules.push_back(s.rules[0]);
  refuses(s, "repeats");
  s = thesis_initial();
  s.rules[0].out = 9;
  refuses(s, "output set 9");
  s = thesis_initial();
  s.rules.clear();
  refuses(s, "empty");
}

TEST(Yaml, RoundTripAndErrorsNameTheKey) {
  const FlcSpec a = thesis_optimised();
  const FlcSpec b = parse_yaml(to_yaml(a), "roundtrip");
  EXPECT_EQ(b.id, a.id);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(b.inputs[i].positions, a.inputs[i].positions);
    EXPECT_EQ(b.inputs[i].scaling, a.inputs[i].scaling);
  }
  EXPECT_EQ(b.output.positions, a.output.positions);
  ASSERT_EQ(b.rules.size(), a.rules.size());
  for (const Rule& r : a.rules) {
    const Rule* m = find_rule(b, a.inputs[0].sets[r.in[0]], a.inputs[1].sets[r.in[1]], a.inputs[2].sets[r.in[2]]);
    ASSERT_NE(m, nullptr);
    EXPECT_EQ(m->out, r.out);
  }
  // The file in config/ is the one compiled in.
  const FlcSpec f = load_yaml((aerie::test::source_dir() / "config/flc/initial.yaml").string());
  EXPECT_EQ(to_yaml(f), to_yaml(thesis_initial()));

  std::string text = thesis_initial_yaml();
  text.replace(text.find("Negative: [BigLeft, Left, LittleLeft, Zero, LittleRight]"), 8, "Negatyve");
  try {
    parse_yaml(text, "bad.yaml");
    FAIL() << "accepted a misspelt set";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("bad.yaml"), std::string::npos) << msg;
    EXPECT_NE(msg.find("Negatyve"), std::string::npos) << msg;
    EXPECT_NE(msg.find("line"), std::string::npos) << msg;
  }
}

TEST(Fll, RoundTripRestoresTheScaledParameters) {
  for (const FlcSpec& a : {thesis_initial(), thesis_optimised(), prune(thesis_optimised())}) {
    const std::string fll = to_fll(a);
    const FlcSpec b = parse_fll(fll, "roundtrip.fll");
    EXPECT_EQ(b.id, a.id);
    EXPECT_EQ(b.rules.size(), a.rules.size());
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(b.inputs[i].sets, a.inputs[i].sets);
      EXPECT_EQ(b.inputs[i].scaling, a.inputs[i].scaling);
      for (size_t k = 0; k < a.inputs[i].positions.size(); ++k)
        EXPECT_NEAR(b.inputs[i].positions[k], a.inputs[i].positions[k], 1e-12);
    }
    const Flc fa(a), fb(b);
    for (double e = -120; e <= 120; e += 7.3)
      EXPECT_NEAR(fa.evaluate(e, e / 5, -e / 9), fb.evaluate(e, e / 5, -e / 9), 1e-9);
    // Without our comment lines the FLL is still a valid controller in raw units.
    std::string plain;
    std::istringstream is(fll);
    for (std::string line; std::getline(is, line);)
      if (line.rfind("#", 0) != 0) plain += line + "\n";
    const FlcSpec c = parse_fll(plain, "plain.fll");
    EXPECT_EQ(c.inputs[0].scaling, 1.0);
    const Flc fc(c);
    for (double e = -120; e <= 120; e += 7.3)
      EXPECT_NEAR(fa.evaluate(e, e / 5, -e / 9), fc.evaluate(e, e / 5, -e / 9), 1e-9);
  }
}

TEST(Fll, ImportRefusesWhatEq51DoesNotCover) {
  const std::string fll = to_fll(thesis_initial());
  auto refuses = [&](const std::string& from, const std::string& to, const std::string& reason) {
    std::string t = fll;
    const auto at = t.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    t.replace(at, from.size(), to);
    try {
      parse_fll(t, "x.fll");
      ADD_FAILURE() << "accepted " << to;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
    }
  };
  refuses("conjunction: AlgebraicProduct", "conjunction: Minimum", "AlgebraicProduct");
  refuses("defuzzifier: WeightedAverage", "defuzzifier: Centroid", "WeightedAverage");
  refuses("term: BigLeft Triangle", "term: BigLeft Trapezoid", "Triangle");
  refuses("term: Left Triangle -90 -45 0", "term: Left Triangle -80 -45 0", "feet");
  refuses("term: GreatLeft Constant -90", "term: GreatLeft Triangle -90 -90 -67.5", "Constant");
  refuses("then yaw_rate is GreatLeft with 1", "then yaw_rate is Huge with 1", "Huge");
  refuses("and derivative is BigNegative and", "or derivative is BigNegative and", "expected 'and'");
  refuses("with 1\n", "with 2\n", "weight");
  refuses("lock-range: true", "lock-range: false", "lock-range");
}

TEST(Fll, FuzzyliteComputesTheSameOutputs) {
  // The FLL written for fuzzylite, fuzzylite's output vs ours on 10,000 random inputs.
  expect_same_as_fuzzylite(thesis_initial(), 1);
  expect_same_as_fuzzylite(thesis_optimised(), 2);
  expect_same_as_fuzzylite(prune(thesis_optimised()), 3);
  FlcSpec weighted = thesis_optimised();
  std::mt19937_64 rng(4);
  for (auto& r : weighted.rules) r.weight = std::uniform_real_distribution<double>(0.1, 1.0)(rng);
  weighted.id = "weighted";
  expect_same_as_fuzzylite(weighted, 5);
  // And fuzzylite's own export of what it imported reads back into the same controller.
  fl::FllImporter importer;
  std::unique_ptr<fl::Engine> engine(importer.fromString(to_fll(weighted)));
  const FlcSpec back = parse_fll(fl::FllExporter().toString(engine.get()), "fuzzylite-export.fll");
  const Flc a(weighted), b(back);
  for (double e = -20; e <= 20; e += 0.77) EXPECT_NEAR(a.evaluate(e, 3 * e, -e), b.evaluate(e, 3 * e, -e), 1e-9);
}

TEST(Fll, FuzzylitesDefaultThreeDecimalExportIsAccepted) {
  // Issue 18: aerie-ceopt's SF+MF controller exported by fuzzylite at its default 3 decimals
  // was refused (its feet no longer exactly at the neighbours' peaks). Accepted within the
  // documented tolerance, it computes nearly what the original does.
  const FlcSpec sfmf = load_yaml((aerie::test::source_dir() / "config" / "flc" / "sfmf.yaml").string());
  fl::FllImporter importer;
  std::unique_ptr<fl::Engine> engine(importer.fromString(to_fll(sfmf)));
  const int decimals = fl::fuzzylite::decimals();
  fl::fuzzylite::setDecimals(3);
  const std::string text = fl::FllExporter().toString(engine.get());
  fl::fuzzylite::setDecimals(decimals);
  const FlcSpec back = parse_fll(text, "fuzzylite-3-decimals.fll");
  const Flc a(sfmf), b(back);
  double worst = 0;
  for (double e = -90; e <= 90; e += 1.3)
    for (double d = -20; d <= 20; d += 2.7) worst = std::max(worst, std::abs(a.evaluate(e, d, -e / 9) - b.evaluate(e, d, -e / 9)));
  EXPECT_LT(worst, 0.5);  // deg/s, of a +-90 deg/s output
  // Feet farther off than printing explains are still refused.
  std::string moved = text;
  const auto at = moved.find("Triangle");
  ASSERT_NE(at, std::string::npos);
  const auto num = moved.find_first_of("-0123456789", at);
  moved.insert(num, "1");  // the first foot of the first term, an order of magnitude off
  EXPECT_THROW(parse_fll(moved, "moved.fll"), std::runtime_error);
}

TEST(Prune, ThesisOptimisedControllerReducesTo45Rules) {
  PruneReport rep;
  const FlcSpec p = prune(thesis_optimised(), {}, &rep);
  EXPECT_EQ(rep.rules_before, 125);
  EXPECT_EQ(rep.rules_after, 45);
  EXPECT_EQ(p.inputs[0].sets, (std::vector<std::string>{"Left", "Zero", "Right"}));
  EXPECT_EQ(p.inputs[1].size(), 5);
  EXPECT_EQ(p.inputs[2].sets, (std::vector<std::string>{"Negative", "Zero", "Positive"}));
  EXPECT_EQ(p.output.sets, (std::vector<std::string>{"Left", "LittleLeft", "Zero", "LittleRight", "Right"}));
  EXPECT_DOUBLE_EQ(p.inputs[0].positions[0], -89.6960);
  // Tables 5.6-5.8 of the thesis, row by row (derivative BigNegative..BigPositive,
  // columns error Left, Zero, Right).
  const std::map<std::string, std::vector<std::vector<std::string>>> tables = {
      {"Zero", {{"Left", "Left", "LittleLeft"}, {"Left", "LittleLeft", "Zero"}, {"LittleLeft", "Zero", "LittleRight"},
                {"Zero", "LittleRight", "Right"}, {"LittleRight", "Right", "Right"}}},
      {"Negative", {{"Left", "LittleLeft", "Zero"}, {"LittleLeft", "Zero", "LittleRight"}, {"Zero", "LittleRight", "Right"},
                    {"LittleRight", "Right", "Right"}, {"Right", "Right", "Right"}}},
      {"Positive", {{"Left", "Left", "Left"}, {"Left", "Left", "LittleLeft"}, {"Left", "LittleLeft", "Zero"},
                    {"LittleLeft", "Zero", "LittleRight"}, {"Zero", "LittleRight", "Right"}}}};
  for (const auto& [integral, rows] : tables)
    for (int d = 0; d < 5; ++d)
      for (int e = 0; e < 3; ++e)
        EXPECT_EQ(consequent(p, p.inputs[0].sets[e], p.inputs[1].sets[d], integral), rows[d][e])
            << integral << " / " << p.inputs[1].sets[d] << " / " << p.inputs[0].sets[e];
  // Restricted to one variable: only the error's sets merge (5 x 5 x 5 -> 3 x 5 x 5 rules).
  PruneOptions only_error;
  only_error.variables = {"error"};
  const FlcSpec e = prune(thesis_optimised(), only_error);
  EXPECT_EQ(e.rules.size(), 75u);
  EXPECT_EQ(e.output.size(), 9);
  EXPECT_EQ(e.inputs[2].size(), 5);
  // Nothing overlaps in the initial controller.
  EXPECT_EQ(prune(thesis_initial()).rules.size(), 125u);
}

TEST(ErrorSignals, DerivativeAndIntegralOverMessageTime) {
  ErrorSignals s;
  auto x = s.update(0.0, 0.0, 90.0);
  EXPECT_EQ(x, (std::array<double, 3>{90, 0, 0}));
  x = s.update(0.5, 10.0, 90.0);
  EXPECT_DOUBLE_EQ(x[0], 80.0);
  EXPECT_DOUBLE_EQ(x[1], -20.0);
  EXPECT_DOUBLE_EQ(x[2], 40.0);
  x = s.update(0.5, 12.0, 90.0);  // same time stamp: no derivative/integral update
  EXPECT_DOUBLE_EQ(x[1], -20.0);
  EXPECT_DOUBLE_EQ(x[2], 40.0);
  // Wrapping: reference 170, heading -175 is an error of -15, not 345.
  s.reset();
  x = s.update(0.0, -175.0, 170.0);
  EXPECT_DOUBLE_EQ(x[0], -15.0);
  x = s.update(1.0, 175.0, -170.0);  // error 15 across the wrap
  EXPECT_DOUBLE_EQ(x[0], 15.0);
  EXPECT_DOUBLE_EQ(wrap_deg(540.0), -180.0);
  EXPECT_DOUBLE_EQ(wrap_deg(-190.0), 170.0);
}

namespace {
// A controller of thesis_initial() shape with n0 x n1 x n2 input sets (evenly spaced) and one rule.
FlcSpec with_sets(int n0, int n1, int n2) {
  FlcSpec s = thesis_initial();
  const int n[3] = {n0, n1, n2};
  for (int i = 0; i < 3; ++i) {
    Variable& v = s.inputs[i];
    v.min = -1;
    v.max = n[i];
    v.sets.clear();
    v.positions.clear();
    for (int k = 0; k < n[i]; ++k) {
      v.sets.push_back("s" + std::to_string(k));
      v.positions.push_back(k);
    }
  }
  s.rules = {Rule{{0, 0, 0}, 0, 1.0}};
  return s;
}

std::string refusal(const FlcSpec& s) {
  try {
    Flc f(s);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Validation, RuleTableSizeIsCheckedIn64BitsBeforeAllocating) {
  // 2048 x 2048 x 1024 = 2^32 overflowed the int product (a crash); 1626^3 wrapped to 3975080
  // cells (an aliased table). Both are refused by their true size, before any allocation.
  EXPECT_EQ(rule_table_cells({5, 5, 5}), 125);
  std::string e = refusal(with_sets(2048, 2048, 1024));
  EXPECT_NE(e.find("rule table of 2048 x 2048 x 1024 input sets = 4294967296 cells is larger than 262144"),
            std::string::npos) << e;
  e = refusal(with_sets(1626, 1626, 1626));
  EXPECT_NE(e.find("1626 x 1626 x 1626 input sets = 4298942376 cells"), std::string::npos) << e;
  try {
    rule_table_cells({INT32_MAX, INT32_MAX, INT32_MAX});  // overflows int64 too
    FAIL();
  } catch (const std::invalid_argument& e2) {
    EXPECT_NE(std::string(e2.what()).find("2147483647 x 2147483647 x 2147483647 input sets is larger"), std::string::npos)
        << e2.what();
  }
  // One variable past kMaxSets, however small the table.
  FlcSpec wide = with_sets(2, 2, 2);
  wide.output.sets.clear();
  wide.output.positions.clear();
  for (int k = 0; k <= kMaxSets; ++k) {
    wide.output.sets.push_back("o" + std::to_string(k));
    wide.output.positions.push_back(k * 1e-3);
  }
  wide.output.min = -1, wide.output.max = 1;
  EXPECT_NE(refusal(wide).find("has 65 sets, more than 64"), std::string::npos) << refusal(wide);
  EXPECT_EQ(refusal(with_sets(64, 64, 64)), "");  // the largest table is accepted
}

TEST(FllFormat, RefusesTooManyTermsAndTooLongTexts) {
  // The reproducer's shape: 2048 terms in one input. Refused at the 65th term line.
  std::string fll = "Engine: big\nInputVariable: error\n  enabled: true\n  range: -2048 2048\n  lock-range: true\n";
  for (int k = 0; k < 2048; ++k)
    fll += "  term: s" + std::to_string(k) + " Triangle " + std::to_string(k - 1) + " " + std::to_string(k) + " " +
           std::to_string(k + 1) + "\n";
  try {
    parse_fll(fll, "big.fll");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("big.fll:70: 'error' has more than 64 terms"), std::string::npos) << e.what();
  }
  try {
    parse_fll(std::string(kMaxFllBytes + 1, '#'), "huge.fll");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("huge.fll: FLL text of 1048577 bytes, more than 1048576"), std::string::npos)
        << e.what();
  }
}
