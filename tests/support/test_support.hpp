#pragma once
// Helpers shared by the test suites.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace aerie::test {

// <repo>/../shared/data, or $AERIE_DATA_DIR when set.
inline std::filesystem::path shared_data_dir() {
  if (const char* env = std::getenv("AERIE_DATA_DIR")) return env;
  return std::filesystem::path(AERIE_SOURCE_DIR).parent_path() / "shared" / "data";
}

inline std::filesystem::path shared_data(const std::string& rel) { return shared_data_dir() / rel; }

inline std::filesystem::path source_dir() { return AERIE_SOURCE_DIR; }
inline std::filesystem::path binary_dir() { return AERIE_BINARY_DIR; }

// A fresh empty folder under the build tree for one test's outputs.
inline std::filesystem::path scratch_dir(const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  auto dir = binary_dir() / "test-scratch" / (std::string(info->test_suite_name()) + "." + info->name() + "." + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace aerie::test

// Skips the test (with the reason) when a shared dataset is absent, e.g. on a clone
// without ../shared; CI always has it.
#define AERIE_REQUIRE_DATA(rel)                                                       \
  do {                                                                                \
    if (!std::filesystem::exists(::aerie::test::shared_data(rel)))                    \
      GTEST_SKIP() << "shared data not found: " << ::aerie::test::shared_data(rel);   \
  } while (0)
