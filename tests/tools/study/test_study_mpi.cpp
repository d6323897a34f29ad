// tools/study over MPI ranks (study-probe under mpirun): the rows of one process for any number
// of ranks; a rank that hangs or dies ends the study naming it, its host and the lost runs, and
// the partial study resumes (in one process, or on two ranks) to the uninterrupted one.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>

#include "tests/integration/process.hpp"
#include "tests/support/test_support.hpp"
#include "tests/tools/study/files.hpp"

using namespace aerie;

namespace {

using test::slurp;

const std::string kProbe = AERIE_BINARY_DIR "/tests/study-probe";

std::vector<std::string> mpirun(int ranks, std::vector<std::string> args) {
  std::vector<std::string> cmd{AERIE_MPIEXEC, "-np", std::to_string(ranks), "--oversubscribe", "--allow-run-as-root",
                               kProbe};
  cmd.insert(cmd.end(), args.begin(), args.end());
  return cmd;
}

// Exit status of the command, its stdout + stderr in `output`.
int run(const std::vector<std::string>& cmd, const std::filesystem::path& log, std::string& output, double timeout_s = 60) {
  test::Process p(cmd, log);
  const auto status = p.wait(timeout_s);
  output = slurp(log);
  return status ? *status : -1;
}

std::string hostname() {
  char name[256] = {};
  gethostname(name, sizeof name - 1);
  return name;
}

struct Reference {
  std::string rows, pairs;
};
Reference reference(const std::filesystem::path& dir, int runs) {
  std::string out;
  EXPECT_EQ(run({kProbe, "--runs", std::to_string(runs), "--out", (dir / "ref").string()}, dir / "ref.log", out), 0) << out;
  return {slurp(dir / "ref/rows.csv"), slurp(dir / "ref/pairs.csv")};
}

// The interrupted study in `dir` continued by `cmd` (a --resume): the finished runs are kept
// and the rows equal the uninterrupted study's.
void expect_resumes(const std::vector<std::string>& cmd, const std::filesystem::path& dir, const Reference& ref) {
  std::string out;
  ASSERT_LT(slurp(dir / "mpi/rows.csv").size(), ref.rows.size()) << "nothing was lost: no test";
  ASSERT_EQ(run(cmd, dir / "resume.log", out), 0) << out;
  EXPECT_EQ(out.find("resumed 0"), std::string::npos) << out;
  EXPECT_EQ(slurp(dir / "mpi/rows.csv"), ref.rows);
  EXPECT_EQ(slurp(dir / "mpi/pairs.csv"), ref.pairs);
}

}  // namespace

TEST(StudyMpi, ThreeRanksWriteTheRowsOfOneProcess) {
  const auto dir = test::scratch_dir("ranks");
  const Reference ref = reference(dir, 12);
  std::string out;
  ASSERT_EQ(run(mpirun(3, {"--runs", "12", "--sleep-ms", "50", "--out", (dir / "mpi").string()}), dir / "mpi.log", out), 0)
      << out;
  EXPECT_NE(out.find("flown 12 resumed 0 failed 0 written 12 ranks 3 slept "), std::string::npos) << out;
  for (const char* worker : {"rank 1 flew ", "rank 2 flew "}) {  // the workers had their share
    const auto at = out.find(worker);
    ASSERT_NE(at, std::string::npos) << out;
    EXPECT_GT(std::stoi(out.substr(at + std::strlen(worker))), 0) << out;
  }
  EXPECT_EQ(slurp(dir / "mpi/rows.csv"), ref.rows);
  EXPECT_EQ(slurp(dir / "mpi/pairs.csv"), ref.pairs);
}

TEST(StudyMpi, AHungRankEndsTheStudyNamingItItsHostAndTheLostRunAndTheStudyResumes) {
  const auto dir = test::scratch_dir("hang");
  const Reference ref = reference(dir, 10);
  std::string out;
  const auto mpi = (dir / "mpi").string();
  const int status =
      run(mpirun(2, {"--runs", "10", "--sleep-ms", "30", "--hang-rank", "1", "--rank-timeout", "2", "--out", mpi}),
          dir / "mpi.log", out);
  EXPECT_NE(status, 0) << out;
  EXPECT_NE(out.find("study-probe: the study stops, ranks lost:\n  rank 1 (" + hostname() +
                     ") has not answered for 2 s (--rank-timeout); lost: run "),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("continue with --resume " + mpi), std::string::npos) << out;
  // Rank 0 flew runs while rank 1 hung: they are kept, and the rest is flown without MPI.
  expect_resumes({kProbe, "--runs", "10", "--resume", mpi}, dir, ref);
}

TEST(StudyMpi, ADeadRankEndsTheJobNamingItAndTheRunsInFlightAndTheStudyResumes) {
  const auto dir = test::scratch_dir("dead");
  const Reference ref = reference(dir, 10);
  std::string out;
  const auto mpi = (dir / "mpi").string();
  const int status = run(mpirun(2, {"--runs", "10", "--sleep-ms", "30", "--die-rank", "1", "--out", mpi}), dir / "mpi.log", out);
  EXPECT_NE(status, 0) << out;
  // mpirun names the rank and its host; rank 0, stopped by mpirun, names the runs in flight.
  EXPECT_NE(out.find("process rank 1 with PID"), std::string::npos) << out;
  EXPECT_NE(out.find("on node " + hostname()), std::string::npos) << out;
  EXPECT_NE(out.find("study-probe: stopped by SIGTERM"), std::string::npos) << out;
  EXPECT_NE(out.find(" on rank 1 (" + hostname() + ")"), std::string::npos) << out;
  expect_resumes(mpirun(2, {"--runs", "10", "--resume", mpi}), dir, ref);  // on two ranks again
}

TEST(StudyMpi, ProbeAnswersHelpAndRefusesAWrongOption) {
  const auto dir = test::scratch_dir("cli");
  std::string out;
  EXPECT_EQ(run({kProbe, "--help"}, dir / "help.log", out), 0);
  EXPECT_NE(out.find("study-probe: a study of trivial runs"), std::string::npos) << out;
  EXPECT_EQ(run({kProbe, "--no-such-option"}, dir / "bad.log", out), 2) << out;
}
