// The study on threads (each takes the next index when it is free), and
// the choice between threads and MPI ranks.
#include "tools/study/study.hpp"

#include <cstdio>
#include <exception>
#include <mutex>

#include "common/util/parallel.hpp"
#include "tools/study/journal.hpp"
#include "tools/study/mpi_study.hpp"

namespace aerie::study {

Record run_one(const Study& study, int index) {
  try {
    Record r = study.run(index);
    if (r.failed()) r.rows.clear();
    return r;
  } catch (const std::exception& e) {
    Record r;
    r.error = e.what();
    if (r.error.empty()) r.error = "exception without a message";
    return r;
  }
}

namespace {

Outcome run_threads(const Study& study, const Options& options) {
  Journal journal(study, options.resume);
  std::vector<int> todo;
  for (int i = 0; i < study.runs; ++i)
    if (!journal.done(i)) todo.push_back(i);
  std::mutex mutex;
  std::exception_ptr write_error;
  size_t next = 0;  // into todo: indices are taken in order, so once stop() says so none after them has started
  util::parallel_for(options.jobs, options.jobs, [&](int) {
    for (;;) {
      int index;
      {
        std::lock_guard lock(mutex);
        if (write_error || next == todo.size() || (study.stop && study.stop())) return;
        index = todo[next++];
      }
      Record r = run_one(study, index);
      std::lock_guard lock(mutex);
      if (write_error) return;
      try {
        journal.complete(index, std::move(r));
      } catch (...) {
        write_error = std::current_exception();
      }
    }
  });
  if (write_error) std::rethrow_exception(write_error);
  return Outcome{true, static_cast<int>(next), journal.resumed(), journal.failed()};
}

}  // namespace

Outcome run(const Study& study, const Options& options, const Session& session) {
  if (study.runs < 0) throw std::invalid_argument(study.tool + ": a study needs runs >= 0");
  if (options.jobs < 1) throw std::invalid_argument(study.tool + ": --jobs must be at least 1");
  if (!(options.rank_timeout_s > 0)) throw std::invalid_argument(study.tool + ": --rank-timeout must be positive");
  if (session.distributed()) return session.rank() == 0 ? coordinate(study, options, session) : serve(study, session);
  return run_threads(study, options);
}

Outcome run_or_exit(const Study& study, const Options& options, const Session& session) {
  try {
    return run(study, options, session);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    session.abort(1);
  }
}

}  // namespace aerie::study
