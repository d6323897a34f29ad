// aerie-linkstudy over tools/study: two MPI ranks write the study.csv and report.md of one
// process (the report's wall-clock figure aside), and a study killed (SIGKILL) after its first
// flights resumes to the uninterrupted one without flying them again; a resume with another
// study YAML is refused.
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

const std::string kTool = AERIE_BINARY_DIR "/bin/aerie-linkstudy";

// Two link conditions x two fault scenarios, one seed: 4 short landings (about 2.5 s each).
const char* kStudy = R"(
seeds: {first: 4, count: 1}
baseline: {delay_ms: 0}
sweeps:
  delay_ms: {values: [0, 300]}
placements: [ground-tracking]
workloads: [landing]
trackers: [amcmr-ct]
faults: [none, "kill:track@6+1"]
landing: {wind_m_s: 1, max_time_s: 14}
)";

std::vector<std::string> study(const std::filesystem::path& yaml, const std::filesystem::path& out,
                               std::vector<std::string> extra = {}) {
  std::vector<std::string> cmd{kTool, "--config", yaml.string(), "--base-dir", AERIE_SOURCE_DIR, "--no-plots"};
  return test::with_out(cmd, extra, out);
}

// report.md but for its line with the flight-thread (wall-clock) time.
std::vector<std::string> report(const std::filesystem::path& dir) {
  std::vector<std::string> out;
  for (const auto& l : lines(slurp(dir / "report.md")))
    if (l.find("s of flight-thread time") == std::string::npos) out.push_back(l);
  return out;
}

std::filesystem::path write_study(const std::filesystem::path& dir, const std::string& yaml) {
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "study.yaml") << yaml;
  return dir / "study.yaml";
}

}  // namespace

TEST(LinkStudyMpi, TwoRanksWriteTheCsvAndReportOfOneProcess) {
  const auto dir = test::scratch_dir("ranks");
  const auto yaml = write_study(dir, kStudy);
  ASSERT_EQ(run(study(yaml, dir / "one"), dir / "one.log"), 0) << slurp(dir / "one.log");
  ASSERT_EQ(run(test::two_ranks(AERIE_MPIEXEC, study(yaml, dir / "mpi")), dir / "mpi.log"), 0) << slurp(dir / "mpi.log");
  const std::string csv = slurp(dir / "one/study.csv");
  ASSERT_EQ(lines(csv).size(), 5u);  // header + 4 flights (each in the one sweep)
  EXPECT_EQ(slurp(dir / "mpi/study.csv"), csv);
  const auto r = report(dir / "one");
  EXPECT_GT(r.size(), 10u);
  EXPECT_NE(slurp(dir / "one/report.md").find("kill:track@6+1"), std::string::npos);  // the faults table, from the notes
  EXPECT_EQ(report(dir / "mpi"), r);
  EXPECT_NE(slurp(dir / "mpi.log").find("on 2 MPI ranks"), std::string::npos) << slurp(dir / "mpi.log");
}

TEST(LinkStudyMpi, AStudyKilledAfterItsFirstFlightsResumesToTheUninterruptedOne) {
  const auto dir = test::scratch_dir("resume");
  const auto yaml = write_study(dir, kStudy);
  ASSERT_EQ(run(study(yaml, dir / "one"), dir / "one.log"), 0) << slurp(dir / "one.log");
  {
    test::Process p(study(yaml, dir / "killed", {"--jobs", "1"}), dir / "killed.log");
    ASSERT_EQ(test::kill_when(p, [&] { return slurp(dir / "killed.log").find("[1/4]") != std::string::npos; }), 128 + SIGKILL);
  }
  ASSERT_EQ(slurp(dir / "killed.log").find("[4/4]"), std::string::npos) << "the study ended before the kill";
  EXPECT_FALSE(std::filesystem::exists(dir / "killed/study.csv"));  // written at the end only
  ASSERT_EQ(run(study(yaml, dir / "killed", {"--resume", (dir / "killed").string()}), dir / "resume.log"), 0)
      << slurp(dir / "resume.log");
  EXPECT_NE(slurp(dir / "resume.log").find("flights resumed from"), std::string::npos) << slurp(dir / "resume.log");
  EXPECT_EQ(slurp(dir / "killed/study.csv"), slurp(dir / "one/study.csv"));
  EXPECT_EQ(report(dir / "killed"), report(dir / "one"));
}

TEST(LinkStudyMpi, ResumeRefusesAnotherStudy) {
  const auto dir = test::scratch_dir("other");
  std::string one_flight = kStudy;
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"values: [0, 300]", "values: [0]"},
                                 {"faults: [none, \"kill:track@6+1\"]", "faults: [none]"}})
    one_flight.replace(one_flight.find(from), from.size(), to);
  const auto yaml = write_study(dir, one_flight);
  ASSERT_EQ(run(study(yaml, dir / "a"), dir / "a.log"), 0) << slurp(dir / "a.log");
  const auto other = write_study(dir / "b", kStudy);
  EXPECT_EQ(run(study(other, dir / "a", {"--resume", (dir / "a").string()}), dir / "b.log"), 1);
  EXPECT_NE(slurp(dir / "b.log").find((dir / "a").string() + "/study.progress: the study there is not this one"),
            std::string::npos)
      << slurp(dir / "b.log");
}
