#include "air/track/eval/folds.hpp"

#include <algorithm>
#include <stdexcept>

#include "air/track/eval/sequence.hpp"

namespace aerie::track::eval {
namespace {

Figures mean_over(const std::vector<Figures>& per_sequence, const std::vector<size_t>& which) {
  std::vector<Figures> f;
  for (size_t s : which) f.push_back(per_sequence[s]);
  return mean(f);
}

}  // namespace

std::vector<std::string> distinct_sequences(const std::vector<std::string>& names) {
  std::vector<std::string> distinct;
  for (const auto& s : names) distinct.push_back(base_name(s));
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  return distinct;
}

std::vector<int> assign_folds(const std::vector<std::string>& sequences, int k) {
  const std::vector<std::string> distinct = distinct_sequences(sequences);
  const int n = static_cast<int>(distinct.size());
  if (k < 2 || k > n)
    throw std::invalid_argument(std::to_string(k) + " folds for " + std::to_string(n) +
                                " sequences (need 2 <= folds <= sequences; folds = sequences is leave-one-out)");
  std::vector<int> fold(sequences.size());
  for (size_t i = 0; i < sequences.size(); ++i) {
    const auto rank = std::lower_bound(distinct.begin(), distinct.end(), base_name(sequences[i])) - distinct.begin();
    fold[i] = static_cast<int>(rank) % k;
  }
  return fold;
}

std::vector<FoldResult> cross_validate(const std::vector<std::vector<Figures>>& scores, const std::vector<int>& fold) {
  if (scores.empty()) throw std::invalid_argument("cross_validate: no candidates");
  for (const auto& c : scores)
    if (c.size() != fold.size())
      throw std::invalid_argument("cross_validate: " + std::to_string(c.size()) + " scores for " +
                                  std::to_string(fold.size()) + " sequences");
  const int k = fold.empty() ? 0 : *std::max_element(fold.begin(), fold.end()) + 1;
  std::vector<FoldResult> out;
  for (int f = 0; f < k; ++f) {
    FoldResult r;
    r.fold = f;
    for (size_t s = 0; s < fold.size(); ++s) (fold[s] == f ? r.heldout : r.tuned).push_back(s);
    if (r.tuned.empty() || r.heldout.empty())
      throw std::invalid_argument("cross_validate: fold " + std::to_string(f) +
                                  " leaves nothing to tune on or hold out");
    for (size_t c = 0; c < scores.size(); ++c) {
      const Figures t = mean_over(scores[c], r.tuned);
      if (c == 0 || t.auc > r.tuned_figures.auc) {
        r.candidate = static_cast<int>(c);
        r.tuned_figures = t;
      }
    }
    r.heldout_figures = mean_over(scores[r.candidate], r.heldout);
    out.push_back(r);
  }
  return out;
}

HeldOutSummary summarise(const std::vector<FoldResult>& folds, const std::vector<std::vector<Figures>>& scores) {
  HeldOutSummary h;
  std::vector<Figures> tuned, heldout;
  for (const auto& f : folds) {
    tuned.push_back(f.tuned_figures);
    for (size_t s : f.heldout) heldout.push_back(scores[f.candidate][s]);
  }
  h.sequences = static_cast<int>(heldout.size());
  h.tuned = mean(tuned);
  h.heldout = mean(heldout);
  return h;
}

}  // namespace aerie::track::eval
