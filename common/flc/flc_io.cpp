#include "common/flc/flc_io.hpp"

#include "common/util/files.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace aerie::flc {
namespace {

// Shortest text that reads back to the same double.
std::string num(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, r.ptr);
}

std::string read_file(const std::string& path) { return util::read_regular_file(path, "controller file"); }

void write_file(const std::string& path, const std::string& text) {
  std::ofstream f(path);
  if (!f || !(f << text)) throw std::runtime_error(path + ": cannot write");
}

// ---------------------------------------------------------------- YAML

struct YamlReader {
  std::string origin;

  [[noreturn]] void fail(const YAML::Node& n, const std::string& key, const std::string& what) const {
    std::string where = origin + ": '" + key + "'";
    if (n.Mark().line >= 0) where += " (line " + std::to_string(n.Mark().line + 1) + ")";
    throw std::runtime_error(where + ": " + what);
  }
  YAML::Node need(const YAML::Node& parent, const std::string& key, const std::string& path) const {
    const YAML::Node n = parent[key];
    if (!n) fail(parent, path + key, "missing");
    return n;
  }
  template <typename T>
  T as(const YAML::Node& n, const std::string& key, const char* expected) const {
    try {
      return n.as<T>();
    } catch (const YAML::Exception&) {
      fail(n, key, std::string("expected ") + expected);
    }
  }

  Variable variable(const YAML::Node& n, const std::string& key) const {
    if (!n.IsMap()) fail(n, key, "expected a map with name, range, scaling, sets, positions");
    Variable v;
    v.name = as<std::string>(need(n, "name", key + "."), key + ".name", "a string");
    v.unit = n["unit"] ? as<std::string>(n["unit"], key + ".unit", "a string") : "";
    const auto range = as<std::vector<double>>(need(n, "range", key + "."), key + ".range", "[min, max]");
    if (range.size() != 2) fail(n["range"], key + ".range", "expected [min, max]");
    v.min = range[0];
    v.max = range[1];
    v.scaling = n["scaling"] ? as<double>(n["scaling"], key + ".scaling", "a number") : 1.0;
    v.sets = as<std::vector<std::string>>(need(n, "sets", key + "."), key + ".sets", "a list of set names");
    v.positions = as<std::vector<double>>(need(n, "positions", key + "."), key + ".positions", "a list of numbers");
    return v;
  }

  int set_index(const Variable& v, const YAML::Node& n, const std::string& key, const std::string& set) const {
    const int k = v.index_of(set);
    if (k < 0) fail(n, key, "'" + set + "' is not a set of '" + v.name + "'");
    return k;
  }

  // One table of the rule base (a slice at one set of the third input).
  void table(const FlcSpec& spec, const YAML::Node& n, const std::string& key, std::vector<Rule>& rules) const {
    const Variable& e = spec.inputs[0];
    const Variable& d = spec.inputs[1];
    const Variable& i = spec.inputs[2];
    const auto slice = as<std::string>(need(n, i.name, key + "."), key + "." + i.name, "a set name");
    const int ki = set_index(i, n[i.name], key + "." + i.name, slice);
    const auto columns = as<std::vector<std::string>>(need(n, "columns", key + "."), key + ".columns", "a list of set names");
    std::vector<int> ke;
    for (const auto& c : columns) ke.push_back(set_index(e, n["columns"], key + ".columns", c));
    const YAML::Node rows = need(n, "rows", key + ".");
    if (!rows.IsMap()) fail(rows, key + ".rows", "expected a map <derivative set>: [output set per column]");
    const YAML::Node weights = n["weights"];
    for (const auto& row : rows) {
      const auto dname = as<std::string>(row.first, key + ".rows", "a set name");
      const std::string rkey = key + ".rows." + dname;
      const int kd = set_index(d, row.first, rkey, dname);
      const auto outs = as<std::vector<std::string>>(row.second, rkey, "a list of output set names");
      if (outs.size() != ke.size())
        fail(row.second, rkey, "has " + std::to_string(outs.size()) + " entries for " + std::to_string(ke.size()) + " columns");
      std::vector<double> w(outs.size(), 1.0);
      if (weights && weights[dname]) {
        w = as<std::vector<double>>(weights[dname], key + ".weights." + dname, "a list of numbers");
        if (w.size() != outs.size()) fail(weights[dname], key + ".weights." + dname, "must have one weight per column");
      }
      for (size_t c = 0; c < outs.size(); ++c) {
        if (outs[c] == "-") continue;
        rules.push_back(Rule{{ke[c], kd, ki}, set_index(spec.output, row.second, rkey, outs[c]), w[c]});
      }
    }
  }
};

