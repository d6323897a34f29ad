// Highway's run-time dispatch of the air side's SIMD kernels, as built into the product libraries
// (docs/arm.md): which target each kernel file takes on this CPU, logged, and that it is a vector
// target (aarch64: NEON or SVE/SVE2; x86: SSE4, AVX2 or AVX-512), never the scalar fallback.
// test_simd_targets.cpp checks that every target gives the scalar path's results.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <iostream>
#include <set>
#include <string>
#include <vector>

#include "air/stereo/sgbm_ctf/sgm.hpp"
#include "air/track/features/kernels.hpp"

#include "tests/air/simd/cpu_targets.hpp"

namespace {

std::string names(const std::vector<int64_t>& targets) {
  std::string s;
  for (int64_t t : targets) s += (s.empty() ? "" : " ") + std::string(hwy::TargetName(t));
  return s;
}

const std::set<std::string>& vector_targets() {
#if defined(__aarch64__)
  static const std::set<std::string> s{"NEON", "SVE", "SVE2", "SVE_256", "SVE2_128"};
#elif defined(__arm__)
  static const std::set<std::string> s{"NEON"};
#elif defined(__x86_64__) || defined(__i386__)
  static const std::set<std::string> s{"SSE4", "AVX2", "AVX3", "AVX3_DL"};
#else
  static const std::set<std::string> s{};
#endif
  return s;
}

const char* arch_name() {
#if defined(__aarch64__)
  return "aarch64";
#elif defined(__arm__)
  return "arm";
#elif defined(__x86_64__)
  return "x86_64";
#else
  return "other";
#endif
}

}  // namespace

TEST(SimdDispatch, EveryKernelTakesAVectorTarget) {
  const std::string stereo = aerie::stereo::SemiGlobalMatcher::simd_target();
  const std::string track = aerie::track::kernels::target_name();
  const std::vector<int64_t> cpu = cpu_targets();
  ASSERT_FALSE(cpu.empty());
  std::cout << "[simd] arch " << arch_name() << "; targets this CPU runs (compiled in, best first): " << names(cpu)
            << "\n[simd] air/stereo/sgbm_ctf kernels (census, cost_row, aggregate_pass, select_row): " << stereo
            << "\n[simd] air/track/features kernels (features_run, add_log_ratio, softplus_sums): " << track
            << std::endl;
  RecordProperty("arch", arch_name());
  RecordProperty("stereo_target", stereo);
  RecordProperty("track_target", track);
  // Dispatch takes the best target the CPU has.
  EXPECT_EQ(stereo, hwy::TargetName(cpu.front()));
  EXPECT_EQ(track, hwy::TargetName(cpu.front()));
  for (const std::string& t : {stereo, track}) {
    EXPECT_NE(t, "EMU128") << "scalar fallback taken";
    EXPECT_NE(t, "SCALAR") << "scalar fallback taken";
    if (!vector_targets().empty()) {
      EXPECT_TRUE(vector_targets().count(t)) << t << " is not a vector target of " << arch_name();
    }
  }
}

