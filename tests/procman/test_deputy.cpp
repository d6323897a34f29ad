// Deputy lifecycle with real child processes: start, output, stop with the stop
// signal, SIGKILL after the grace time, crash -> respawn with back-off, restart by
// run id, removal, stale orders, and no orphans left behind.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <limits>
#include <thread>

#include "procman/proc_stats.hpp"
#include "tests/procman/deputy_harness.hpp"
#include "tests/support/test_support.hpp"

using namespace aerie::procman;
using aerie::procman::test::CmdSpec;
using aerie::procman::test::DeputyHarness;
using Clock = std::chrono::steady_clock;

namespace {

bool alive(pid_t pid) {
  const auto p = read_process(pid);
  if (!p) return false;
  // A zombie is dead; /proc/<pid>/stat state 'Z'.
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  std::getline(in, line);
  const size_t rp = line.rfind(')');
  return rp != std::string::npos && line.size() > rp + 2 && line[rp + 2] != 'Z';
}

std::vector<pid_t> read_pids(const std::string& path) {
  std::ifstream in(path);
  std::vector<pid_t> out;
  for (pid_t p; in >> p;) out.push_back(p);
  return out;
}

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

}  // namespace

TEST(Deputy, StartsOnlyWhenTheRunIdChangesAndCapturesOutput) {
  DeputyHarness h;
  CmdSpec c;
  c.exec = "sh -c 'echo hello; echo oops >&2; exit 3'";
  c.runid = 0;  // a new command with run id 0 is not started (libbot2)
  ASSERT_EQ(h.order({c}), Deputy::OrdersResult::Applied);
  ASSERT_NE(h.cmd(1), nullptr);
  EXPECT_EQ(h.cmd(1)->pid, 0);

  c.runid = 1;
  h.order({c});
  EXPECT_GT(h.cmd(1)->pid, 0);
  ASSERT_TRUE(h.run_until([&] { return h.cmd(1)->pid == 0; }));
  h.run_for(50);
  EXPECT_NE(h.text(1).find("hello\n"), std::string::npos) << h.text(1);
  EXPECT_NE(h.text(1).find("oops\n"), std::string::npos) << h.text(1);
  EXPECT_NE(h.text(1).find("exited with code 3"), std::string::npos) << h.text(1);

  const auto info = h.deputy.report(123);
  EXPECT_EQ(info.host, "testhost");
  EXPECT_EQ(info.utime, 123);
  ASSERT_EQ(info.ncmds, 1);
  EXPECT_EQ(info.cmds[0].sheriff_id, 1);
  EXPECT_EQ(info.cmds[0].actual_runid, 1);
  EXPECT_EQ(info.cmds[0].pid, 0);
  EXPECT_TRUE(WIFEXITED(info.cmds[0].exit_code));
  EXPECT_EQ(WEXITSTATUS(info.cmds[0].exit_code), 3);
  EXPECT_EQ(info.cmds[0].cmd.exec_str, c.exec);
  EXPECT_GT(info.phys_mem_total_bytes, 0);

  // Same orders again: the run id is unchanged, so it is not started again.
  h.order({c});
  EXPECT_EQ(h.cmd(1)->pid, 0);
}

TEST(Deputy, ExpandsVariablesAndPassesEnvironment) {
  setenv("AERIE_DEPUTY_TEST_VAR", "from-env", 1);
  DeputyHarness h;
  CmdSpec c;
  c.exec = "GREETING=bonjour sh -c 'echo \"$GREETING ${AERIE_DEPUTY_TEST_VAR}\"' ${AERIE_DEPUTY_TEST_VAR}";
  h.order({c});
  ASSERT_TRUE(h.run_until([&] { return h.cmd(1)->pid == 0; }));
  h.run_for(30);
  EXPECT_NE(h.text(1).find("bonjour from-env"), std::string::npos) << h.text(1);
}