void emit_variable(YAML::Emitter& y, const Variable& v) {
  y << YAML::BeginMap;
  y << YAML::Key << "name" << YAML::Value << v.name;
  if (!v.unit.empty()) y << YAML::Key << "unit" << YAML::Value << v.unit;
  y << YAML::Key << "range" << YAML::Value << YAML::Flow << YAML::BeginSeq << v.min << v.max << YAML::EndSeq;
  y << YAML::Key << "scaling" << YAML::Value << v.scaling;
  y << YAML::Key << "sets" << YAML::Value << YAML::Flow << v.sets;
  y << YAML::Key << "positions" << YAML::Value << YAML::Flow << v.positions;
  y << YAML::EndMap;
}

// ---------------------------------------------------------------- FLL

bool valid_identifier(const std::string& s) {
  if (s.empty() || std::isdigit(static_cast<unsigned char>(s[0]))) return false;
  return std::all_of(s.begin(), s.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

std::string sanitize(const std::string& s) {
  std::string out = s.empty() ? "aerie_flc" : s;
  for (char& c : out)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') c = '_';
  if (std::isdigit(static_cast<unsigned char>(out[0]))) out = "_" + out;
  return out;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

std::vector<std::string> words(const std::string& s) {
  std::istringstream is(s);
  std::vector<std::string> w;
  for (std::string t; is >> t;) w.push_back(t);
  return w;
}

struct FllTerm {
  std::string name, shape;
  std::vector<double> params;
  int line = 0;
};

struct FllVariable {
  std::string name;
  double lo = NAN, hi = NAN;
  bool lock_range = false;
  std::vector<FllTerm> terms;
  std::map<std::string, std::string> keys;
  int line = 0;
};

}  // namespace

// ---------------------------------------------------------------- YAML API

FlcSpec parse_yaml(const std::string& text, const std::string& origin) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(origin + ": YAML syntax error: " + e.what());
  }
  YamlReader r{origin};
  if (!root.IsMap()) throw std::runtime_error(origin + ": expected a map with id, inputs, output, rules");
  FlcSpec spec;
  spec.id = root["id"] ? r.as<std::string>(root["id"], "id", "a string") : "";
  const YAML::Node inputs = r.need(root, "inputs", "");
  if (!inputs.IsSequence() || inputs.size() != kInputs)
    r.fail(inputs, "inputs", "expected a list of exactly 3 variables (error, derivative, integral)");
  for (int i = 0; i < kInputs; ++i) spec.inputs[i] = r.variable(inputs[i], "inputs[" + std::to_string(i) + "]");
  spec.output = r.variable(r.need(root, "output", ""), "output");
  for (const auto& v : spec.inputs)
    if (v.sets.size() != v.positions.size())
      throw std::runtime_error(origin + ": input '" + v.name + "' has " + std::to_string(v.sets.size()) + " sets but " +
                               std::to_string(v.positions.size()) + " positions");
  const YAML::Node tables = r.need(root, "rules", "");
  if (!tables.IsSequence()) r.fail(tables, "rules", "expected a list of tables (one per set of the third input)");
  for (size_t t = 0; t < tables.size(); ++t) r.table(spec, tables[t], "rules[" + std::to_string(t) + "]", spec.rules);
  try {
    spec.validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(origin + ": " + e.what());
  }
  return spec;
}

FlcSpec load_yaml(const std::string& path) { return parse_yaml(read_file(path), path); }

