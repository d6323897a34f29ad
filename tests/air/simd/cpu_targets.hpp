#pragma once
// The Highway targets this CPU runs and the kernels were compiled for, best first (read before
// any test mocks the supported set), shared by the dispatch and the vector-vs-scalar tests.
#include <hwy/targets.h>

#include <cstdint>
#include <vector>

inline const std::vector<int64_t>& cpu_targets() {
  static const std::vector<int64_t> targets = [] {
    hwy::SetSupportedTargetsForTest(0);
    return hwy::SupportedAndGeneratedTargets();
  }();
  return targets;
}
