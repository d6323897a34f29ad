// Dynamic hand-out over MPI (docs/scale.md). Protocol, on MPI_COMM_WORLD:
//   worker -> 0  kHello   its processor name, once
//   0 -> worker  kWork    the index of its next run (one int), or kStop
//   worker -> 0  kResult  the run's Record (index, note, error, rows), then waits for kWork
// Rank 0 polls with MPI_Iprobe, so that it notices a worker that has not answered within
// --rank-timeout; errors return (MPI_ERRORS_RETURN) rather than abort. Only this thread calls
// MPI (MPI_THREAD_FUNNELED): rank 0's own runs fly on a second thread that takes indices from
// the same queue.
#include <mpi.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <mutex>
#include <thread>

#include "tools/study/journal.hpp"
#include "tools/study/mpi_study.hpp"

namespace aerie::study {

namespace {

constexpr int kHello = 1, kWork = 2, kStop = 3, kResult = 4;
using Clock = std::chrono::steady_clock;

volatile std::sig_atomic_t g_terminated = 0;
extern "C" void on_terminate(int) { g_terminated = 1; }

// A Record as bytes (the ranks of one job share the byte order): int32 index, then note, error
// and each output's rows as uint64 length + bytes.
void put_u64(std::string& out, uint64_t v) { out.append(reinterpret_cast<const char*>(&v), sizeof v); }
std::string encode(int index, const Record& r) {
  std::string out(reinterpret_cast<const char*>(&index), sizeof index);
  put_u64(out, r.rows.size());
  for (const std::string* s : {&r.note, &r.error}) {
    put_u64(out, s->size());
    out += *s;
  }
  for (const auto& rows : r.rows) {
    put_u64(out, rows.size());
    out += rows;
  }
  return out;
}
Record decode(const std::string& in, int source, int& index) {
  size_t at = 0;
  auto take = [&](void* dst, size_t n) {
    if (in.size() - at < n)
      throw std::runtime_error("study: result from rank " + std::to_string(source) + " is truncated (" +
                               std::to_string(in.size()) + " bytes)");
    std::memcpy(dst, in.data() + at, n);
    at += n;
  };
  auto take_string = [&] {
    uint64_t n = 0;
    take(&n, sizeof n);
    std::string s(static_cast<size_t>(std::min<uint64_t>(n, in.size())), '\0');
    take(s.data(), static_cast<size_t>(n));
    return s;
  };
  uint64_t count = 0;
  take(&index, sizeof index);
  take(&count, sizeof count);
  Record r;
  r.note = take_string();
  r.error = take_string();
  for (uint64_t k = 0; k < count && k < in.size(); ++k) r.rows.push_back(take_string());
  return r;
}

std::string processor_name() {
  char name[MPI_MAX_PROCESSOR_NAME] = {};
  int len = 0;
  if (MPI_Get_processor_name(name, &len) != MPI_SUCCESS) return "unknown host";
  return std::string(name, static_cast<size_t>(len));
}

struct Worker {
  std::string host = "host not reported";
  int index = -1;  // the run it flies
  bool stopped = false, lost = false;
  Clock::time_point since;
};

}  // namespace

Outcome coordinate(const Study& study, const Options& options, const Session& session) {
  Journal journal(study, options.resume);
  std::mutex mutex;  // todo, stopping, local_*
  std::deque<int> todo;
  for (int i = 0; i < study.runs; ++i)
    if (!journal.done(i)) todo.push_back(i);
  const int not_resumed = static_cast<int>(todo.size());
  bool stopping = false;
  std::vector<std::pair<int, Record>> local_done;
  int local_index = -1;
  std::atomic<bool> local_finished{false};
  const std::string host0 = processor_name();

  std::signal(SIGTERM, on_terminate);
  std::thread local([&] {
    for (;;) {
      int i;
      {
        std::lock_guard lock(mutex);
        if (stopping || todo.empty()) break;
        i = local_index = todo.front();
        todo.pop_front();
      }
      Record r = run_one(study, i);
      std::lock_guard lock(mutex);
      local_done.emplace_back(i, std::move(r));
      local_index = -1;
    }
    local_finished = true;
  });

  std::vector<Worker> workers(static_cast<size_t>(session.size()));
  for (auto& w : workers) w.since = Clock::now();
  const auto timeout = std::chrono::duration<double>(options.rank_timeout_s);
  std::string lost;  // what the error says about the lost ranks
  auto where = [&](int rank) {
    return "rank " + std::to_string(rank) + " (" + (rank == 0 ? host0 : workers[static_cast<size_t>(rank)].host) + ")";
  };
  auto lose = [&](int rank, const std::string& why) {
    Worker& w = workers[static_cast<size_t>(rank)];
    w.lost = true;
    lost += "\n  " + where(rank) + " " + why +
            (w.index >= 0 ? "; lost: " + study.describe(w.index) : std::string("; it held no run"));
    std::lock_guard lock(mutex);
    stopping = true;
  };
  auto not_started = [&] {
    std::lock_guard lock(mutex);
    return todo.size();
  };
  int flown = 0;
  try {
    for (;;) {
      if (g_terminated) {
        std::string inflight;
        {
          std::lock_guard lock(mutex);
          if (local_index >= 0) inflight += "\n  " + study.describe(local_index) + " on " + where(0);
        }
        for (size_t r = 1; r < workers.size(); ++r)
          if (workers[r].index >= 0) inflight += "\n  " + study.describe(workers[r].index) + " on " + where(static_cast<int>(r));
        std::fprintf(stderr,
                     "%s: stopped by SIGTERM (mpirun ends the job so when a rank dies, naming the rank and its host; a "
                     "scheduler at its time limit too). Runs in flight, lost:%s\n%zu runs not started. The finished runs "
                     "are in %s: continue with --resume %s\n",
                     study.tool.c_str(), inflight.empty() ? " none" : inflight.c_str(), not_started(), study.dir.c_str(),
                     study.dir.c_str());
        std::fflush(stderr);
        std::_Exit(128 + SIGTERM);  // every finished run is flushed; rank 0's own run cannot be waited for
      }
      if (study.stop && study.stop()) {  // no run is handed out any more; those under way finish
        std::lock_guard lock(mutex);
        stopping = true;
      }
      bool busy = false;
      int flag = 0;
      MPI_Status status;
      if (MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status) != MPI_SUCCESS)
        throw RankLost(study.tool + ": MPI_Iprobe failed on rank 0 (" + host0 + ")");
      if (flag) {
        busy = true;
        const int source = status.MPI_SOURCE;
        Worker& w = workers[static_cast<size_t>(source)];
        int count = 0;
        MPI_Get_count(&status, MPI_BYTE, &count);
        std::string bytes(static_cast<size_t>(std::max(count, 0)), '\0');
        if (MPI_Recv(bytes.data(), count, MPI_BYTE, source, status.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE) != MPI_SUCCESS) {
          lose(source, "failed while sending its result");
        } else if (!w.lost) {  // a rank given up for lost stays lost, even if it answers late
          if (status.MPI_TAG == kHello) {
            w.host = bytes;
          } else if (status.MPI_TAG == kResult) {
            int index = -1;
            Record r = decode(bytes, source, index);
            if (index != w.index)
              throw RankLost(study.tool + ": " + where(source) + " returned run " + std::to_string(index) +
                             ", it was given run " + std::to_string(w.index));
            w.index = -1;
            journal.complete(index, std::move(r));
            ++flown;
          }
          int next = -1;
          {
            std::lock_guard lock(mutex);
            if (!stopping && !todo.empty()) {
              next = todo.front();
              todo.pop_front();
            }
          }
          const int rc = MPI_Send(&next, 1, MPI_INT, source, next >= 0 ? kWork : kStop, MPI_COMM_WORLD);
          if (next >= 0) {
            w.index = next;
            w.since = Clock::now();
          } else {
            w.stopped = true;
          }
          if (rc != MPI_SUCCESS) lose(source, "could not be reached");
        }
      }
      {
        std::vector<std::pair<int, Record>> done;
        {
          std::lock_guard lock(mutex);
          done.swap(local_done);
        }
        for (auto& [index, r] : done) {
          journal.complete(index, std::move(r));
          ++flown;
          busy = true;
        }
      }
      bool all = local_finished.load();
      const auto now = Clock::now();
      for (size_t r = 1; r < workers.size(); ++r) {
        Worker& w = workers[r];
        if (w.stopped || w.lost) continue;
        if (now - w.since > timeout) {
          char why[160];
          std::snprintf(why, sizeof why, "has not answered for %.0f s (--rank-timeout)", options.rank_timeout_s);
          lose(static_cast<int>(r), why);
        } else {
          all = false;
        }
      }
      if (all) {
        std::lock_guard lock(mutex);
        if (local_done.empty()) break;
      }
      if (!busy) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  } catch (...) {
    {
      std::lock_guard lock(mutex);
      stopping = true;
    }
    local.join();
    throw;
  }
  local.join();
  if (!lost.empty())
    throw RankLost(study.tool + ": the study stops, ranks lost:" + lost + "\n" + std::to_string(not_started()) +
                   " runs not started. The finished runs are in " + study.dir + ": continue with --resume " + study.dir);
  return Outcome{true, flown, study.runs - not_resumed, journal.failed()};
}

Outcome serve(const Study& study, const Session& session) {
  const std::string host = processor_name();
  auto check = [&](int rc, const char* what) {
    if (rc != MPI_SUCCESS)
      throw std::runtime_error(study.tool + ": rank " + std::to_string(session.rank()) + " (" + host + "): " + what +
                               " rank 0 failed");
  };
  check(MPI_Send(host.data(), static_cast<int>(host.size()), MPI_BYTE, 0, kHello, MPI_COMM_WORLD), "reporting to");
  Outcome outcome{false, 0, 0, 0};
  for (;;) {
    int index = -1;
    MPI_Status status;
    check(MPI_Recv(&index, 1, MPI_INT, 0, MPI_ANY_TAG, MPI_COMM_WORLD, &status), "receiving work from");
    if (status.MPI_TAG == kStop) break;
    const Record r = run_one(study, index);
    outcome.failed += r.failed();
    const std::string bytes = encode(index, r);
    check(MPI_Send(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, 0, kResult, MPI_COMM_WORLD), "sending a result to");
    ++outcome.flown;
  }
  return outcome;
}

bool Session::launched() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"})
    if (std::getenv(v)) return true;
  return false;
}