std::string to_yaml(const FlcSpec& spec) {
  spec.validate();
  YAML::Emitter y;
  y.SetDoublePrecision(17);
  y << YAML::BeginMap;
  y << YAML::Key << "id" << YAML::Value << spec.id;
  y << YAML::Key << "inputs" << YAML::Value << YAML::BeginSeq;
  for (const auto& v : spec.inputs) emit_variable(y, v);
  y << YAML::EndSeq;
  y << YAML::Key << "output" << YAML::Value;
  emit_variable(y, spec.output);
  // Rule tables: one per integral set that has rules, columns = error sets used.
  const Variable& e = spec.inputs[0];
  const Variable& d = spec.inputs[1];
  const Variable& in = spec.inputs[2];
  y << YAML::Key << "rules" << YAML::Value << YAML::BeginSeq;
  for (int ki = 0; ki < in.size(); ++ki) {
    std::map<std::pair<int, int>, const Rule*> cell;  // (derivative, error) -> rule
    std::vector<bool> col(static_cast<size_t>(e.size()), false), row(static_cast<size_t>(d.size()), false);
    bool weighted = false;
    for (const Rule& r : spec.rules)
      if (r.in[2] == ki) {
        cell[{r.in[1], r.in[0]}] = &r;
        col[static_cast<size_t>(r.in[0])] = row[static_cast<size_t>(r.in[1])] = true;
        weighted = weighted || r.weight != 1.0;
      }
    if (cell.empty()) continue;
    std::vector<std::string> columns;
    for (int ke = 0; ke < e.size(); ++ke)
      if (col[static_cast<size_t>(ke)]) columns.push_back(e.sets[ke]);
    y << YAML::BeginMap << YAML::Key << in.name << YAML::Value << in.sets[ki];
    y << YAML::Key << "columns" << YAML::Value << YAML::Flow << columns;
    for (const char* part : {"rows", "weights"}) {
      const bool weights = part[0] == 'w';
      if (weights && !weighted) continue;
      y << YAML::Key << part << YAML::Value << YAML::BeginMap;
      for (int kd = 0; kd < d.size(); ++kd) {
        if (!row[static_cast<size_t>(kd)]) continue;
        y << YAML::Key << d.sets[kd] << YAML::Value << YAML::Flow << YAML::BeginSeq;
        for (int ke = 0; ke < e.size(); ++ke) {
          if (!col[static_cast<size_t>(ke)]) continue;
          const auto it = cell.find({kd, ke});
          if (weights)
            y << (it == cell.end() ? 0.0 : it->second->weight);
          else
            y << (it == cell.end() ? std::string("-") : spec.output.sets[it->second->out]);
        }
        y << YAML::EndSeq;
      }
      y << YAML::EndMap;
    }
    y << YAML::EndMap;
  }
  y << YAML::EndSeq << YAML::EndMap;
  return std::string("# Aerie fuzzy logic controller (format: config/flc/initial.yaml, docs/flc.md)\n") + y.c_str() + "\n";
}

void save_yaml(const FlcSpec& spec, const std::string& path) { write_file(path, to_yaml(spec)); }

// ---------------------------------------------------------------- FLL API

std::string to_fll(const FlcSpec& spec) {
  spec.validate();
  for (const Variable* v : {&spec.inputs[0], &spec.inputs[1], &spec.inputs[2], &spec.output}) {
    if (!valid_identifier(v->name)) throw std::invalid_argument("FLL export: variable name '" + v->name + "' is not an identifier");
    for (const auto& s : v->sets)
      if (!valid_identifier(s)) throw std::invalid_argument("FLL export: set name '" + s + "' of '" + v->name + "' is not an identifier");
  }
  std::ostringstream f;
  f << "# Aerie fuzzy logic controller '" << spec.id << "' (thesis 5.1.3, eq. 5.1), exported by aerie_flc.\n"
    << "# Inputs are raw (unscaled): each scaling factor K is folded into its variable, a set at\n"
    << "# position c becomes a triangle peaking at c/K; output sets are Constants K_u*c.\n"
    << "# aerie-flc id: " << spec.id << "\n# aerie-flc scaling:";
  for (const auto& v : spec.inputs) f << " " << v.name << "=" << num(v.scaling);
  f << " " << spec.output.name << "=" << num(spec.output.scaling) << "\n";
  f << "Engine: " << sanitize(spec.id) << "\n";
  for (const auto& v : spec.inputs) {
    const double k = v.scaling;
    const double lo = std::min(v.min / k, v.max / k), hi = std::max(v.min / k, v.max / k);
    f << "InputVariable: " << v.name << "\n  enabled: true\n  range: " << num(lo) << " " << num(hi) << "\n  lock-range: true\n";
    const int n = v.size();
    for (int s = 0; s < n; ++s) {
      const auto& c = v.positions;
      const double a = s > 0 ? c[s - 1] : c[0] - (c[1] - c[0]);
      const double e = s < n - 1 ? c[s + 1] : c[n - 1] + (c[n - 1] - c[n - 2]);
      double ra = a / k, rb = c[s] / k, re = e / k;
      if (ra > re) std::swap(ra, re);  // negative factor mirrors the triangle
      f << "  term: " << v.sets[s] << " Triangle " << num(ra) << " " << num(rb) << " " << num(re) << "\n";
    }
  }
  const Variable& o = spec.output;
  const double olo = std::min(o.min * o.scaling, o.max * o.scaling), ohi = std::max(o.min * o.scaling, o.max * o.scaling);
  f << "OutputVariable: " << o.name << "\n  enabled: true\n  range: " << num(olo) << " " << num(ohi)
    << "\n  lock-range: false\n  aggregation: none\n  defuzzifier: WeightedAverage TakagiSugeno\n"
    << "  default: 0\n  lock-previous: false\n";
  for (int s = 0; s < o.size(); ++s) f << "  term: " << o.sets[s] << " Constant " << num(o.positions[s] * o.scaling) << "\n";
  f << "RuleBlock: rules\n  enabled: true\n  conjunction: AlgebraicProduct\n  disjunction: none\n"
    << "  implication: none\n  activation: General\n";
  for (const Rule& r : spec.rules) {
    f << "  rule: if";
    for (int i = 0; i < kInputs; ++i)
      f << (i ? " and " : " ") << spec.inputs[i].name << " is " << spec.inputs[i].sets[r.in[i]];
    f << " then " << o.name << " is " << o.sets[r.out] << " with " << num(r.weight) << "\n";
  }
  return f.str();
}

