// study-probe: a study of trivial runs over tools/study, for the tests: threads, or MPI ranks
// under mpirun; a rank that hangs or dies on its first run (--hang-rank, --die-rank).
//   study-probe --runs N --out DIR | --resume DIR [--jobs J] [--sleep-ms MS] [--rank-timeout S]
//               [--hang-rank R] [--die-rank R] [--fail-run I]
// Run i writes "i,i*i/7" to rows.csv and, for even i, two rows to pairs.csv; it sleeps
// MS x (1 + (5 i) mod 3) ms first, so that runs finish out of index order.
#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <sstream>
#include <thread>

#include "tools/study/study.hpp"

using namespace aerie;

int main(int argc, char** argv) {
  study::Session session(argc, argv);
  CLI::App app{"study-probe: a study of trivial runs (tools/study) for the tests: threads, or MPI ranks under mpirun"};
  int runs = 8, jobs = 1, sleep_ms = 0, hang_rank = -1, die_rank = -1, fail_run = -1;
  double rank_timeout_s = 600;
  std::string out_dir, resume_dir;
  auto* out = app.add_option("--out", out_dir, "output folder (rows.csv, pairs.csv, study.progress)");
  app.add_option("--resume", resume_dir, "continue the study in this folder")->excludes(out);
  app.add_option("--runs", runs, "number of runs")->check(CLI::NonNegativeNumber);
  app.add_option("--jobs", jobs, "threads without MPI")->check(CLI::Range(1, 64));
  app.add_option("--sleep-ms", sleep_ms, "base time of a run in ms")->check(CLI::NonNegativeNumber);
  app.add_option("--rank-timeout", rank_timeout_s, "under MPI: seconds a rank may take over a run")->check(CLI::PositiveNumber);
  app.add_option("--hang-rank", hang_rank, "this rank hangs on its first run");
  app.add_option("--die-rank", die_rank, "this rank kills itself (SIGKILL) on its first run");
  app.add_option("--fail-run", fail_run, "this run throws");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = session.rank() == 0 ? app.exit(e) : e.get_exit_code();  // the help or the error, once
    return rc == 0 ? 0 : 2;
  }
  if (out_dir.empty() == resume_dir.empty()) {
    std::fprintf(stderr, "study-probe: give --out DIR or --resume DIR\n");
    return 2;
  }
  bool first = true;
  std::atomic<long> slept_ms{0};  // by this process's runs
  study::Study st;
  st.tool = "study-probe";
  st.dir = resume_dir.empty() ? out_dir : resume_dir;
  st.runs = runs;
  st.outputs = {{"rows.csv", "index,value\n"}, {"pairs.csv", "index,half\n"}};
  st.definition = "runs=" + std::to_string(runs);
  st.run = [&](int i) {
    if (first && session.rank() == hang_rank) std::this_thread::sleep_for(std::chrono::hours(1));
    if (first && session.rank() == die_rank) std::raise(SIGKILL);
    first = false;
    std::this_thread::sleep_for(std::chrono::milliseconds(sleep_ms * (1 + (5 * i) % 3)));
    slept_ms += sleep_ms * (1 + (5 * i) % 3);
    if (i == fail_run) throw std::runtime_error("asked to fail");
    std::ostringstream row, pairs;
    row << i << ',' << i * i / 7.0 << '\n';
    if (i % 2 == 0) pairs << i << ",a\n" << i << ",b\n";
    return study::Record{{row.str(), pairs.str()}, "note" + std::to_string(i), ""};
  };
  st.describe = [](int i) { return "run " + std::to_string(i); };
  int written = 0;
  st.on_written = [&](int i, const study::Record& r) {
    if (r.note != "note" + std::to_string(i) && !r.failed()) {
      std::fprintf(stderr, "study-probe: run %d has note '%s'\n", i, r.note.c_str());
      std::exit(3);
    }
    ++written;
  };
  study::Options options{jobs, !resume_dir.empty(), rank_timeout_s};
  try {
    const study::Outcome o = study::run(st, options, session);
    if (!o.writer) {
      std::printf("rank %d flew %d slept %ld ms\n", session.rank(), o.flown, slept_ms.load());
      return 0;
    }
    std::printf("flown %d resumed %d failed %d written %d ranks %d slept %ld ms\n", o.flown, o.resumed, o.failed, written,
                session.size(), slept_ms.load());
    return o.failed ? 1 : 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    session.abort(1);
  }
}
