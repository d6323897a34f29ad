#pragma once
// A study: N indexed runs, each a function from its index to CSV rows, flown on threads or,
// when the program was started by mpirun (or srun) with more than one rank, over MPI ranks with
// dynamic hand-out (docs/scale.md). Rows reach the output files in index order whatever order
// the runs finished in, each run's rows flushed as soon as it and every run before it are
// complete; a journal next to them (DIR/study.progress) makes a partial study resumable.
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace aerie::study {

// What one run produced.
struct Record {
  std::vector<std::string> rows;  // per output file, its rows ('\n'-terminated), possibly empty
  std::string note;               // kept in the journal and handed to on_written, written to no file
  std::string error;              // non-empty: the run failed (it threw) and has no rows
  bool failed() const { return !error.empty(); }
};

struct Output {
  std::string name;    // file name in the study folder
  std::string header;  // its first line(s), '\n'-terminated
};

struct Study {
  std::string tool;                 // prefix of every message, e.g. "aerie-bench-landing"
  std::string dir;                  // output folder (created)
  int runs = 0;
  std::vector<Output> outputs;
  // What defines the runs (their options, not --jobs or --out): a resumed study must match.
  std::string definition;
  std::function<Record(int)> run;   // a run that throws fails: its error is its Record's
  std::function<std::string(int)> describe;  // for messages: "run with seed 5"
  // On the writing process, once per run in index order, when its rows are written; runs
  // resumed from the journal come first, with their note and error but no rows.
  std::function<void(int, const Record&)> on_written;
  // Optional, polled on the writing process: once it returns true no run is started any more
  // (Ctrl-C); the runs under way finish and are written, the study stays resumable.
  std::function<bool()> stop;
};

struct Options {
  int jobs = 1;                // threads, without MPI
  bool resume = false;         // continue the study in `dir` from its journal
  double rank_timeout_s = 600; // MPI: a rank that does not return its run within this ends the study
};

struct Outcome {
  bool writer = true;          // false on MPI ranks other than 0 (they wrote nothing)
  int flown = 0, resumed = 0, failed = 0;  // failed: resumed failures included
};

// Thrown (on rank 0) when a rank is lost; what() names the rank, its host and the lost runs.
// The caller must then end every rank: Session::abort.
struct RankLost : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// MPI for the life of the program, only when it was started by a launcher: Open MPI's mpirun
// sets OMPI_COMM_WORLD_SIZE, PMIx (srun --mpi=pmix) PMIX_RANK, MPICH/Hydra PMI_SIZE. Without
// them MPI is never initialised and the program runs exactly as without MPI. Construct it first
// in main, before any thread starts.
class Session {
 public:
  Session(int& argc, char**& argv);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
  static bool launched();     // the environment says a launcher started this process
  bool distributed() const { return size_ > 1; }
  int rank() const { return rank_; }
  int size() const { return size_; }
  [[noreturn]] void abort(int code) const;  // MPI_Abort under MPI, else exit(code)
  // Rank 0's `bytes` on every rank (MPI_Bcast; every rank must call it at the same point, outside
  // a study): how a program that runs studies one after another (aerie-ceopt: one per CE
  // iteration) tells the other ranks what the next one is. Without MPI, `bytes` itself.
  std::string broadcast(const std::string& bytes) const;

 private:
  bool mpi_ = false;
  int rank_ = 0, size_ = 1;
};

// Runs the study: over the session's ranks when it is distributed, else on `jobs` threads.
// Throws std::runtime_error when the folder cannot be written or does not resume (naming the
// file and what differs), RankLost when a rank is lost.
Outcome run(const Study& study, const Options& options, const Session& session);

// run() as a program's main calls it: an error is printed (its what()) and ends every rank
// with status 1 (Session::abort); the ranks that wrote nothing get writer == false.
Outcome run_or_exit(const Study& study, const Options& options, const Session& session);

// The run's Record, its exception caught into `error`.
Record run_one(const Study& study, int index);

}  // namespace aerie::study
