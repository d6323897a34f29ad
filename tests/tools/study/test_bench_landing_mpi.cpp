// aerie-bench-landing over tools/study: two MPI ranks write the rows of one process (every
// column but wall_s), and a study killed (SIGKILL) after its first rows resumes to the
// uninterrupted one, keeping the rows it had.
#include <gtest/gtest.h>

#include <sstream>
#include <thread>

#include "tests/support/test_support.hpp"
#include "tests/tools/study/files.hpp"

using namespace aerie;

namespace {

using test::lines;
using test::run;
using test::slurp;

std::vector<std::string> without_wall(const std::filesystem::path& csv) { return test::without_column(csv, "wall_s"); }

const std::string kBench = AERIE_BINARY_DIR "/bin/aerie-bench-landing";

// The shortest landing study the suite flies: 4 seeds in the room.
std::vector<std::string> bench(const std::filesystem::path& out, std::vector<std::string> extra = {}) {
  const std::string src = AERIE_SOURCE_DIR;
  std::vector<std::string> cmd{kBench, "--runs", "4", "--seed", "3", "--no-plots",
                               "--sim-config-dir", src + "/config/sim", "--track-config", src + "/config/track_landing.yaml",
                               "--pilot-config", src + "/config/pilot.yaml"};
  return test::with_out(cmd, extra, out);
}

}  // namespace

TEST(BenchLandingMpi, TwoRanksWriteTheRowsOfOneProcess) {
  const auto dir = test::scratch_dir("ranks");
  ASSERT_EQ(run(bench(dir / "one"), dir / "one.log"), 0) << slurp(dir / "one.log");
  ASSERT_EQ(run(test::two_ranks(AERIE_MPIEXEC, bench(dir / "mpi")), dir / "mpi.log"), 0) << slurp(dir / "mpi.log");
  const auto one = without_wall(dir / "one/landings.csv");
  ASSERT_EQ(one.size(), 5u);  // header + 4 landings
  EXPECT_EQ(without_wall(dir / "mpi/landings.csv"), one);
  EXPECT_EQ(slurp(dir / "mpi/descent.csv"), slurp(dir / "one/descent.csv"));
  // The same summary line, but for its wall-clock ratio at the end.
  const auto summary = [&](const char* log) {
    for (const auto& l : lines(slurp(dir / log)))
      if (l.find("landed in bounds") != std::string::npos) return l.substr(0, l.rfind(','));
    return std::string("(none)");
  };
  EXPECT_EQ(summary("mpi.log"), summary("one.log"));
}

TEST(BenchLandingMpi, AStudyKilledAfterItsFirstRowsResumesToTheUninterruptedOne) {
  const auto dir = test::scratch_dir("resume");
  ASSERT_EQ(run(bench(dir / "one"), dir / "one.log"), 0) << slurp(dir / "one.log");
  std::string kept;
  {
    test::Process p(bench(dir / "killed", {"--jobs", "2"}), dir / "killed.log");
    ASSERT_EQ(test::kill_when(p, [&] { return lines(slurp(dir / "killed/landings.csv")).size() >= 2; }), 128 + SIGKILL);
    kept = slurp(dir / "killed/landings.csv");
  }
  const auto partial = lines(kept);
  ASSERT_GE(partial.size(), 2u);
  ASSERT_LT(partial.size(), 5u) << "the study ended before the kill: nothing to resume";
  ASSERT_EQ(run(bench(dir / "killed", {"--resume", (dir / "killed").string()}), dir / "resume.log"), 0)
      << slurp(dir / "resume.log");
  EXPECT_EQ(without_wall(dir / "killed/landings.csv"), without_wall(dir / "one/landings.csv"));
  EXPECT_EQ(slurp(dir / "killed/descent.csv"), slurp(dir / "one/descent.csv"));
  // The rows written before the kill are kept as they were (their wall_s too): not flown again.
  const auto final_rows = lines(slurp(dir / "killed/landings.csv"));
  for (size_t k = 0; k < partial.size(); ++k) EXPECT_EQ(final_rows[k], partial[k]);
}

TEST(BenchLandingMpi, ResumeRefusesOtherOptions) {
  const auto dir = test::scratch_dir("other");
  auto cmd = bench(dir / "a");
  cmd[2] = "1";  // --runs 1
  ASSERT_EQ(run(cmd, dir / "a.log"), 0) << slurp(dir / "a.log");
  cmd = bench(dir / "a", {"--resume", (dir / "a").string()});
  EXPECT_EQ(run(cmd, dir / "b.log"), 1);
  EXPECT_NE(slurp(dir / "b.log").find((dir / "a").string() + "/study.progress: the study there is not this one"),
            std::string::npos)
      << slurp(dir / "b.log");
}
