// tools/study in one process: rows in index order whatever order the runs finish in, the
// journal's resume after a SIGKILL (byte for byte the uninterrupted study, finished runs not
// flown again), failed runs, and the refusals of a folder that is not this study.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#include "tests/support/test_support.hpp"
#include "tests/tools/study/files.hpp"
#include "tools/study/study.hpp"

using namespace aerie;

namespace {

using test::slurp;

study::Record record_of(int i) {
  std::string pairs = i % 2 == 0 ? std::to_string(i) + ",a\n" + std::to_string(i) + ",b\n" : "";
  return study::Record{{std::to_string(i) + "," + std::to_string(i * i) + "\n", pairs}, "n" + std::to_string(i), ""};
}

struct Probe {
  study::Study st;
  std::mutex mutex;
  std::vector<int> finished, written;  // in the order they happened
  Probe(const std::filesystem::path& dir, int runs, std::function<void(int)> before = {}) {
    st.tool = "test-study";
    st.dir = dir.string();
    st.runs = runs;
    st.outputs = {{"rows.csv", "index,square\n"}, {"pairs.csv", "index,half\n"}};
    st.definition = "probe runs=" + std::to_string(runs);
    st.run = [this, before](int i) {
      if (before) before(i);
      std::lock_guard lock(mutex);
      finished.push_back(i);
      return record_of(i);
    };
    st.describe = [](int i) { return "run " + std::to_string(i); };
    st.on_written = [this](int i, const study::Record& r) {
      if (r.failed())
        EXPECT_TRUE(r.rows.empty());
      else
        EXPECT_EQ(r.note, "n" + std::to_string(i));
      written.push_back(i);
    };
  }
};

std::string expected_rows(int runs) {
  std::string s = "index,square\n";
  for (int i = 0; i < runs; ++i) s += record_of(i).rows[0];
  return s;
}
std::string expected_pairs(int runs) {
  std::string s = "index,half\n";
  for (int i = 0; i < runs; ++i) s += record_of(i).rows[1];
  return s;
}

std::vector<int> iota(int n) {
  std::vector<int> v(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) v[static_cast<size_t>(i)] = i;
  return v;
}

int argc0 = 0;
char** argv0 = nullptr;

}  // namespace

TEST(Study, RowsAreWrittenInIndexOrderWhateverOrderTheRunsFinish) {
  study::Session session(argc0, argv0);
  ASSERT_FALSE(session.distributed());
  const auto dir = test::scratch_dir("order");
  // Later runs are shorter: on 4 threads they finish before earlier ones.
  Probe p(dir, 12, [](int i) { std::this_thread::sleep_for(std::chrono::milliseconds(4 * (12 - i))); });
  const study::Outcome o = study::run(p.st, study::Options{4, false, 600}, session);
  EXPECT_TRUE(o.writer);
  EXPECT_EQ(o.flown, 12);
  EXPECT_EQ(o.resumed, 0);
  EXPECT_EQ(o.failed, 0);
  EXPECT_FALSE(std::is_sorted(p.finished.begin(), p.finished.end())) << "the runs finished in index order: no test";
  EXPECT_EQ(p.written, iota(12));
  EXPECT_EQ(slurp(dir / "rows.csv"), expected_rows(12));
  EXPECT_EQ(slurp(dir / "pairs.csv"), expected_pairs(12));
  // The runs that finished before an earlier one were journaled as held.
  const std::string journal = slurp(dir / "study.progress");
  EXPECT_NE(journal.find("\nh "), std::string::npos);
  size_t w = 0;
  for (size_t at = journal.find("\nw "); at != std::string::npos; at = journal.find("\nw ", at + 1)) ++w;
  EXPECT_EQ(w, 12u);
}

