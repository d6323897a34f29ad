#include "air/track/eval/grid.hpp"

#include <algorithm>
#include <stdexcept>

#include "air/track/factory.hpp"

namespace aerie::track::eval {
namespace {

std::string flow(const YAML::Node& n) {
  YAML::Emitter e;
  e << YAML::Flow << n;
  return e.c_str();
}

Candidate make_candidate(const YAML::Node& keys, const util::Config& base, const std::string& origin) {
  const YAML::Node own = keys.IsNull() ? YAML::Node(YAML::NodeType::Map) : keys;
  if (!own.IsMap()) throw std::invalid_argument(origin + ": a candidate is a map of parameters, e.g. {lambda: 0.01}");
  YAML::Node merged = base.node().IsMap() ? YAML::Clone(base.node()) : YAML::Node(YAML::NodeType::Map);
  for (const auto& kv : own) merged[kv.first.as<std::string>()] = kv.second;
  return {flow(own), util::Config::parse(YAML::Dump(merged), origin)};
}

}  // namespace

std::vector<std::vector<Candidate>> load_grid(const util::Config& grid, const util::Config& base,
                                              const std::vector<std::string>& trackers) {
  const YAML::Node& root = grid.node();
  if (root && !root.IsNull() && !root.IsMap())
    throw std::invalid_argument(grid.origin() + ": expected a map of tracker name -> list of candidate settings");
  if (root.IsMap())
    for (const auto& kv : root) {
      const auto name = kv.first.as<std::string>();
      if (!is_known_tracker(name)) throw std::invalid_argument(grid.origin() + ": unknown tracker '" + name + "'");
      if (std::find(trackers.begin(), trackers.end(), name) == trackers.end())
        throw std::invalid_argument(grid.origin() + ": tracker '" + name + "' is not among the trackers run");
      if (!kv.second.IsSequence() || kv.second.size() == 0)
        throw std::invalid_argument(grid.origin() + ":" + name + ": expected a non-empty list of candidate settings");
    }
  std::vector<std::vector<Candidate>> out;
  for (const auto& t : trackers) {
    const util::Config section = base.section(t);
    std::vector<Candidate> list;
    if (!grid.has(t)) {
      list.push_back({"{}", section});
    } else {
      const YAML::Node candidates = grid.node()[t];
      for (size_t c = 0; c < candidates.size(); ++c)
        list.push_back(make_candidate(candidates[c], section, grid.origin() + ":" + t + "[" + std::to_string(c) + "]"));
    }
    for (const auto& c : list) {
      try {
        make_tracker(t, c.params);
      } catch (const std::exception& e) {
        throw std::invalid_argument(e.what());
      }
    }
    out.push_back(std::move(list));
  }
  return out;
}

}  // namespace aerie::track::eval