Session::Session(int& argc, char**& argv) {
  if (!launched()) return;
  int provided = 0;
  if (MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS)
    throw std::runtime_error("MPI_Init_thread failed (started by a launcher: OMPI_COMM_WORLD_SIZE, PMIX_RANK or PMI_SIZE is set)");
  mpi_ = true;
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

Session::~Session() {
  if (mpi_) MPI_Finalize();
}

std::string Session::broadcast(const std::string& bytes) const {
  if (!mpi_ || size_ < 2) return bytes;
  uint64_t size = bytes.size();
  if (MPI_Bcast(&size, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD) != MPI_SUCCESS)
    throw std::runtime_error("study: MPI_Bcast failed on rank " + std::to_string(rank_));
  std::string out = rank_ == 0 ? bytes : std::string(static_cast<size_t>(size), '\0');
  for (uint64_t at = 0; at < size;) {  // MPI counts are int: in pieces of 1 GiB
    const int n = static_cast<int>(std::min<uint64_t>(size - at, uint64_t{1} << 30));
    if (MPI_Bcast(out.data() + at, n, MPI_BYTE, 0, MPI_COMM_WORLD) != MPI_SUCCESS)
      throw std::runtime_error("study: MPI_Bcast failed on rank " + std::to_string(rank_));
    at += static_cast<uint64_t>(n);
  }
  return out;
}

void Session::abort(int code) const {
  std::fflush(stdout);
  std::fflush(stderr);
  if (mpi_) MPI_Abort(MPI_COMM_WORLD, code);
  std::exit(code);
}

}  // namespace aerie::study
