#pragma once
// The end of the seeded lock-step benches (their runs are studies: tools/study).
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace aerie::bench {

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
