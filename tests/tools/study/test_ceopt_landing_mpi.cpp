// aerie-ceopt landing over tools/study: two MPI ranks give the CE history (means, sigmas, best
// and iteration-best costs of every iteration), the tuned pilot.yaml and the report's gains of
// one process without a journal; a --resumable tuning killed (SIGKILL) in its second batch
// resumes to the same result, not flying the landings its journals hold; the FLC tuning under
// mpirun is refused.
#include <gtest/gtest.h>

#include <fstream>
#include <thread>

#include "tests/support/test_support.hpp"
#include "tests/tools/study/files.hpp"

using namespace aerie;

namespace {

using test::lines;
using test::run;
using test::slurp;

const std::string kTool = AERIE_BINARY_DIR "/bin/aerie-ceopt";

// Two iterations of two candidates on one training seed without wind: 5 landings.
std::filesystem::path write_config(const std::filesystem::path& dir) {
  const std::string src = AERIE_SOURCE_DIR;
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "ceopt_landing.yaml") << "sim_config: " << src << "/config/sim/landing_room.yaml\n"
                                            << "track_config: " << src << "/config/track_landing.yaml\n"
                                            << "pilot_config: " << src << "/config/pilot.yaml\n"
                                            << "wind_m_s: 0\ntraining: {first: 7, count: 1}\nvalidation: {count: 0}\n"
                                            << "ce: {samples: 2, elite: 1, iterations: 2, seed: 3}\n";
  return dir / "ceopt_landing.yaml";
}

std::vector<std::string> ceopt(const std::filesystem::path& config, const std::filesystem::path& out,
                               std::vector<std::string> extra = {}) {
  std::vector<std::string> cmd{kTool, "landing", "--config", config.string(), "--no-lcm"};
  return test::with_out(cmd, extra, out);
}

// report.md without its command line and its wall/CPU time.
std::vector<std::string> report(const std::filesystem::path& dir) {
  std::vector<std::string> out;
  for (const auto& l : lines(slurp(dir / "report.md")))
    if (l.rfind("Command:", 0) != 0 && l.rfind("Wall time", 0) != 0) out.push_back(l);
  return out;
}

void expect_same_tuning(const std::filesystem::path& a, const std::filesystem::path& b) {
  const std::string history = slurp(a / "ce_history.csv");
  EXPECT_EQ(lines(history).size(), 3u);  // header + 2 iterations
  EXPECT_EQ(slurp(b / "ce_history.csv"), history);
  EXPECT_FALSE(slurp(a / "pilot.yaml").empty());
  EXPECT_EQ(slurp(b / "pilot.yaml"), slurp(a / "pilot.yaml"));
  EXPECT_EQ(test::without_column(b / "validation.csv"), test::without_column(a / "validation.csv"));
  EXPECT_EQ(report(b), report(a));
}

}  // namespace

// One test, so that the single-process tuning both halves compare with is flown once (ctest
// runs every test in a process of its own).
TEST(CeoptLandingMpi, TwoRanksAndAResumedTuningTuneAsOneProcess) {
  const auto dir = test::scratch_dir("tuning");
  const auto config = write_config(dir);
  ASSERT_EQ(run(ceopt(config, dir / "one", {"--threads", "2"}), dir / "one.log", 180), 0) << slurp(dir / "one.log");
  EXPECT_FALSE(std::filesystem::exists(dir / "one/studies"));  // without mpirun or --resumable: as before, no journal

  // Two ranks.
  ASSERT_EQ(run(test::two_ranks(AERIE_MPIEXEC, ceopt(config, dir / "mpi", {"--threads", "1"})), dir / "mpi.log", 180), 0)
      << slurp(dir / "mpi.log");
  expect_same_tuning(dir / "one", dir / "mpi");
  // One study per batch: the initial gains, then each iteration's candidates x the training seed.
  for (const char* b : {"batch-000", "batch-001", "batch-002"})
    EXPECT_EQ(lines(slurp(dir / "mpi/studies" / b / "landings.csv")).size(), std::string(b) == "batch-000" ? 2u : 3u) << b;
  EXPECT_FALSE(std::filesystem::exists(dir / "mpi/studies/batch-003"));

  // --resumable, killed in its second batch (the first iteration), then --resume.
  const auto killed = dir / "killed";
  std::string kept;
  {
    // One landing at a time, so that the kill comes after the first iteration's first landing.
    test::Process p(ceopt(config, killed, {"--resumable", "--threads", "1"}), dir / "killed.log");
    ASSERT_EQ(test::kill_when(p, [&] { return lines(slurp(killed / "studies/batch-001/landings.csv")).size() >= 2; }, 120),
              128 + SIGKILL);
    kept = slurp(killed / "studies/batch-001/landings.csv");
  }
  ASSERT_EQ(lines(kept).size(), 2u) << "the kill came after the first iteration's first landing";
  EXPECT_FALSE(std::filesystem::exists(killed / "ce_history.csv"));
  ASSERT_EQ(run(ceopt(config, killed, {"--threads", "2", "--resume", killed.string()}), dir / "resume.log", 180), 0)
      << slurp(dir / "resume.log");
  expect_same_tuning(dir / "one", killed);
  // The landings journaled before the kill were not flown again: their rows (wall_s too) stand.
  EXPECT_EQ(slurp(killed / "studies/batch-001/landings.csv").rfind(kept, 0), 0u);
}

TEST(CeoptLandingMpiFlc, TheFlcTuningUnderMpirunIsRefused) {
  const auto dir = test::scratch_dir("flc");
  EXPECT_EQ(run(test::two_ranks(AERIE_MPIEXEC, {kTool, "--no-lcm", "--out", (dir / "out").string()}), dir / "log", 60), 2);
  EXPECT_NE(slurp(dir / "log").find("under mpirun only `aerie-ceopt landing` spreads over the ranks"), std::string::npos)
      << slurp(dir / "log");
}
