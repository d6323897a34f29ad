#pragma once
// Order statistics of a sample (latencies, delays), percentiles by linear
// interpolation between closest ranks (as numpy's default).
#include <cstdint>
#include <vector>

namespace aerie::latency {

struct Summary {
  int64_t count = 0;
  double min = 0, mean = 0, median = 0, p90 = 0, p99 = 0, max = 0;
};

Summary summarize(std::vector<double> values);
// q in [0, 1]; `sorted` must be sorted ascending and non-empty.
double percentile_sorted(const std::vector<double>& sorted, double q);
// The same for any non-empty sample.
double percentile(std::vector<double> values, double q);

}  // namespace aerie::latency
