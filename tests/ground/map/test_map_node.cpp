// The aerie-map executable: saves the map at exit (SIGINT) and continues a saved map.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "ground/map/occupancy.hpp"
#include "tests/support/test_support.hpp"

extern char** environ;

namespace {

pid_t spawn(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  EXPECT_EQ(posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), environ), 0);
  return pid;
}

int wait_exit(pid_t pid, double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  int status = 0;
  while (waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -2;
}

// True once the process catches SIGINT (its stop handlers are installed): SigCgt in /proc.
bool catches_sigint(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("SigCgt:", 0) == 0) return (std::stoull(line.substr(7), nullptr, 16) >> (SIGINT - 1)) & 1;
  return false;
}

// Runs aerie-map (in-process LCM: nothing to receive) and stops it with SIGINT.
int run_and_interrupt(std::vector<std::string> args) {
  args.insert(args.begin(), {AERIE_MAP_EXE, "--lcm-url", "memq://", "--log-level", "warn"});
  const pid_t pid = spawn(args);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (!catches_sigint(pid) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // into the main loop
  kill(pid, SIGINT);
  return wait_exit(pid, 20.0);
}

}  // namespace

TEST(MapNode, SavesAtExitAndContinuesASavedMap) {
  const auto dir = aerie::test::scratch_dir("node");
  // A map to continue from.
  aerie::map::OccupancyMap map;
  map.insert_frame({{2.05f, 0.05f, 0.05f}}, {0.05f, 0.05f, 0.05f});
  const auto start = (dir / "start.ot").string();
  map.save(start);

  const auto saved = (dir / "saved.bt").string();
  ASSERT_EQ(run_and_interrupt({"--load", start, "--save", saved}), 0);
  ASSERT_TRUE(std::filesystem::exists(saved));
  aerie::map::OccupancyMap back;
  back.load(saved);
  EXPECT_EQ(back.occupancy({2.05, 0.05, 0.05}).state, aerie::map::Occupancy::Occupied);
  EXPECT_EQ(back.occupancy({1.05, 0.05, 0.05}).state, aerie::map::Occupancy::Free);
}

TEST(MapNode, BadArgumentsFailWithACode) {
  const auto dir = aerie::test::scratch_dir("bad");
  EXPECT_EQ(wait_exit(spawn({AERIE_MAP_EXE, "--lcm-url", "memq://", "--save", (dir / "map.txt").string()}), 20.0), 1);
  EXPECT_NE(wait_exit(spawn({AERIE_MAP_EXE, "--load", (dir / "missing.bt").string()}), 20.0), 0);
  EXPECT_EQ(wait_exit(spawn({AERIE_MAP_EXE, "--help"}), 20.0), 0);
}

TEST(MapNode, LoadRefusesAnOtWithAGarbageBody) {
  // The header of a real map, then random bytes: was loaded as 39,879 nodes of nonsense.
  const auto dir = aerie::test::scratch_dir("garbage");
  aerie::map::OccupancyMap map;
  for (int i = 0; i < 50; ++i) map.insert_frame({{2.05f, 0.05f * i, 0.05f}}, {0.05f, 0.05f, 0.05f});
  const auto good = (dir / "good.ot").string();
  map.save(good);
  std::ifstream in(good, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  uint32_t x = 12345;
  for (size_t i = text.find("data\n") + 5; i < text.size(); ++i) {
    x = x * 1664525u + 1013904223u;
    text[i] = static_cast<char>(x >> 24);
  }
  const auto garbage = (dir / "garbage.ot").string();
  std::ofstream(garbage, std::ios::binary) << text;
  EXPECT_THROW(aerie::map::read_octree_file(garbage), std::runtime_error);
  EXPECT_EQ(wait_exit(spawn({AERIE_MAP_EXE, "--lcm-url", "memq://", "--save", "", "--load", garbage}), 20.0), 1);
  EXPECT_NO_THROW(aerie::map::read_octree_file(good));
}

TEST(MapNode, LoadChecksTheBodyOctoMapReadsNotALaterOne) {
  // OctoMap's header is tokens: "data 49" ends it, and the body starts on the next line. The
  // check read lines and looked for "data" alone on one, so it checked the (empty) body after a
  // later "data" line while OctoMap read the 0xFF bytes first: a tree growing without end (fuzz
  // finding, fuzz/regressions/octomap/bt_data_token_not_line_oom.bt: 24 GB under ASan).
  const std::string header = "# Octomap OcTree binary file\nid OcTree\nsize 49\nres 0.1\ndata 49\n";
  const std::string text = header + std::string(64, '\xff') + "\ndata\n";
  std::istringstream in(text);
  try {
    aerie::map::read_octree(in, true);
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("deeper than 16"), std::string::npos) << e.what();
  }
  // The old binary format (no text header) and a wrong first line are refused by name.
  std::istringstream old(std::string("\x03\0\0\0", 4) + std::string(12, '\0'));
  EXPECT_THROW(aerie::map::read_octree(old, true), std::invalid_argument);
  std::istringstream wrong("# Octomap OcTree file\nid OcTree\nres 0.1\ndata\n");
  try {
    aerie::map::read_octree(wrong, true);  // an .ot header read as .bt
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("# Octomap OcTree binary file"), std::string::npos) << e.what();
  }
}

