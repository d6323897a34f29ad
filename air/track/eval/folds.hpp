#pragma once
// k-fold cross-validation over sequences for choosing a tracker's settings without reporting
// on the data they were chosen on: per fold, the candidate with the best mean success AUC on
// the other folds' sequences (the tuned-on figures) is scored on the fold's own (held out).
#include <string>
#include <vector>

#include "air/track/eval/metrics.hpp"

namespace aerie::track::eval {

// The fold of sequences[i]: the rank of its base_name() among the distinct base names sorted
// (byte order) modulo k, so that the segments of one sequence (temporal_segments) share its
// fold, and k = the number of sequences is leave-one-sequence-out. Throws
// std::invalid_argument unless 2 <= k <= that number.
std::vector<int> assign_folds(const std::vector<std::string>& sequences, int k);
// The distinct base_name()s of the names, sorted (byte order): the sequences the folds split.
std::vector<std::string> distinct_sequences(const std::vector<std::string>& names);

struct FoldResult {
  int fold = 0;
  int candidate = 0;                   // the chosen one (best tuned AUC; ties -> the lower index)
  std::vector<size_t> tuned, heldout;  // sequence indices
  Figures tuned_figures;               // the candidate's mean over `tuned`
  Figures heldout_figures;             // and over `heldout`
};

// scores[c][s]: the figures of candidate c on sequence s; fold[s] from assign_folds (folds 0..k-1,
// none empty). One result per fold.
std::vector<FoldResult> cross_validate(const std::vector<std::vector<Figures>>& scores, const std::vector<int>& fold);

struct HeldOutSummary {
  int sequences = 0;
  Figures tuned;    // mean of the folds' tuned-on means
  Figures heldout;  // mean over the sequences of the figures each got when held out
};
HeldOutSummary summarise(const std::vector<FoldResult>& folds, const std::vector<std::vector<Figures>>& scores);

}  // namespace aerie::track::eval
