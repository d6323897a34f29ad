#pragma once
// The candidate settings of each tracker for aerie-bench-track --folds, from a grid file:
//   dcf:                        # a tracker name -> a list of candidates
//     - {}                      # the base settings (its section of -c, or its defaults)
//     - {learning_rate: 0.02}   # keys merged over the base settings
// A tracker the grid does not name has one candidate, its base settings.
#include <string>
#include <vector>

#include "common/util/config.hpp"

namespace aerie::track::eval {

struct Candidate {
  std::string settings;  // the candidate's own keys as one-line YAML ("{}" = the base settings)
  util::Config params;   // those keys merged over the tracker's base section
};

// Returns candidates[t] for trackers[t]. `base` holds the tracker sections (-c). Every
// candidate is built once with make_tracker, so a bad one fails here, before any tracking.
// Throws std::invalid_argument naming the file, the tracker and the candidate for: a grid that
// is not a map, an unknown tracker or one not in `trackers`, a tracker without a non-empty
// list of maps, and (make_tracker's message) a key the tracker does not know or a bad value.
std::vector<std::vector<Candidate>> load_grid(const util::Config& grid, const util::Config& base,
                                              const std::vector<std::string>& trackers);

}  // namespace aerie::track::eval