TEST(Deputy, ReportsCommandsThatCannotStart) {
  DeputyHarness h;
  CmdSpec missing;
  missing.exec = "aerie-no-such-program-42 --x";
  CmdSpec unset = missing;
  unset.id = 2;
  unset.exec = "echo $AERIE_SURELY_UNSET_VARIABLE";
  h.order({missing, unset});
  ASSERT_TRUE(h.run_until([&] { return h.cmd(1)->pid == 0; }));
  h.run_for(30);
  EXPECT_NE(h.text(1).find("cannot run 'aerie-no-such-program-42'"), std::string::npos) << h.text(1);
  EXPECT_EQ(WEXITSTATUS(h.cmd(1)->exit_status), 127);
  EXPECT_EQ(h.cmd(2)->pid, 0);
  EXPECT_NE(h.text(2).find("AERIE_SURELY_UNSET_VARIABLE is not set"), std::string::npos) << h.text(2);
  EXPECT_EQ(WEXITSTATUS(h.cmd(2)->exit_status), 127);
}

TEST(Deputy, StopSendsTheStopSignal) {
  DeputyHarness h;
  CmdSpec c;
  c.exec = "sleep 100";
  c.stop_signal = SIGTERM;
  c.stop_time_allowed = 10;
  h.order({c});
  const pid_t pid = h.cmd(1)->pid;
  ASSERT_GT(pid, 0);
  h.run_for(100);
  EXPECT_EQ(h.cmd(1)->state(), ProcState::Running);
  c.force_quit = true;
  const auto t0 = Clock::now();
  h.order({c});
  EXPECT_EQ(h.cmd(1)->state(), ProcState::Stopping);
  ASSERT_TRUE(h.run_until([&] { return h.cmd(1)->pid == 0; }));
  EXPECT_LT(ms_between(t0, Clock::now()), 5000.0);  // well before the 10 s grace time
  EXPECT_TRUE(WIFSIGNALED(h.cmd(1)->exit_status));
  EXPECT_EQ(WTERMSIG(h.cmd(1)->exit_status), SIGTERM);
  EXPECT_FALSE(alive(pid));
  EXPECT_EQ(h.cmd(1)->state(), ProcState::Stopped);
}

TEST(Deputy, SigkillFollowsAfterTheGraceTime) {
  DeputyHarness h;
  CmdSpec c;
  c.exec = "sh -c 'trap \"echo got TERM\" TERM; echo ready; while true; do sleep 0.05; done'";
  c.stop_signal = SIGTERM;
  c.stop_time_allowed = 0.6;
  h.order({c});
  ASSERT_TRUE(h.run_until([&] { return h.text(1).find("ready") != std::string::npos; }));
  c.force_quit = true;
  const auto t0 = Clock::now();
  h.order({c});
  ASSERT_TRUE(h.run_until([&] { return h.cmd(1)->pid == 0; }, 10000));
  const double elapsed = ms_between(t0, Clock::now());
  EXPECT_GE(elapsed, 600.0);   // not before the grace time
  EXPECT_LT(elapsed, 5000.0);
  EXPECT_NE(h.text(1).find("got TERM"), std::string::npos) << h.text(1);
  EXPECT_NE(h.text(1).find("sending SIGKILL"), std::string::npos) << h.text(1);
  EXPECT_EQ(WTERMSIG(h.cmd(1)->exit_status), SIGKILL);
}

TEST(Deputy, CrashIsRespawnedWithExponentialBackoff) {
  DeputyHarness h;  // back-off 50 ms doubling to 400 ms
  CmdSpec c;
  c.exec = "sh -c 'echo run; exit 1'";
  c.auto_respawn = true;
  h.order({c});
  ASSERT_TRUE(h.run_until([&] { return h.cmd(1)->restarts >= 6; }, 10000));
  // Start times: each "run" line. Delays between the exits and the next starts
  // follow 50, 100, 200, 400, 400 ms (lower bounds; the machine may be slow).
  std::vector<Clock::time_point> starts;
  for (const auto& o : h.output)
    if (o.id == 1 && o.text.find("run\n") != std::string::npos) starts.push_back(o.at);
  ASSERT_GE(starts.size(), 6u) << h.text(1);
  const double expected[] = {50, 100, 200, 400, 400};
  for (int k = 0; k < 5; ++k) {
    const double gap = ms_between(starts[k], starts[k + 1]);
    EXPECT_GE(gap, expected[k]) << "respawn " << k;
    EXPECT_LT(gap, expected[k] + 1500) << "respawn " << k;
  }
  EXPECT_NE(h.text(1).find("respawning in 400 ms"), std::string::npos);
  EXPECT_EQ(h.text(1).find("respawning in 800 ms"), std::string::npos);
  const int restarts = h.cmd(1)->restarts;
  // Stopping cancels the pending respawn.
  c.force_quit = true;
  h.order({c});
  h.run_for(700);
  EXPECT_EQ(h.cmd(1)->pid, 0);
  EXPECT_LE(h.cmd(1)->restarts, restarts + 1);
  EXPECT_EQ(h.cmd(1)->state(), ProcState::Stopped);
}

