#pragma once
// Set and rule reduction after membership-function optimisation (thesis 5.1.5,
// Figs. 5.26-5.29, Tables 5.6-5.8): adjacent sets whose peaks nearly coincide are
// merged into the innermost of them (the one CE moved there); an input set's rules go
// with it, rules that pointed to a removed output set point to the kept one.
#include <string>
#include <vector>

#include "common/flc/flc.hpp"

namespace aerie::flc {

struct PruneOptions {
  // Two adjacent sets overlap when their peaks are closer than this fraction of the
  // variable's even spacing (range / (sets - 1)).
  double overlap_fraction = 0.1;
  // Variables whose sets may be merged; empty = all four.
  std::vector<std::string> variables;
};

struct PruneReport {
  std::vector<std::string> removed_sets;  // "<variable>.<set> -> <kept set>"
  int rules_before = 0, rules_after = 0;
  int sets_before = 0, sets_after = 0;    // over all four variables
};

FlcSpec prune(const FlcSpec& spec, const PruneOptions& options = {}, PruneReport* report = nullptr);

}  // namespace aerie::flc
