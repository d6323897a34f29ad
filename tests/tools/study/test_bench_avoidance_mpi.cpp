// aerie-bench-avoidance over tools/study: two MPI ranks write the rows and summary lines of one
// process (every column but wall_s), and a study killed (SIGKILL) after its first rows resumes
// to the uninterrupted one, keeping the rows it had.
#include <gtest/gtest.h>

#include <thread>

#include "tests/support/test_support.hpp"
#include "tests/tools/study/files.hpp"

using namespace aerie;

namespace {

using test::lines;
using test::run;
using test::slurp;
using test::without_column;

const std::string kBench = AERIE_BINARY_DIR "/bin/aerie-bench-avoidance";

// A short avoidance study: 3 seeds at two speeds on ground-truth heading (about 1.5 s a flight),
// run from the repository (config/avoidance.yaml names the node configurations relative to it).
std::vector<std::string> bench(const std::filesystem::path& out, std::vector<std::string> extra = {}) {
  std::filesystem::current_path(AERIE_SOURCE_DIR);
  std::vector<std::string> cmd{kBench, "--runs", "3", "--seed", "2", "--source", "gt", "--speed", "0.4,0.8", "--no-plots"};
  return test::with_out(cmd, extra, out);
}

// The summary lines, without their wall-clock ratio at the end.
std::vector<std::string> summaries(const std::filesystem::path& log) {
  std::vector<std::string> out;
  for (const auto& l : lines(slurp(log)))
    if (l.find(" completed, steady heading RMSE") != std::string::npos) out.push_back(l.substr(0, l.rfind(',')));
  return out;
}

}  // namespace

TEST(BenchAvoidanceMpi, TwoRanksWriteTheRowsOfOneProcess) {
  const auto dir = test::scratch_dir("ranks");
  ASSERT_EQ(run(bench(dir / "one", {"--jobs", "2"}), dir / "one.log"), 0) << slurp(dir / "one.log");
  ASSERT_EQ(run(test::two_ranks(AERIE_MPIEXEC, bench(dir / "mpi")), dir / "mpi.log"), 0) << slurp(dir / "mpi.log");
  const auto one = without_column(dir / "one/avoidance.csv");
  ASSERT_EQ(one.size(), 7u);  // header + 2 speeds x 3 seeds
  EXPECT_EQ(without_column(dir / "mpi/avoidance.csv"), one);
  EXPECT_EQ(slurp(dir / "mpi/trajectories.csv"), slurp(dir / "one/trajectories.csv"));
  EXPECT_GT(lines(slurp(dir / "one/trajectories.csv")).size(), 7u);
  const auto s = summaries(dir / "one.log");
  ASSERT_EQ(s.size(), 2u);  // one per speed
  EXPECT_EQ(summaries(dir / "mpi.log"), s);
}

TEST(BenchAvoidanceMpi, AStudyKilledAfterItsFirstRowsResumesToTheUninterruptedOne) {
  const auto dir = test::scratch_dir("resume");
  ASSERT_EQ(run(bench(dir / "one", {"--jobs", "2"}), dir / "one.log"), 0) << slurp(dir / "one.log");
  std::string kept;
  {
    test::Process p(bench(dir / "killed", {"--jobs", "2"}), dir / "killed.log");
    ASSERT_EQ(test::kill_when(p, [&] { return lines(slurp(dir / "killed/avoidance.csv")).size() >= 2; }), 128 + SIGKILL);
    kept = slurp(dir / "killed/avoidance.csv");
  }
  const auto partial = lines(kept);
  ASSERT_GE(partial.size(), 2u);
  ASSERT_LT(partial.size(), 7u) << "the study ended before the kill: nothing to resume";
  ASSERT_EQ(run(bench(dir / "killed", {"--jobs", "2", "--resume", (dir / "killed").string()}), dir / "resume.log"), 0)
      << slurp(dir / "resume.log");
  EXPECT_EQ(without_column(dir / "killed/avoidance.csv"), without_column(dir / "one/avoidance.csv"));
  EXPECT_EQ(slurp(dir / "killed/trajectories.csv"), slurp(dir / "one/trajectories.csv"));
  const auto final_rows = lines(slurp(dir / "killed/avoidance.csv"));
  for (size_t k = 0; k < partial.size(); ++k) EXPECT_EQ(final_rows[k], partial[k]);  // not flown again
  EXPECT_EQ(summaries(dir / "resume.log"), summaries(dir / "one.log"));  // the resumed runs counted too
}
