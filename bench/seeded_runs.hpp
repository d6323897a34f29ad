#pragma once
// Seeded closed-loop runs on a few threads, as the lock-step benches fly them: run i has seed
// `seed + i` and its own slot, so the results do not depend on the number of threads.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>
#include <mutex>
#include <vector>

#include "common/util/parallel.hpp"

namespace aerie::bench {

// fly(seed) -> Result for seed, seed + 1, ..., seed + runs - 1 on `jobs` threads. A run that
// throws is reported on stderr with its seed (as "<tool>: run with seed S failed: why") and
// counted in `failures`; its slot keeps a default Result.
template <class Result, class Fly>
std::vector<Result> run_seeded(int runs, int jobs, uint64_t seed, const char* tool, Fly fly, int& failures) {
  std::vector<Result> results(static_cast<size_t>(runs));
  std::mutex err_mutex;
  util::parallel_for(runs, jobs, [&](int i) {
    const uint64_t s = seed + static_cast<uint64_t>(i);
    try {
      results[static_cast<size_t>(i)] = fly(s);
    } catch (const std::exception& e) {
      std::lock_guard lk(err_mutex);
      std::fprintf(stderr, "%s: run with seed %llu failed: %s\n", tool, static_cast<unsigned long long>(s), e.what());
      ++failures;
    }
  });
  return results;
}

// The end of a bench: its plot script over the output folder (when asked and present, from the
// repository root), the number of failed runs; the exit status (1 when a run failed).
inline int finish(const char* tool, const std::string& plot_script, const std::string& out_dir, bool plots, int failures) {
  if (plots && std::filesystem::exists(plot_script)) {
    const std::string cmd = "/usr/bin/python3 " + plot_script + " " + out_dir;
    if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "%s: plotting failed (%s)\n", tool, cmd.c_str());
  }
  if (failures) std::fprintf(stderr, "%s: %d runs failed (no row for them)\n", tool, failures);
  return failures ? 1 : 0;
}

}  // namespace aerie::bench