FlcSpec parse_fll(const std::string& text, const std::string& origin) {
  auto fail = [&](int line, const std::string& what) -> void {
    throw std::runtime_error(origin + (line > 0 ? ":" + std::to_string(line) : std::string()) + ": " + what);
  };
  auto number = [&](int line, const std::string& s) {
    double v = 0;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    if (r.ec != std::errc() || r.ptr != s.data() + s.size()) fail(line, "'" + s + "' is not a number");
    return v;
  };
  std::string id, engine;
  if (text.size() > kMaxFllBytes)
    fail(0, "FLL text of " + std::to_string(text.size()) + " bytes, more than " + std::to_string(kMaxFllBytes));
  std::map<std::string, double> scaling;
  std::vector<FllVariable> inputs, outputs;
  std::map<std::string, std::string> block;
  std::vector<std::pair<int, std::string>> rules;
  enum { NONE, INPUT, OUTPUT, BLOCK } section = NONE;
  int blocks = 0;

  std::istringstream is(text);
  int ln = 0;
  for (std::string raw; std::getline(is, raw);) {
    ++ln;
    std::string line = trim(raw);
    if (line.rfind("# aerie-flc ", 0) == 0) {  // our metadata comments
      const std::string meta = line.substr(12);
      if (meta.rfind("id:", 0) == 0) id = trim(meta.substr(3));
      if (meta.rfind("scaling:", 0) == 0)
        for (const auto& kv : words(meta.substr(8))) {
          const auto eq = kv.find('=');
          if (eq == std::string::npos) fail(ln, "scaling entry '" + kv + "' is not name=value");
          scaling[kv.substr(0, eq)] = number(ln, kv.substr(eq + 1));
        }
      continue;
    }
    line = trim(line.substr(0, line.find('#')));
    if (line.empty()) continue;
    const auto colon = line.find(':');
    if (colon == std::string::npos) fail(ln, "expected 'key: value', got '" + line + "'");
    const std::string key = trim(line.substr(0, colon)), value = trim(line.substr(colon + 1));
    if (key == "Engine") {
      engine = value;
      section = NONE;
    } else if (key == "InputVariable" || key == "OutputVariable") {
      auto& list = key == "InputVariable" ? inputs : outputs;
      list.push_back(FllVariable{value, NAN, NAN, false, {}, {}, ln});
      section = key == "InputVariable" ? INPUT : OUTPUT;
    } else if (key == "RuleBlock") {
      if (++blocks > 1) fail(ln, "more than one RuleBlock (aerie_flc has one rule base)");
      section = BLOCK;
    } else if (key == "description") {
      continue;
    } else if (section == INPUT || section == OUTPUT) {
      FllVariable& v = section == INPUT ? inputs.back() : outputs.back();
      if (key == "range") {
        const auto w = words(value);
        if (w.size() != 2) fail(ln, "range of '" + v.name + "' must be two numbers");
        v.lo = number(ln, w[0]);
        v.hi = number(ln, w[1]);
      } else if (key == "lock-range") {
        v.lock_range = value == "true";
      } else if (key == "term") {
        auto w = words(value);
        if (w.size() < 2) fail(ln, "term of '" + v.name + "' must be '<name> <shape> <parameters>'");
        if (v.terms.size() >= static_cast<size_t>(kMaxSets))
          fail(ln, "'" + v.name + "' has more than " + std::to_string(kMaxSets) + " terms");
        FllTerm t{w[0], w[1], {}, ln};
        for (size_t k = 2; k < w.size(); ++k) t.params.push_back(number(ln, w[k]));
        v.terms.push_back(t);
      } else {
        v.keys[key] = value;
      }
    } else if (section == BLOCK) {
      if (key == "rule")
        rules.emplace_back(ln, value);
      else
        block[key] = value;
    } else {
      fail(ln, "'" + key + "' outside of a variable or rule block");
    }
  }
  if (inputs.size() != kInputs) fail(0, "expected 3 input variables (error, derivative, integral), found " + std::to_string(inputs.size()));
  if (outputs.size() != 1) fail(0, "expected 1 output variable, found " + std::to_string(outputs.size()));
  if (blocks != 1) fail(0, "expected one RuleBlock");
  auto require_key = [&](const std::map<std::string, std::string>& keys, const std::string& key, const std::string& want,
                         const std::string& where) {
    const auto it = keys.find(key);
    const std::string got = it == keys.end() ? "(absent)" : it->second;
    if (want == "none" ? (it != keys.end() && got != "none" && !got.empty()) : got != want)
      fail(0, where + " " + key + " is " + got + "; aerie_flc implements eq. 5.1, which needs " + want);
  };
  require_key(block, "conjunction", "AlgebraicProduct", "rule block");
  require_key(outputs[0].keys, "aggregation", "none", "output");
  {
    const auto it = outputs[0].keys.find("defuzzifier");
    if (it == outputs[0].keys.end() || words(it->second).empty() || words(it->second)[0] != "WeightedAverage")
      fail(outputs[0].line, "output defuzzifier must be WeightedAverage (height method, eq. 5.1)");
  }

  FlcSpec spec;
  spec.id = !id.empty() ? id : engine;
  auto factor = [&](const std::string& name) {
    const auto it = scaling.find(name);
    return it == scaling.end() ? 1.0 : it->second;
  };
  for (int i = 0; i < kInputs; ++i) {
    const FllVariable& fv = inputs[static_cast<size_t>(i)];
    Variable& v = spec.inputs[i];
    v.name = fv.name;
    v.scaling = factor(fv.name);
    if (!fv.lock_range) fail(fv.line, "input '" + fv.name + "' must have lock-range: true (inputs saturate to the range)");
    if (std::isnan(fv.lo)) fail(fv.line, "input '" + fv.name + "' has no range");
    const double k = v.scaling;
    v.min = std::min(fv.lo * k, fv.hi * k);
    v.max = std::max(fv.lo * k, fv.hi * k);
    // Order the sets by scaled peak (a negative factor reverses the raw order).
    std::vector<FllTerm> terms = fv.terms;
    for (const auto& t : terms)
      if (t.shape != "Triangle" || t.params.size() != 3)
        fail(t.line, "input term '" + t.name + "' must be 'Triangle a b c' (aerie_flc uses triangular sets)");
    std::stable_sort(terms.begin(), terms.end(), [&](const FllTerm& a, const FllTerm& b) { return a.params[1] * k < b.params[1] * k; });
    for (const auto& t : terms) {
      v.sets.push_back(t.name);
      v.positions.push_back(t.params[1] * k);
    }
    // The triangles must be the Ruspini partition of their peaks (see flc.hpp).
    const int n = static_cast<int>(terms.size());
    if (n < 2) fail(fv.line, "input '" + fv.name + "' needs at least 2 terms");
    // Up to what printing moved them: 1e-9 of the range, or 1.5e-3 in the file's own (unscaled)
    // units, three roundings at fuzzylite's default 3 decimals (a foot against two peaks).
    const double tol = std::max(1e-9 * (v.max - v.min), 1.5e-3 * std::abs(k));
    for (int s = 0; s < n; ++s) {
      const auto& c = v.positions;
      double a = terms[static_cast<size_t>(s)].params[0] * k, e = terms[static_cast<size_t>(s)].params[2] * k;
      if (a > e) std::swap(a, e);
      const double want_a = s > 0 ? c[s - 1] : c[0] - (c[1] - c[0]);
      const double want_e = s < n - 1 ? c[s + 1] : c[n - 1] + (c[n - 1] - c[n - 2]);
      if (std::abs(a - want_a) > tol || std::abs(e - want_e) > tol)
        fail(terms[static_cast<size_t>(s)].line, "term '" + v.sets[s] + "' of '" + v.name +
                                                     "': each triangle's feet must be the peaks of its neighbours (the end sets mirror "
                                                     "their inner foot); aerie_flc parametrises sets by their peaks");
    }
  }
  {
    const FllVariable& fo = outputs[0];
    Variable& o = spec.output;
    o.name = fo.name;
    o.scaling = factor(fo.name);
    if (std::isnan(fo.lo)) fail(fo.line, "output '" + fo.name + "' has no range");
    o.min = std::min(fo.lo / o.scaling, fo.hi / o.scaling);
    o.max = std::max(fo.lo / o.scaling, fo.hi / o.scaling);
    std::vector<FllTerm> terms = fo.terms;
    for (const auto& t : terms)
      if (t.shape != "Constant" || t.params.size() != 1)
        fail(t.line, "output term '" + t.name + "' must be 'Constant v' (eq. 5.1 uses the peaks of the output sets)");
    std::stable_sort(terms.begin(), terms.end(),
                     [&](const FllTerm& a, const FllTerm& b) { return a.params[0] / o.scaling < b.params[0] / o.scaling; });
    for (const auto& t : terms) {
      o.sets.push_back(t.name);
      o.positions.push_back(t.params[0] / o.scaling);
    }
  }
  // Rules: "if A is X and B is Y and C is Z then O is W [with w]".
  for (const auto& [line, text_rule] : rules) {
    const auto w = words(text_rule);
    auto bad = [&, line = line, &text_rule = text_rule](const std::string& why) {  // init-captures: clang < 16 cannot capture a structured binding
      fail(line, "rule '" + text_rule + "': " + why + " (expected: if <input> is <set> and ... then <output> is <set> [with w])");
    };
    if (w.size() < 8 || w[0] != "if") bad("too short");
    Rule r;
    r.in = {-1, -1, -1};
    size_t p = 1;
    for (int k = 0; k < kInputs; ++k) {
      if (p + 2 >= w.size() || w[p + 1] != "is") bad("expected '<input> is <set>'");
      int i = -1;
      for (int q = 0; q < kInputs; ++q)
        if (spec.inputs[q].name == w[p]) i = q;
      if (i < 0) bad("'" + w[p] + "' is not an input");
      if (r.in[i] >= 0) bad("input '" + w[p] + "' appears twice");
      r.in[i] = spec.inputs[i].index_of(w[p + 2]);
      if (r.in[i] < 0) bad("'" + w[p + 2] + "' is not a set of '" + w[p] + "' (hedges are not supported)");
      p += 3;
      const std::string want = k < kInputs - 1 ? "and" : "then";
      if (p >= w.size() || w[p] != want) bad("expected '" + want + "' after the " + std::to_string(k + 1) + ". proposition");
      ++p;
    }
    if (p + 3 > w.size() || w[p] != spec.output.name || w[p + 1] != "is") bad("expected '" + spec.output.name + " is <set>'");
    r.out = spec.output.index_of(w[p + 2]);
    if (r.out < 0) bad("'" + w[p + 2] + "' is not a set of '" + spec.output.name + "'");
    p += 3;
    if (p < w.size()) {
      if (w[p] != "with" || p + 2 != w.size()) bad("unexpected '" + w[p] + "'");
      r.weight = number(line, w[p + 1]);
    }
    spec.rules.push_back(r);
  }
  try {
    spec.validate();
  } catch (const std::invalid_argument& e) {
    fail(0, e.what());
  }
  return spec;
}

FlcSpec load_fll(const std::string& path) { return parse_fll(read_file(path), path); }
void save_fll(const FlcSpec& spec, const std::string& path) { write_file(path, to_fll(spec)); }

FlcSpec load_controller(const std::string& path) {
  const auto dot = path.rfind('.');
  const std::string ext = dot == std::string::npos ? "" : path.substr(dot + 1);
  if (ext == "fll") return load_fll(path);
  if (ext == "yaml" || ext == "yml") return load_yaml(path);
  throw std::runtime_error(path + ": unknown controller format (expected .yaml, .yml or .fll)");
}

FlcSpec thesis_initial() { return parse_yaml(thesis_initial_yaml(), "config/flc/initial.yaml (compiled in)"); }

}  // namespace aerie::flc