TEST(Deputy, BackoffResetsAfterAStableRun) {
  auto opts = DeputyHarness::default_options();
  opts.stable_run_s = 0.2;
  DeputyHarness h(opts);
  CmdSpec c;
  c.exec = "sh -c 'sleep 0.3; exit 1'";
  c.auto_respawn = true;
  h.order({c});
  ASSERT_TRUE(h.run_until([&] { return h.cmd(1)->restarts >= 3; }, 10000));
  EXPECT_EQ(h.text(1).find("respawning in 100 ms"), std::string::npos) << h.text(1);
  EXPECT_NE(h.text(1).find("respawning in 50 ms"), std::string::npos) << h.text(1);
}

TEST(Deputy, RestartsWhenTheRunIdChanges) {
  DeputyHarness h;
  CmdSpec c;
  c.exec = "sleep 100";
  h.order({c});
  const pid_t first = h.cmd(1)->pid;
  ASSERT_GT(first, 0);
  c.runid = 2;
  h.order({c});
  EXPECT_EQ(h.cmd(1)->state(), ProcState::Stopping);
  ASSERT_TRUE(h.run_until([&] { return h.cmd(1)->pid != 0 && h.cmd(1)->pid != first; }));
  EXPECT_EQ(h.cmd(1)->actual_runid, 2);
  EXPECT_FALSE(alive(first));
}

TEST(Deputy, CommandsMissingFromOrdersAreStoppedAndRemoved) {
  DeputyHarness h;
  CmdSpec a, b;
  a.exec = b.exec = "sleep 100";
  b.id = 2;
  b.name = "b";
  h.order({a, b});
  const pid_t pb = h.cmd(2)->pid;
  ASSERT_GT(pb, 0);
  h.order({a});
  ASSERT_TRUE(h.run_until([&] { return h.cmd(2) == nullptr; }));
  EXPECT_FALSE(alive(pb));
  ASSERT_NE(h.cmd(1), nullptr);
  EXPECT_GT(h.cmd(1)->pid, 0);
  EXPECT_EQ(h.deputy.report(0).ncmds, 1);
}

TEST(Deputy, RefusesStaleOrdersAndTellsToCheckTheClocks) {
  DeputyHarness h;
  CmdSpec c;
  c.exec = "sleep 100";
  EXPECT_EQ(h.order({c}, /*age_us=*/120'000'000), Deputy::OrdersResult::Stale);
  EXPECT_EQ(h.cmd(1), nullptr);
  const std::string msg = h.text(0);
  EXPECT_NE(msg.find("120."), std::string::npos) << msg;
  EXPECT_NE(msg.find("Check that the clocks"), std::string::npos) << msg;
  // Fresh orders are taken; orders for another deputy are ignored.
  EXPECT_EQ(h.order({c}, 1'000'000), Deputy::OrdersResult::Applied);
  EXPECT_GT(h.cmd(1)->pid, 0);
  EXPECT_EQ(h.deputy.handle_orders(aerie::procman::test::make_orders("other", {}), aerie::util::wall_utime()),
            Deputy::OrdersResult::OtherHost);
  EXPECT_NE(h.cmd(1), nullptr);
}

// The orders' stamp comes off the network: INT64_MIN (the fuzzer's find,
// fuzz/regressions/procman_messages/orders2_utime_INT64_MIN.bin) overflowed the age's int64
// difference. They are orders from the distant past: refused as stale, nothing started.
TEST(Deputy, OrdersWithAHostileStampAreRefusedAsStale) {
  DeputyHarness h;
  CmdSpec c;
  c.exec = "sleep 100";
  auto orders = aerie::procman::test::make_orders(h.deputy.name(), {c});
  orders.utime = std::numeric_limits<int64_t>::min();
  EXPECT_EQ(h.deputy.handle_orders(orders, aerie::util::wall_utime()), Deputy::OrdersResult::Stale);
  EXPECT_EQ(h.cmd(1), nullptr);
}

