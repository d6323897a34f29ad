#pragma once
// Helpers shared by the test suites.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

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

// What `load(text)` throws, or "" when it accepts the text.
template <typename Load>
std::string refusal(Load&& load, const std::string& text) {
  try {
    load(text);
  } catch (const std::exception& e) {
    return e.what();
  }
  return {};
}

// Each (config text, expected words) case must be refused with a message holding the words.
template <typename Load>
void expect_refusals(Load&& load, const std::vector<std::pair<std::string, std::string>>& cases) {
  for (const auto& [text, why] : cases) {
    const std::string e = refusal(load, text);
    EXPECT_NE(e.find(why), std::string::npos) << text << " -> " << (e.empty() ? "accepted" : e);
  }
}

// What a command run through the shell printed on stdout, and its exit status (-1 when it did
// not exit normally). Redirect stderr in `command` ("2>&1", "2>FILE") to see it.
struct ToolRun {
  int rc = -1;
  std::string out;
};
inline ToolRun run_tool(const std::string& command) {
  ToolRun r;
  FILE* p = ::popen(command.c_str(), "r");
  if (p == nullptr) return r;
  char buf[4096];
  size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  const int status = ::pclose(p);
  r.rc = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

}  // namespace aerie::test

// Skips the test (with the reason) when a shared dataset is absent, e.g. on a clone
// without ../shared; CI always has it.
#define AERIE_REQUIRE_DATA(rel)                                                       \
  do {                                                                                \
    if (!std::filesystem::exists(::aerie::test::shared_data(rel)))                    \
      GTEST_SKIP() << "shared data not found: " << ::aerie::test::shared_data(rel);   \
  } while (0)
