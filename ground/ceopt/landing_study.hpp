#pragma once
// aerie-ceopt landing's landings as studies (tools/study, docs/scale.md): each batch that
// tune_landing asks for — the initial gains on the training seeds, one CE iteration's candidates
// x their training seeds, the validation — is one study, spread over the MPI ranks when mpirun
// started aerie-ceopt (rank 0 samples, updates and writes; the other ranks fly what it hands
// out), and journaled in DIR/batch-NNN/ (study.progress, landings.csv) so that a --resume flies
// only the landings that are not in the journals yet.
#include <string>

#include "ground/ceopt/landing_tuning.hpp"
#include "tools/study/study.hpp"

namespace aerie::ceopt {

struct LandingStudyOptions {
  std::string dir;              // the batches' folders go here (aerie-ceopt: OUT/studies)
  bool resume = false;          // continue each batch from its journal where there is one
  int jobs = 1;                 // threads, without MPI
  double rank_timeout_s = 600;  // MPI: a rank that does not return its landing within this ends the tuning
};

// On rank 0 (or without MPI): the flier for tune_landing. Each call tells the other ranks the
// batch, flies it as a study and returns its runs; throws std::runtime_error when a landing
// failed (naming it) and study::RankLost when a rank is lost.
LandingFlier landing_study_flier(const LandingTuning& problem, const LandingStudyOptions& options,
                                 const study::Session& session);
// On rank 0 at the end (also after an error it can recover from): no more batches.
void end_landing_studies(const study::Session& session);
// On ranks 1..N-1: fly the batches rank 0 hands out until it ends them.
void serve_landing_studies(const LandingTuning& problem, const study::Session& session);

}  // namespace aerie::ceopt
