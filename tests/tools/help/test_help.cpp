// Every executable in build/<preset>/bin answers --help: exit 0 and a first line that describes
// it (not a bare "Usage:" line, not Google Benchmark's flag list), and refuses an unknown option
// (a non-zero exit, within the timeout, instead of running). Issue 49: aerie-bench-fhog-micro
// ran its benchmark on --help, aerie-bench-ipsl-micro printed only the benchmark flags.
// The executables are listed when the test runs (after the full build of scripts/test.sh).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

const fs::path kBin = fs::path(AERIE_BINARY_DIR) / "bin";

// Executables whose --help lacks a description line, each with the reason. (No Java tool is
// installed in bin/: lcm-spy runs from lcm.jar, docs/logs.md.)
const std::map<std::string, std::string> kNoDescription = {};

std::vector<std::string> executables() {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(kBin, ec)) {
    if (!e.is_regular_file()) continue;
    if ((e.status().permissions() & fs::perms::owner_exec) == fs::perms::none) continue;
    names.push_back(e.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

struct Outcome {
  int status = -1;  // exit code; 124 = killed by the timeout
  std::string output;
};

// Runs `bin/name args` with no input and a timeout, stdout and stderr together.
Outcome run(const std::string& name, const std::string& args, int timeout_s) {
  const std::string command = "timeout -k 2 " + std::to_string(timeout_s) + " '" + (kBin / name).string() + "' " +
                              args + " </dev/null 2>&1";
  Outcome r;
  FILE* p = popen(command.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n = 0;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + (WIFSIGNALED(st) ? WTERMSIG(st) : 0);
  return r;
}

std::string first_line(const std::string& text) {
  const size_t start = text.find_first_not_of("\n");
  if (start == std::string::npos) return {};
  return text.substr(start, text.find('\n', start) - start);
}

std::string test_name(const testing::TestParamInfo<std::string>& info) {
  std::string s = info.param;
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
}

class Help : public testing::TestWithParam<std::string> {};

}  // namespace

TEST(HelpSurvey, TheBinFolderHoldsTheDemoAndTheNodes) {
  const auto names = executables();
  ASSERT_FALSE(names.empty()) << kBin << " has no executables: build first (bash scripts/test.sh)";
  for (const char* core : {"aerie-track", "aerie-vo", "aerie-viewer", "aerie-deputy", "aerie-sheriff", "aerie-log"})
    EXPECT_TRUE(std::count(names.begin(), names.end(), core)) << core << " not in " << kBin;
  for (const auto& [name, reason] : kNoDescription)  // not built by every preset (asan: no benchmarks)
    if (!std::count(names.begin(), names.end(), name)) std::printf("listed exception %s is not in bin/\n", name.c_str());
}

TEST_P(Help, AnswersHelpWithADescriptionAndRefusesAnUnknownOption) {
  const std::string& name = GetParam();
  const Outcome help = run(name, "--help", 30);
  EXPECT_EQ(help.status, 0) << name << " --help:\n" << help.output;
  const std::string line = first_line(help.output);
  EXPECT_FALSE(line.empty()) << name << " --help printed nothing";
  if (const auto it = kNoDescription.find(name); it != kNoDescription.end()) {
    std::printf("%s: no description line, listed: %s\n", name.c_str(), it->second.c_str());
  } else {
    EXPECT_NE(line.rfind("Usage", 0), 0u) << name << ": the first line of --help is not a description: " << line;
    EXPECT_NE(line.rfind("benchmark [", 0), 0u) << name << ": only Google Benchmark's flags: " << line;
    EXPECT_GE(std::count(line.begin(), line.end(), ' '), 2) << name << ": not a description: " << line;
  }
  const Outcome bad = run(name, "--no-such-option-issue-49", 30);
  EXPECT_NE(bad.status, 0) << name << " accepted an unknown option:\n" << bad.output;
  EXPECT_NE(bad.status, 124) << name << " ran on an unknown option until the timeout";
  EXPECT_FALSE(first_line(bad.output).empty()) << name << " refused an unknown option without a word";
}

INSTANTIATE_TEST_SUITE_P(EveryExecutable, Help, testing::ValuesIn(executables()), test_name);

#ifdef AERIE_DEMO_TARGETS
// The demo builds only its own executables (CMake target "demo"): each one config/demo.pmd
// runs (the first word of every exec) and each one scripts/demo.sh calls ("$BIN/<name>").
TEST(DemoTarget, BuildsEveryExecutableTheDemoRuns) {
  std::set<std::string> demo;
  std::stringstream list(AERIE_DEMO_TARGETS);
  for (std::string t; std::getline(list, t, ',');)
    if (!t.empty()) demo.insert(t);
  ASSERT_FALSE(demo.empty()) << "the demo target has no dependencies";
  std::set<std::string> used;
  auto read = [](const fs::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  };
  const std::string pmd = read(fs::path(AERIE_SOURCE_DIR) / "config/demo.pmd");
  const std::regex exec_re(R"re(exec\s*=\s*"([A-Za-z0-9_.-]+))re");
  for (std::sregex_iterator it(pmd.begin(), pmd.end(), exec_re), end; it != end; ++it) used.insert((*it)[1]);
  const std::string sh = read(fs::path(AERIE_SOURCE_DIR) / "scripts/demo.sh");
  const std::regex bin_re(R"re(\$BIN/([A-Za-z0-9_.-]+))re");
  for (std::sregex_iterator it(sh.begin(), sh.end(), bin_re), end; it != end; ++it) used.insert((*it)[1]);
  ASSERT_GE(used.size(), 8u) << "too few executables found in config/demo.pmd and scripts/demo.sh";
  for (const auto& exe : used) EXPECT_TRUE(demo.count(exe)) << exe << " is run by the demo but not built by target demo";
  EXPECT_NE(sh.find("--target demo"), std::string::npos) << "scripts/demo.sh does not build the demo target";
}
#endif