TEST(Study, ResumeAfterASigkillEqualsTheUninterruptedStudyAndFliesOnlyWhatWasMissing) {
  study::Session session(argc0, argv0);
  const auto ref = test::scratch_dir("reference"), dir = test::scratch_dir("killed");
  const int runs = 16;
  {
    Probe p(ref, runs);
    study::run(p.st, study::Options{1, false, 600}, session);
  }
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {  // on 3 threads, out of order; run 9 kills the process
    Probe p(dir, runs, [](int i) {
      if (i == 9) raise(SIGKILL);
      std::this_thread::sleep_for(std::chrono::milliseconds(3 * (1 + (5 * i) % 4)));
    });
    study::run(p.st, study::Options{3, false, 600}, session);
    _exit(0);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
  // The runs the journal says finished (written or held).
  std::set<int> done;
  {
    std::istringstream j(slurp(dir / "study.progress"));
    std::string line;
    while (std::getline(j, line))
      if (line.size() > 2 && (line[0] == 'w' || line[0] == 'h') && line[1] == ' ') done.insert(std::stoi(line.substr(2)));
  }
  ASSERT_FALSE(done.empty());
  ASSERT_FALSE(done.count(9));
  // A death in the middle of a write: a torn row and a torn journal record.
  std::ofstream(dir / "rows.csv", std::ios::app) << "15,22";
  std::ofstream(dir / "study.progress", std::ios::app) << "w 15 o 12";

  Probe p(dir, runs);
  const study::Outcome o = study::run(p.st, study::Options{2, true, 600}, session);
  EXPECT_EQ(o.resumed, static_cast<int>(done.size()));
  EXPECT_EQ(o.flown, runs - static_cast<int>(done.size()));
  for (int i : p.finished) EXPECT_FALSE(done.count(i)) << "run " << i << " flown again";
  EXPECT_EQ(p.written, iota(runs));  // resumed ones first, each once, in index order
  EXPECT_EQ(slurp(dir / "rows.csv"), slurp(ref / "rows.csv"));
  EXPECT_EQ(slurp(dir / "pairs.csv"), slurp(ref / "pairs.csv"));
  EXPECT_EQ(slurp(dir / "rows.csv"), expected_rows(runs));
}

TEST(Study, AFailedRunHasNoRowsIsCountedAndIsNotFlownAgainOnResume) {
  study::Session session(argc0, argv0);
  const auto dir = test::scratch_dir("failed");
  Probe p(dir, 6, [](int i) {
    if (i == 2) throw std::runtime_error("no lift");
  });
  testing::internal::CaptureStderr();
  const study::Outcome o = study::run(p.st, study::Options{2, false, 600}, session);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(o.failed, 1);
  EXPECT_NE(err.find("test-study: run 2 failed: no lift"), std::string::npos) << err;
  std::string want = "index,square\n";
  for (int i : {0, 1, 3, 4, 5}) want += record_of(i).rows[0];
  EXPECT_EQ(slurp(dir / "rows.csv"), want);
  Probe again(dir, 6);
  testing::internal::CaptureStderr();
  const study::Outcome r = study::run(again.st, study::Options{1, true, 600}, session);
  const std::string err2 = testing::internal::GetCapturedStderr();
  EXPECT_EQ(r.flown, 0);
  EXPECT_EQ(r.resumed, 6);
  EXPECT_EQ(r.failed, 1);
  EXPECT_NE(err2.find("run 2 failed (earlier in this study): no lift"), std::string::npos) << err2;
  EXPECT_EQ(slurp(dir / "rows.csv"), want);
}

TEST(Study, ResumeRefusesAFolderThatIsNotThisStudy) {
  study::Session session(argc0, argv0);
  const auto dir = test::scratch_dir("other");
  {
    Probe p(dir, 4);
    study::run(p.st, study::Options{1, false, 600}, session);
  }
  auto refusal = [&](Probe& p) {
    try {
      study::run(p.st, study::Options{1, true, 600}, session);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  Probe more(dir, 5);  // another number of runs: another definition
  const std::string a = refusal(more);
  EXPECT_NE(a.find(dir.string() + "/study.progress: the study there is not this one"), std::string::npos) << a;
  Probe same(dir, 4);
  std::filesystem::resize_file(dir / "rows.csv", 20);  // shorter than the journal says
  const std::string b = refusal(same);
  EXPECT_NE(b.find(dir.string() + "/rows.csv: 20 bytes, the journal"), std::string::npos) << b;
  std::filesystem::remove(dir / "study.progress");
  const std::string c = refusal(same);
  EXPECT_NE(c.find("study.progress: not found, but " + dir.string() + "/rows.csv exists"), std::string::npos) << c;
}

TEST(Study, ResumeOfAnEmptyFolderStartsTheStudy) {
  study::Session session(argc0, argv0);
  const auto dir = test::scratch_dir("fresh") / "not-yet";
  Probe p(dir, 3);
  const study::Outcome o = study::run(p.st, study::Options{1, true, 600}, session);
  EXPECT_EQ(o.flown, 3);
  EXPECT_EQ(slurp(dir / "rows.csv"), expected_rows(3));
}
