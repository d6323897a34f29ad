#pragma once
// What the study tests read back (a whole file, its lines, a CSV without its wall-clock
// column) and how they start the executables (alone or under mpirun with two ranks).
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/integration/process.hpp"

namespace aerie::test {

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline std::vector<std::string> lines(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream in(s);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

// The CSV's lines without the column named `column` in its header (e.g. wall_s).
inline std::vector<std::string> without_column(const std::filesystem::path& csv, const std::string& column = "wall_s") {
  std::vector<std::string> out;
  int skip = -1;
  for (const auto& l : lines(slurp(csv))) {
    std::vector<std::string> cells;
    std::istringstream in(l);
    for (std::string c; std::getline(in, c, ',');) cells.push_back(c);
    if (skip < 0) skip = static_cast<int>(std::find(cells.begin(), cells.end(), column) - cells.begin());
    std::string row;
    for (size_t k = 0; k < cells.size(); ++k)
      if (static_cast<int>(k) != skip) row += cells[k] + ",";
    out.push_back(row);
  }
  return out;
}

// Runs cmd (stdout and stderr to log); its exit status, -1 when it did not end in time.
inline int run(const std::vector<std::string>& cmd, const std::filesystem::path& log, double timeout_s = 120) {
  Process p(cmd, log);
  const auto status = p.wait(timeout_s);
  return status ? *status : -1;
}

// cmd under `mpirun -np 2`, as the tests run it (root, two ranks on two cores or fewer).
inline std::vector<std::string> two_ranks(const std::string& mpiexec, const std::vector<std::string>& cmd) {
  std::vector<std::string> out{mpiexec, "-np", "2", "--oversubscribe", "--allow-run-as-root"};
  out.insert(out.end(), cmd.begin(), cmd.end());
  return out;
}

// base + extra, then `--out out` unless extra resumes (`--resume DIR`).
inline std::vector<std::string> with_out(std::vector<std::string> base, const std::vector<std::string>& extra,
                                         const std::filesystem::path& out) {
  base.insert(base.end(), extra.begin(), extra.end());
  if (std::find(extra.begin(), extra.end(), "--resume") == extra.end()) {
    base.push_back("--out");
    base.push_back(out.string());
  }
  return base;
}

// SIGKILL to p once `ready` says so (polled every 10 ms, for timeout_s at most); its exit status.
inline std::optional<int> kill_when(Process& p, const std::function<bool()>& ready, double timeout_s = 90) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!ready() && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  p.signal(SIGKILL);
  return p.wait(10);
}

}  // namespace aerie::test