TEST(Deputy, NoOrphansSurviveAStop) {
  DeputyHarness h;
  const auto dir = aerie::test::scratch_dir("orphans");
  const std::string pids = (dir / "pids").string();
  CmdSpec c;
  // Two background children and one that leaves the session (setsid).
  c.exec = "sh -c 'sleep 1000 & echo $! >> " + pids + "; setsid sleep 1000 & echo $! >> " + pids +
           "; sh -c \"sleep 1000 & echo \\$! >> " + pids + "; wait\" & echo ready; wait'";
  c.stop_time_allowed = 1;
  h.order({c});
  ASSERT_TRUE(h.run_until([&] { return read_pids(pids).size() >= 3; }));
  const auto children = read_pids(pids);
  for (pid_t p : children) EXPECT_TRUE(alive(p)) << p;
  c.force_quit = true;
  h.order({c});
  ASSERT_TRUE(h.run_until([&] {
    if (h.cmd(1)->pid != 0) return false;
    for (pid_t p : children)
      if (alive(p)) return false;
    return true;
  }, 10000));
}

TEST(Deputy, OrphansOfACrashedCommandAreKilled) {
  DeputyHarness h;
  const auto dir = aerie::test::scratch_dir("crash");
  const std::string pids = (dir / "pids").string();
  CmdSpec c;
  c.exec = "sh -c 'setsid sleep 1000 & echo $! >> " + pids + "; sleep 1000 & echo $! >> " + pids + "; wait'";
  h.order({c});
  ASSERT_TRUE(h.run_until([&] { return read_pids(pids).size() >= 2; }));
  const auto children = read_pids(pids);
  for (pid_t p : children) ASSERT_TRUE(alive(p)) << p;
  kill(h.cmd(1)->pid, SIGKILL);  // the command crashes, its children are orphaned
  ASSERT_TRUE(h.run_until([&] { return h.cmd(1)->pid == 0; }));
  h.run_until([&] {
    h.deputy.sample_usage();  // the periodic sweep of orphans re-parented to the deputy
    for (pid_t p : children)
      if (alive(p)) return false;
    return true;
  }, 5000);
  for (pid_t p : children) EXPECT_FALSE(alive(p)) << p;
}

TEST(Deputy, ShutdownLeavesNothingRunning) {
  std::vector<pid_t> children;
  std::vector<pid_t> leaders;
  const auto dir = aerie::test::scratch_dir("shutdown");
  const std::string pids = (dir / "pids").string();
  {
    DeputyHarness h;
    std::vector<CmdSpec> cmds;
    for (int i = 1; i <= 3; ++i) {
      CmdSpec c;
      c.id = i;
      c.name = "c" + std::to_string(i);
      // Ignores SIGTERM: only SIGKILL after the grace time ends it.
      c.exec = "sh -c 'trap \"\" TERM; sleep 1000 & echo $! >> " + pids + "; wait'";
      c.stop_time_allowed = 0.3;
      cmds.push_back(c);
    }
    h.order(cmds);
    ASSERT_TRUE(h.run_until([&] { return read_pids(pids).size() >= 3; }));
    for (int i = 1; i <= 3; ++i) leaders.push_back(h.cmd(i)->pid);
    children = read_pids(pids);
    for (pid_t p : children) ASSERT_TRUE(alive(p)) << p;
    const auto t0 = Clock::now();
    h.deputy.shutdown();
    EXPECT_LT(ms_between(t0, Clock::now()), 5000.0);
    EXPECT_TRUE(h.deputy.commands().empty());
    EXPECT_EQ(h.deputy.handle_orders(aerie::procman::test::make_orders("testhost", cmds), aerie::util::wall_utime()),
              Deputy::OrdersResult::Exiting);
  }
  for (pid_t p : leaders) EXPECT_FALSE(alive(p)) << p;
  for (pid_t p : children) EXPECT_FALSE(alive(p)) << p;
}

