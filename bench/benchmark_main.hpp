#pragma once
// main() of a Google Benchmark executable in Aerie's shape: `--help` prints a description line
// and Google Benchmark's flags (exit 0), an unknown option is refused in one line (exit 2).
#include <benchmark/benchmark.h>

#include <cstdio>

namespace aerie::bench {

inline int benchmark_main(int argc, char** argv, const char* name, const char* description) {
  static const char* n = name;
  static const char* d = description;
  benchmark::Initialize(&argc, argv, [] {
    std::printf("%s: %s\nOptions (Google Benchmark's):\n", n, d);
    benchmark::PrintDefaultHelp();
  });
  if (argc > 1) {
    std::fprintf(stderr, "%s: unknown option '%s' (see --help)\n", name, argv[1]);
    return 2;
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

}  // namespace aerie::bench
