#pragma once
// The study over MPI ranks (internal to tools/study): rank 0 coordinates, writes and flies runs
// on a thread of its own; every other rank asks for the next run when it is free.
#include "tools/study/study.hpp"

namespace aerie::study {

Outcome coordinate(const Study& study, const Options& options, const Session& session);  // rank 0
Outcome serve(const Study& study, const Session& session);                                 // ranks 1..N-1

}  // namespace aerie::study