// Issue 49: the first sample after a start had no CPU figure (it waited for a previous sample
// with CPU time), so a busy command showed 0 % for its first reports. A new process has used
// none: the first sample measures from the start.
TEST(Deputy, TheFirstSampleAfterTheStartHasACpuFigure) {
  DeputyHarness h;
  CmdSpec c;
  c.exec = "sh -c 'while :; do :; done'";
  h.order({c});
  h.run_for(500);
  h.deputy.sample_usage();
  const auto info = h.deputy.report(0);
  ASSERT_EQ(info.ncmds, 1);
  ASSERT_GT(info.cmds[0].pid, 0);
  EXPECT_GT(info.cmds[0].cpu_usage, 0.02f);
  EXPECT_LE(info.cmds[0].cpu_usage, 1.0f);
  EXPECT_GT(info.cmds[0].mem_rss_bytes, 0);
}

TEST(Deputy, ReportsCpuAndMemory) {
  DeputyHarness h;
  CmdSpec c;
  c.exec = "sh -c 'while :; do :; done'";
  h.order({c});
  h.deputy.sample_usage();
  for (int i = 0; i < 3; ++i) {
    h.run_for(400);
    h.deputy.sample_usage();
  }
  const auto info = h.deputy.report(0);
  ASSERT_EQ(info.ncmds, 1);
  EXPECT_GT(info.cmds[0].cpu_usage, 0.02f);  // fraction of the whole host
  EXPECT_LE(info.cmds[0].cpu_usage, 1.0f);
  EXPECT_GT(info.cmds[0].mem_rss_bytes, 0);
  EXPECT_GT(info.cmds[0].mem_vsize_bytes, info.cmds[0].mem_rss_bytes);
  EXPECT_GT(info.cpu_load, 0.0f);
  EXPECT_GT(info.phys_mem_free_bytes, 0);
  EXPECT_LE(info.phys_mem_free_bytes, info.phys_mem_total_bytes);
}

// --- Safety: no command starts unless the current orders ask for a run ----------

TEST(DeputySafety, UnknownIdStartsOnlyWhenTheOrdersAskForARun) {
  DeputyHarness h;
  CmdSpec idle, quit, run;
  idle.id = 1001;
  idle.name = "idle";
  idle.exec = "sleep 100";
  idle.runid = 0;  // never asked to run
  quit = idle;
  quit.id = 1002;
  quit.name = "quit";
  quit.runid = 7;
  quit.force_quit = true;  // a run id, but stopped
  run = idle;
  run.id = 1003;
  run.name = "run";
  run.runid = 1;  // asked to run
  h.order({idle, quit, run});
  EXPECT_EQ(h.cmd(1001)->pid, 0);
  EXPECT_EQ(h.cmd(1002)->pid, 0);
  EXPECT_GT(h.cmd(1003)->pid, 0);
  h.run_for(100);
  h.order({idle, quit, run});  // the same orders again change nothing
  EXPECT_EQ(h.cmd(1001)->pid, 0);
  EXPECT_EQ(h.cmd(1002)->pid, 0);
  EXPECT_EQ(h.cmd(1002)->actual_runid, 7);
}

// The reported fault: a deputy holding stopped commands of an earlier sheriff that
// numbered its ids 1..N gets orders of another config whose commands reuse those
// ids with run id 0. Nothing may start.
TEST(DeputySafety, ReusedIdsOfAnotherCommandAreNotStarted) {
  DeputyHarness h;
  std::vector<CmdSpec> old_cmds;
  for (int i = 1; i <= 3; ++i) {
    CmdSpec c;
    c.id = i;
    c.name = "old" + std::to_string(i);
    c.exec = "sleep 100";
    c.runid = 2;
    old_cmds.push_back(c);
  }
  h.order(old_cmds);
  for (int i = 1; i <= 3; ++i) ASSERT_GT(h.cmd(i)->pid, 0);
  for (auto& c : old_cmds) c.force_quit = true;  // the first sheriff stops them
  h.order(old_cmds);
  ASSERT_TRUE(h.run_until([&] { return h.cmd(1)->pid == 0 && h.cmd(2)->pid == 0 && h.cmd(3)->pid == 0; }));
  h.output.clear();

  std::vector<CmdSpec> new_cmds;
  for (int i = 1; i <= 3; ++i) {
    CmdSpec c;
    c.id = i;
    c.name = "new" + std::to_string(i);
    c.exec = "sleep 100";
    c.runid = 0;  // a fresh sheriff, no script: nothing asked to run
    new_cmds.push_back(c);
  }
  auto o = aerie::procman::test::make_orders("testhost", new_cmds);
  o.sheriff_name = "other-sheriff";
  ASSERT_EQ(h.deputy.handle_orders(o, aerie::util::wall_utime()), Deputy::OrdersResult::Applied);
  h.run_for(200);
  h.deputy.handle_orders(o, aerie::util::wall_utime());
  for (int i = 1; i <= 3; ++i) {
    EXPECT_EQ(h.cmd(i)->pid, 0) << "command " << i << " started without being asked";
    EXPECT_EQ(h.cmd(i)->cmd.command_name, "new" + std::to_string(i));
    EXPECT_EQ(h.cmd(i)->exit_status, 0);  // the old command's exit is not the new one's
  }
  EXPECT_NE(h.text(0).find("taking orders from sheriff 'other-sheriff'"), std::string::npos) << h.text(0);
  EXPECT_NE(h.text(0).find("names id 1 [new1], which here was [old1]"), std::string::npos) << h.text(0);

  // The new sheriff asks for a run: now it starts.
  new_cmds[0].runid = 1;
  o = aerie::procman::test::make_orders("testhost", new_cmds);
  o.sheriff_name = "other-sheriff";
  h.deputy.handle_orders(o, aerie::util::wall_utime());
  EXPECT_GT(h.cmd(1)->pid, 0);
  EXPECT_EQ(h.cmd(2)->pid, 0);
}

