#include "common/flc/prune.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>

namespace aerie::flc {
namespace {

// For each set of v, the index (in v) of the set it is merged into.
std::vector<int> merge_map(const Variable& v, const PruneOptions& options) {
  const int n = v.size();
  std::vector<int> keep(static_cast<size_t>(n));
  const auto& only = options.variables;
  if (!only.empty() && std::find(only.begin(), only.end(), v.name) == only.end()) {
    for (int k = 0; k < n; ++k) keep[static_cast<size_t>(k)] = k;
    return keep;
  }
  const double fraction = options.overlap_fraction;
  const double gap = fraction * (v.max - v.min) / std::max(1, n - 1);
  for (int first = 0; first < n;) {
    int last = first;
    while (last + 1 < n && v.positions[last + 1] - v.positions[last] < gap) ++last;
    int inner = first;  // the set of the cluster closest to zero
    for (int k = first; k <= last; ++k)
      if (std::abs(v.positions[k]) < std::abs(v.positions[inner])) inner = k;
    for (int k = first; k <= last; ++k) keep[static_cast<size_t>(k)] = inner;
    first = last + 1;
  }
  return keep;
}

// Removes the merged sets of v; returns old index -> new index of its kept set.
std::vector<int> apply(Variable& v, const std::vector<int>& keep, PruneReport& rep) {
  Variable out = v;
  out.sets.clear();
  out.positions.clear();
  std::vector<int> new_index(keep.size(), -1);
  for (int k = 0; k < v.size(); ++k)
    if (keep[static_cast<size_t>(k)] == k) {
      new_index[static_cast<size_t>(k)] = out.size();
      out.sets.push_back(v.sets[k]);
      out.positions.push_back(v.positions[k]);
    }
  for (int k = 0; k < v.size(); ++k) {
    const int kept = keep[static_cast<size_t>(k)];
    if (kept != k) rep.removed_sets.push_back(v.name + "." + v.sets[k] + " -> " + v.sets[kept]);
    new_index[static_cast<size_t>(k)] = new_index[static_cast<size_t>(kept)];
  }
  rep.sets_before += v.size();
  rep.sets_after += out.size();
  v = std::move(out);
  return new_index;
}

}  // namespace

FlcSpec prune(const FlcSpec& spec, const PruneOptions& options, PruneReport* report) {
  spec.validate();
  PruneReport rep;
  FlcSpec out = spec;
  std::array<std::vector<int>, kInputs> in_keep, in_index;
  for (int i = 0; i < kInputs; ++i) {
    in_keep[i] = merge_map(spec.inputs[i], options);
    in_index[i] = apply(out.inputs[i], in_keep[i], rep);
  }
  const auto out_index = apply(out.output, merge_map(spec.output, options), rep);
  out.rules.clear();
  for (const Rule& r : spec.rules) {
    bool removed = false;  // the rule of a removed input set goes with it
    Rule nr = r;
    for (int i = 0; i < kInputs; ++i) {
      removed = removed || in_keep[i][static_cast<size_t>(r.in[i])] != r.in[i];
      nr.in[i] = in_index[i][static_cast<size_t>(r.in[i])];
    }
    if (removed) continue;
    nr.out = out_index[static_cast<size_t>(r.out)];
    out.rules.push_back(nr);
  }
  rep.rules_before = static_cast<int>(spec.rules.size());
  rep.rules_after = static_cast<int>(out.rules.size());
  if (!out.id.empty()) out.id += "-pruned";
  out.validate();
  if (report) *report = rep;
  return out;
}

}  // namespace aerie::flc