TEST(DeputySafety, ARunningCommandWhoseIdIsReusedIsStoppedAndTheNewOneWaits) {
  DeputyHarness h;
  CmdSpec old_cmd;
  old_cmd.id = 5;
  old_cmd.name = "old";
  old_cmd.exec = "sleep 100";
  old_cmd.runid = 3;
  h.order({old_cmd});
  const pid_t old_pid = h.cmd(5)->pid;
  ASSERT_GT(old_pid, 0);
  CmdSpec new_cmd = old_cmd;
  new_cmd.name = "new";
  new_cmd.runid = 1;  // differs from the old run id 3, but is not a request to start "new"
  h.order({new_cmd});
  ASSERT_TRUE(h.run_until([&] { return h.cmd(5)->pid == 0; }));
  EXPECT_FALSE(alive(old_pid));
  h.run_for(200);
  h.order({new_cmd});
  EXPECT_EQ(h.cmd(5)->pid, 0);
  EXPECT_EQ(h.cmd(5)->exit_status, 0);
  new_cmd.runid = 2;
  h.order({new_cmd});
  EXPECT_GT(h.cmd(5)->pid, 0);
  EXPECT_NE(h.cmd(5)->pid, old_pid);
}

TEST(DeputySafety, ObeysTheNewestSheriffAndDropsWhatItDoesNotName) {
  DeputyHarness h;
  CmdSpec a;
  a.id = 11;
  a.name = "a";
  a.exec = "sleep 100";
  auto oa = aerie::procman::test::make_orders("testhost", {a});
  oa.sheriff_name = "sheriff-A";
  h.deputy.handle_orders(oa, aerie::util::wall_utime());
  const pid_t pa = h.cmd(11)->pid;
  ASSERT_GT(pa, 0);

  CmdSpec b;
  b.id = 22;
  b.name = "b";
  b.exec = "sleep 100";
  b.runid = 0;
  auto ob = aerie::procman::test::make_orders("testhost", {b});
  ob.sheriff_name = "sheriff-B";
  h.deputy.handle_orders(ob, aerie::util::wall_utime());
  ASSERT_TRUE(h.run_until([&] { return h.cmd(11) == nullptr; }));
  EXPECT_FALSE(alive(pa));
  ASSERT_NE(h.cmd(22), nullptr);
  EXPECT_EQ(h.cmd(22)->pid, 0);
  EXPECT_NE(h.text(0).find("taking orders from sheriff 'sheriff-B' (previous orders came from 'sheriff-A')"),
            std::string::npos)
      << h.text(0);
  // An observer sends nothing; empty orders from a sheriff with no command for
  // this host stop and remove everything (libbot2).
  auto empty = aerie::procman::test::make_orders("testhost", {});
  empty.sheriff_name = "sheriff-C";
  h.deputy.handle_orders(empty, aerie::util::wall_utime());
  EXPECT_TRUE(h.deputy.commands().empty());
}
