// Sheriff logic: command states from deputy reports, orders, adoption of running
// commands, observer mode, and scripts run against a real in-process deputy.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <limits>
#include <set>

#include "procman/sheriff.hpp"
#include "tests/procman/deputy_harness.hpp"

using namespace aerie::procman;

namespace {

const char* kConfig = R"PMD(
group "vision" {
  cmd "sleeper" { exec = "sleep 100"; host = "testhost"; stop_signal = 15; stop_time_allowed = 2; }
  group "stereo" {
    cmd "talker" { exec = "sh -c 'echo talking; sleep 100'"; host = "testhost"; stop_signal = 15; }
  }
}
cmd "ground-thing" { exec = "sleep 100"; host = "ground"; }
script "start_vision" {
  start group "vision" wait "running";
  wait ms 100;
  restart cmd "sleeper" wait "running";
  stop everything wait "stopped";
}
script "outer" { run_script "start_vision"; }
script "never" { wait cmd "ground-thing" status "running"; }
)PMD";

bot_procman::deputy_cmd2_t reported(int32_t id, const std::string& name, int32_t pid, int32_t runid,
                                    int exit_status = 0, bool respawn = false) {
  bot_procman::deputy_cmd2_t d;
  d.cmd.command_name = name;
  d.cmd.exec_str = "x";
  d.cmd.auto_respawn = respawn;
  d.cmd.num_options = 0;
  d.pid = pid;
  d.actual_runid = runid;
  d.exit_code = exit_status;
  d.cpu_usage = 0.25f;
  d.mem_vsize_bytes = 2 << 20;
  d.mem_rss_bytes = 1 << 20;
  d.sheriff_id = id;
  return d;
}

bot_procman::info2_t info(const std::string& host, std::vector<bot_procman::deputy_cmd2_t> cmds) {
  bot_procman::info2_t m;
  m.utime = 1;
  m.host = host;
  m.cpu_load = 0.5f;
  m.phys_mem_total_bytes = 8LL << 30;
  m.phys_mem_free_bytes = 4LL << 30;
  m.swap_total_bytes = m.swap_free_bytes = 0;
  m.cmds = std::move(cmds);
  m.ncmds = static_cast<int32_t>(m.cmds.size());
  m.num_options = 0;
  return m;
}

// Runs sheriff <-> deputy in one process (orders and reports passed directly).
struct Loop {
  Sheriff sheriff{"test-sheriff"};
  test::DeputyHarness deputy;
  int64_t now_ms = 0;

  void exchange() {
    for (const auto& o : sheriff.orders(aerie::util::wall_utime()))
      deputy.deputy.handle_orders(o, aerie::util::wall_utime());
    deputy.run_for(10);
    now_ms += 10;
    sheriff.on_info(deputy.deputy.report(aerie::util::wall_utime()), now_ms);
  }
};

}  // namespace

TEST(Sheriff, LoadsConfigAndSelectsTargets) {
  Sheriff s("sh");
  s.load(parse_pmd(kConfig));
  ASSERT_EQ(s.commands().size(), 3u);
  std::set<int32_t> ids;
  for (const auto& c : s.commands()) {
    EXPECT_GT(c.sheriff_id, 0);
    ids.insert(c.sheriff_id);
  }
  EXPECT_EQ(ids.size(), 3u);  // unique, also across hosts
  EXPECT_EQ(s.commands()[0].cmd.stop_signal, 15);
  EXPECT_FLOAT_EQ(s.commands()[0].cmd.stop_time_allowed, 2.0f);
  EXPECT_EQ(s.select(TargetKind::Group, "vision").size(), 2u);
  EXPECT_EQ(s.select(TargetKind::Group, "vision/stereo").size(), 1u);
  EXPECT_EQ(s.select(TargetKind::Everything, "").size(), 3u);
  EXPECT_THROW(s.select(TargetKind::Command, "nope"), std::invalid_argument);
  EXPECT_THROW(s.select(TargetKind::Group, "visio"), std::invalid_argument);
}

TEST(Sheriff, OrdersOnlyForDeputiesHeardFrom) {
  Sheriff s("sh");
  s.load(parse_pmd(kConfig));
  EXPECT_TRUE(s.orders(5).empty());
  s.on_info(info("testhost", {}), 0);
  EXPECT_TRUE(s.take_dirty());
  EXPECT_FALSE(s.take_dirty());
  const auto orders = s.orders(5);
  ASSERT_EQ(orders.size(), 1u);
  EXPECT_EQ(orders[0].host, "testhost");
  EXPECT_EQ(orders[0].sheriff_name, "sh");
  EXPECT_EQ(orders[0].utime, 5);
  ASSERT_EQ(orders[0].ncmds, 2);
  EXPECT_EQ(orders[0].cmds[0].cmd.command_name, "sleeper");
  EXPECT_EQ(orders[0].cmds[0].cmd.group, "vision");
  EXPECT_EQ(orders[0].cmds[1].cmd.group, "vision/stereo");
  EXPECT_EQ(orders[0].cmds[0].desired_runid, 0);
  EXPECT_EQ(orders[0].cmds[0].force_quit, 0);

  s.start(s.select(TargetKind::Command, "sleeper"));
  EXPECT_TRUE(s.take_dirty());
  EXPECT_EQ(s.orders(6)[0].cmds[0].desired_runid, 1);
  s.stop(s.select(TargetKind::Command, "sleeper"));
  EXPECT_EQ(s.orders(6)[0].cmds[0].force_quit, 1);
}

TEST(Sheriff, DerivesCommandStatesFromReports) {
  Sheriff s("sh", false, /*deputy_timeout_s=*/3.0);
  s.load(parse_pmd(kConfig));
  const auto sleeper = s.select(TargetKind::Command, "sleeper");
  const int32_t id = s.find_by_name("sleeper")->sheriff_id;
  auto state = [&](int64_t now) { return s.status(*s.find_by_name("sleeper"), now); };
  EXPECT_EQ(state(0), CommandStatus::Unknown);  // no deputy yet
  s.on_info(info("testhost", {reported(id, "sleeper", 0, 0)}), 0);
  EXPECT_EQ(state(0), CommandStatus::Stopped);  // never started
  s.start(sleeper);
  EXPECT_EQ(state(0), CommandStatus::Starting);
  s.on_info(info("testhost", {reported(id, "sleeper", 100, 1)}), 100);
  EXPECT_EQ(state(100), CommandStatus::Running);
  EXPECT_TRUE(s.reached(sleeper, WaitFor::Running, 100));
  EXPECT_FALSE(s.reached(sleeper, WaitFor::Stopped, 100));
  s.restart(sleeper);
  EXPECT_EQ(state(100), CommandStatus::Restarting);
  EXPECT_FALSE(s.reached(sleeper, WaitFor::Running, 100));
  s.on_info(info("testhost", {reported(id, "sleeper", 101, 2)}), 200);
  EXPECT_EQ(state(200), CommandStatus::Running);
  s.stop(sleeper);
  EXPECT_EQ(state(200), CommandStatus::Stopping);
  s.on_info(info("testhost", {reported(id, "sleeper", 0, 2, W_EXITCODE(0, SIGTERM))}), 300);
  EXPECT_EQ(state(300), CommandStatus::Stopped);  // ended by its stop signal after our order
  EXPECT_TRUE(s.reached(sleeper, WaitFor::Stopped, 300));
  s.on_info(info("testhost", {reported(id, "sleeper", 0, 2, W_EXITCODE(0, 0))}), 400);
  EXPECT_EQ(state(400), CommandStatus::Stopped);
  // The deputy falls silent: unknown after the timeout.
  EXPECT_EQ(state(3400), CommandStatus::Stopped);
  EXPECT_EQ(state(3401), CommandStatus::Unknown);
  EXPECT_FALSE(s.deputy_alive("testhost", 3401));
  // A respawning command (auto_respawn, ended by itself).
  s.start(sleeper);
  s.on_info(info("testhost", {reported(id, "sleeper", 0, 3, W_EXITCODE(1, 0), true)}), 4000);
  EXPECT_EQ(state(4000), CommandStatus::Respawning);
  const std::string table = s.table(4000);
  EXPECT_NE(table.find("respawning"), std::string::npos) << table;
  EXPECT_NE(table.find("code 1"), std::string::npos) << table;
  EXPECT_NE(table.find("testhost"), std::string::npos) << table;
}

// A report's memory figures come off the network: total = INT64_MIN (the fuzzer's find,
// fuzz/regressions/procman_messages/info2_phys_mem_total_INT64_MIN.bin) overflowed the int64
// difference the table took; it wrapped to about +8.8e12 MiB here. Now the difference is taken
// in double, and the table shows the figure as the deputy sent it.
TEST(Sheriff, HostileMemoryFiguresDoNotOverflowTheTable) {
  Sheriff s("test-sheriff");
  bot_procman::info2_t m = info("testhost", {});
  m.phys_mem_total_bytes = std::numeric_limits<int64_t>::min();
  m.phys_mem_free_bytes = 4866197946368;
  s.on_info(m, 100);
  const DeputyView& dv = s.deputies().at("testhost");
  EXPECT_LT(dv.used_mib(), -8.7e12);
  EXPECT_DOUBLE_EQ(dv.used_mib(), (-9223372036854775808.0 - 4866197946368.0) / 1048576.0);
  const std::string table = s.table(100);
  EXPECT_NE(table.find("-8796097662976/"), std::string::npos) << table;
}

// Issue 49: a script's last table (--script start_all --on-script-complete exit) showed 0.0 %
// and 0.0 MiB for every running command: the deputy reports a start at once, before its next
// sample. Such a report (running, RSS 0) is shown as "-"; a sampled one with its figures.
TEST(Sheriff, TheTableShowsADashForARunningCommandNotSampledYet) {
  Sheriff s("sh");
  s.load(parse_pmd(kConfig));
  const int32_t id = s.find_by_name("sleeper")->sheriff_id;
  auto row = [&](int64_t now) {
    const std::string table = s.table(now);
    const size_t at = table.find("sleeper");
    return at == std::string::npos ? std::string() : table.substr(at, table.find('\n', at) - at);
  };
  bot_procman::deputy_cmd2_t d = reported(id, "sleeper", 100, 1);
  d.cpu_usage = 0;
  d.mem_vsize_bytes = d.mem_rss_bytes = 0;
  s.on_info(info("testhost", {d}), 0);
  EXPECT_EQ(row(0), "sleeper              vision         running          100      -         -        0  -") << row(0);
  s.on_info(info("testhost", {reported(id, "sleeper", 100, 1)}), 1000);  // sampled: 25 %, 1 MiB
  EXPECT_EQ(row(1000), "sleeper              vision         running          100  25.0%       1.0        0  -") << row(1000);
}

TEST(Sheriff, CountsRespawnsFromPidChanges) {
  Sheriff s("sh");
  s.load(parse_pmd(kConfig));
  s.on_info(info("testhost", {reported(1, "sleeper", 10, 1)}), 0);
  s.on_info(info("testhost", {reported(1, "sleeper", 0, 1, W_EXITCODE(1, 0), true)}), 1);
  s.on_info(info("testhost", {reported(1, "sleeper", 11, 1)}), 2);
  s.on_info(info("testhost", {reported(1, "sleeper", 12, 1)}), 3);
  EXPECT_EQ(s.find("testhost", 1)->restarts, 2);
  s.on_info(info("testhost", {reported(1, "sleeper", 13, 2)}), 4);  // a new run: not a respawn
  EXPECT_EQ(s.find("testhost", 1)->restarts, 2);
}

TEST(Sheriff, AdoptsWhatADeputyAlreadyRuns) {
  // A sheriff restarted while the deputy runs "talker" under id 7, run 4.
  Sheriff s("sh");
  s.load(parse_pmd(kConfig));
  s.on_info(info("testhost", {reported(7, "talker", 555, 4)}), 0);
  const SheriffCommand* t = s.find_by_name("talker");
  EXPECT_EQ(t->sheriff_id, 7);
  EXPECT_EQ(t->desired_runid, 4);
  EXPECT_EQ(s.status(*t, 0), CommandStatus::Running);
  // Orders keep it as it is: same id, same run id.
  const auto o = s.orders(1)[0];
  const auto it = std::find_if(o.cmds.begin(), o.cmds.end(), [](const auto& c) { return c.cmd.command_name == "talker"; });
  ASSERT_NE(it, o.cmds.end());
  EXPECT_EQ(it->sheriff_id, 7);
  EXPECT_EQ(it->desired_runid, 4);
  EXPECT_EQ(it->force_quit, 0);
}

TEST(Sheriff, ObserverShowsWhatDeputiesReportAndSendsNothing) {
  Sheriff s("watcher", /*observer=*/true);
  s.on_info(info("air", {reported(3, "capture", 42, 1), reported(4, "vo", 0, 0)}), 0);
  ASSERT_EQ(s.commands().size(), 2u);
  EXPECT_EQ(s.status(*s.find("air", 3), 0), CommandStatus::Running);
  EXPECT_EQ(s.status(*s.find("air", 4), 0), CommandStatus::Stopped);
  EXPECT_TRUE(s.orders(1).empty());
  s.on_info(info("air", {reported(3, "capture", 42, 1)}), 1);
  EXPECT_EQ(s.commands().size(), 1u);
}

TEST(Sheriff, ScriptDrivesARealDeputy) {
  Loop loop;
  const PmdConfig cfg = parse_pmd(R"PMD(
group "vision" {
  cmd "sleeper" { exec = "sleep 100"; host = "testhost"; stop_signal = 15; stop_time_allowed = 2; }
  cmd "talker" { exec = "sh -c 'echo talking; sleep 100'"; host = "testhost"; stop_signal = 15; }
}
script "go" {
  start group "vision" wait "running";
  wait ms 100;
  restart cmd "sleeper" wait "running";
  stop everything wait "stopped";
}
script "outer" { run_script "go"; }
)PMD");
  loop.sheriff.load(cfg);
  std::vector<std::string> log;
  ScriptRunner runner(loop.sheriff, cfg, "outer", [&](const std::string& m) { log.push_back(m); }, 20.0);
  loop.exchange();  // the deputy is heard from
  pid_t first_sleeper = 0;
  bool restarted = false;
  for (int i = 0; i < 2000 && runner.step(loop.now_ms) == ScriptRunner::Status::Running; ++i) {
    loop.exchange();
    const auto* c = loop.deputy.cmd(loop.sheriff.find_by_name("sleeper")->sheriff_id);
    if (c && c->pid && !first_sleeper) first_sleeper = c->pid;
    if (c && c->pid && first_sleeper && c->pid != first_sleeper) restarted = true;
  }
  ASSERT_EQ(runner.status(), ScriptRunner::Status::Done) << runner.error();
  EXPECT_TRUE(restarted);
  for (const auto& c : loop.sheriff.commands()) EXPECT_FALSE(c.last.pid) << c.cmd.command_name;
  EXPECT_NE(loop.deputy.text(loop.sheriff.find_by_name("talker")->sheriff_id).find("talking"), std::string::npos);
  ASSERT_GE(log.size(), 6u);
  EXPECT_EQ(log[0], "run_script \"go\"");
  EXPECT_EQ(log.back(), "  ... everything stopped");
}

TEST(Sheriff, ScriptWaitTimesOutWithAMessage) {
  Sheriff s("sh");
  const PmdConfig cfg = parse_pmd(kConfig, "k.pmd");
  s.load(cfg);
  ScriptRunner r(s, cfg, "never", {}, /*wait_timeout_s=*/1.0);
  EXPECT_EQ(r.step(0), ScriptRunner::Status::Running);
  EXPECT_EQ(r.next_timer_ms(0), 1000);
  EXPECT_EQ(r.step(999), ScriptRunner::Status::Running);
  EXPECT_EQ(r.step(1001), ScriptRunner::Status::Failed);
  EXPECT_NE(r.error().find("waiting for cmd \"ground-thing\" to be running"), std::string::npos) << r.error();
  EXPECT_THROW(ScriptRunner(s, cfg, "missing"), std::invalid_argument);
}

// --- Ids, sessions and statuses --------------------------------------------------

namespace {

std::string many_commands(int n) {
  std::string pmd;
  for (int i = 0; i < n; ++i)
    pmd += "cmd \"c" + std::to_string(i) + "\" { exec = \"true\"; host = \"" + (i % 2 ? "air" : "ground") + "\"; }\n";
  return pmd;
}

// One sheriff <-> one in-process deputy: orders and reports passed directly.
void exchange(Sheriff& s, test::DeputyHarness& d, int64_t& now_ms, int rounds = 1) {
  for (int i = 0; i < rounds; ++i) {
    for (const auto& o : s.orders(aerie::util::wall_utime())) d.deputy.handle_orders(o, aerie::util::wall_utime());
    d.run_for(10);
    now_ms += 10;
    s.on_info(d.deputy.report(aerie::util::wall_utime()), now_ms);
  }
}

bool any_running(const test::DeputyHarness& d) {
  for (const auto& [id, c] : d.deputy.commands())
    if (c.pid != 0) return true;
  return false;
}

}  // namespace

TEST(SheriffIds, RandomNonZeroUniqueAndDifferentAcrossSessions) {
  const PmdConfig cfg = parse_pmd(many_commands(200));
  Sheriff a("a"), b("b");
  a.load(cfg);
  b.load(cfg);
  std::set<int32_t> ids_a, ids_b;
  for (const auto& c : a.commands()) {
    EXPECT_GE(c.sheriff_id, 1);
    EXPECT_LE(c.sheriff_id, std::numeric_limits<int32_t>::max());
    ids_a.insert(c.sheriff_id);
  }
  for (const auto& c : b.commands()) ids_b.insert(c.sheriff_id);
  EXPECT_EQ(ids_a.size(), 200u);  // unique within the session (on all hosts)
  EXPECT_EQ(ids_b.size(), 200u);
  // Two sessions share no id (chance of any overlap: ~200*200/2^31 = 2e-5).
  std::vector<int32_t> common;
  std::set_intersection(ids_a.begin(), ids_a.end(), ids_b.begin(), ids_b.end(), std::back_inserter(common));
  EXPECT_TRUE(common.empty());
  // Spread over the 31-bit range, not numbered 1..N: the median is near 2^30.
  std::vector<int32_t> v(ids_a.begin(), ids_a.end());
  EXPECT_GT(v[v.size() / 2], 1 << 28);
  EXPECT_LT(v[v.size() / 2], std::numeric_limits<int32_t>::max() - (1 << 28));
  // A fixed seed gives the same ids (reproducible tests), another seed others.
  Sheriff s1("s", false, 3.0, 42), s2("s", false, 3.0, 42), s3("s", false, 3.0, 43);
  s1.load(cfg);
  s2.load(cfg);
  s3.load(cfg);
  EXPECT_EQ(s1.commands()[0].sheriff_id, s2.commands()[0].sheriff_id);
  EXPECT_NE(s1.commands()[0].sheriff_id, s3.commands()[0].sheriff_id);
}

TEST(SheriffIds, OurIdsAvoidIdsTheDeputyHoldsForOtherCommands) {
  Sheriff s("s", false, 3.0, 7);
  s.load(parse_pmd(R"(cmd "mine" { exec = "true"; host = "testhost"; })"));
  const int32_t mine = s.commands()[0].sheriff_id;
  // The deputy happens to hold `mine`'s id for another command.
  s.on_info(info("testhost", {reported(mine, "someone-elses", 0, 3)}), 0);
  EXPECT_NE(s.commands()[0].sheriff_id, mine);
  EXPECT_GT(s.commands()[0].sheriff_id, 0);
}

TEST(SheriffStatus, StoppedOnOrderReadsStoppedEndingByItselfReadsFailed) {
  Sheriff s("s");
  s.load(parse_pmd(R"PMD(
cmd "polite" { exec = "sleep 100"; host = "testhost"; }
cmd "stubborn" { exec = "sh -c 'trap \"\" INT TERM; echo ready; while :; do sleep 0.05; done'"; host = "testhost"; stop_time_allowed = 0.3; }
cmd "exit0" { exec = "true"; host = "testhost"; }
cmd "exit3" { exec = "sh -c 'exit 3'"; host = "testhost"; }
cmd "selfkill" { exec = "sh -c 'kill -TERM $$'"; host = "testhost"; }
cmd "killed" { exec = "sleep 100"; host = "testhost"; }
)PMD"));
  test::DeputyHarness d;
  int64_t now = 0;
  exchange(s, d, now);
  s.start(s.select(TargetKind::Everything, ""));
  auto st = [&](const char* name) { return s.status(*s.find_by_name(name), now); };
  auto pid_of = [&](const char* name) { return d.cmd(s.find_by_name(name)->sheriff_id)->pid; };
  for (int i = 0; i < 300 && !(st("polite") == CommandStatus::Running && st("stubborn") == CommandStatus::Running &&
                               st("killed") == CommandStatus::Running && d.text(s.find_by_name("stubborn")->sheriff_id).find("ready") != std::string::npos);
       ++i)
    exchange(s, d, now);
  ASSERT_EQ(st("polite"), CommandStatus::Running);
  ASSERT_EQ(st("stubborn"), CommandStatus::Running);
  kill(pid_of("killed"), SIGKILL);  // dies of a signal on its own (OOM killer, say)
  s.stop(s.select(TargetKind::Command, "polite"));
  s.stop(s.select(TargetKind::Command, "stubborn"));
  for (int i = 0; i < 500 && (st("polite") != CommandStatus::Stopped || st("stubborn") != CommandStatus::Stopped ||
                              st("killed") != CommandStatus::Failed);
       ++i)
    exchange(s, d, now);
  const auto& polite = s.find_by_name("polite")->last;
  const auto& stubborn = s.find_by_name("stubborn")->last;
  EXPECT_EQ(st("polite"), CommandStatus::Stopped);  // SIGINT, its stop signal
  EXPECT_TRUE(WIFSIGNALED(polite.exit_code) && WTERMSIG(polite.exit_code) == SIGINT);
  EXPECT_EQ(st("stubborn"), CommandStatus::Stopped);  // SIGKILL after stop_time_allowed
  EXPECT_TRUE(WIFSIGNALED(stubborn.exit_code) && WTERMSIG(stubborn.exit_code) == SIGKILL);
  EXPECT_EQ(st("exit0"), CommandStatus::Stopped);
  EXPECT_EQ(st("exit3"), CommandStatus::Failed);
  EXPECT_EQ(st("selfkill"), CommandStatus::Failed);
  EXPECT_EQ(st("killed"), CommandStatus::Failed);  // SIGKILL, but nobody ordered a stop
  const std::string table = s.table(now);
  EXPECT_NE(table.find("signal 2"), std::string::npos) << table;

  // A new sheriff session adopts them: those that ended by their stop signal or
  // SIGKILL read stopped, the others keep failed.
  Sheriff s2("s2");
  s2.load(parse_pmd(R"PMD(
cmd "polite" { exec = "sleep 100"; host = "testhost"; }
cmd "exit3" { exec = "sh -c 'exit 3'"; host = "testhost"; }
)PMD"));
  s2.on_info(d.deputy.report(aerie::util::wall_utime()), now);
  EXPECT_EQ(s2.status(*s2.find_by_name("polite"), now), CommandStatus::Stopped);
  EXPECT_EQ(s2.status(*s2.find_by_name("exit3"), now), CommandStatus::Failed);
  // An observer, which sends no orders, judges the same way.
  Sheriff obs("obs", /*observer=*/true);
  obs.on_info(d.deputy.report(aerie::util::wall_utime()), now);
  EXPECT_EQ(obs.status(*obs.find_by_name("polite"), now), CommandStatus::Stopped);
  EXPECT_EQ(obs.status(*obs.find_by_name("selfkill"), now), CommandStatus::Failed);
  EXPECT_EQ(obs.status(*obs.find_by_name("exit3"), now), CommandStatus::Failed);
}

// The reported fault: a deputy still holds stopped commands of an earlier sheriff
// session; a new sheriff with another config and no script comes up. Nothing may
// start, the old commands go away, and a start of the new sheriff works.
TEST(SheriffSessions, RestartAgainstADeputyHoldingOldCommandsStartsNothing) {
  test::DeputyHarness d;
  int64_t now = 0;
  {
    Sheriff old_sheriff("aerie-sheriff@ground");
    old_sheriff.load(parse_pmd(R"PMD(
cmd "a1" { exec = "sleep 100"; host = "testhost"; }
cmd "a2" { exec = "sleep 100"; host = "testhost"; }
cmd "a3" { exec = "sleep 100"; host = "testhost"; }
)PMD"));
    exchange(old_sheriff, d, now);
    const auto all = old_sheriff.select(TargetKind::Everything, "");
    old_sheriff.start(all);
    exchange(old_sheriff, d, now, 5);
    ASSERT_TRUE(old_sheriff.reached(all, WaitFor::Running, now));
    old_sheriff.stop(all);
    for (int i = 0; i < 300 && !old_sheriff.reached(all, WaitFor::Stopped, now); ++i) exchange(old_sheriff, d, now);
    ASSERT_TRUE(old_sheriff.reached(all, WaitFor::Stopped, now));
    EXPECT_EQ(d.deputy.commands().size(), 3u);  // held, stopped, with run ids != 0
  }
  // Same sheriff name (same host), other config, no script.
  Sheriff fresh("aerie-sheriff@ground");
  fresh.load(parse_pmd(R"PMD(
cmd "b1" { exec = "sleep 100"; host = "testhost"; }
cmd "b2" { exec = "sleep 100"; host = "testhost"; }
cmd "b3" { exec = "sleep 100"; host = "testhost"; }
)PMD"));
  for (int i = 0; i < 30; ++i) {
    exchange(fresh, d, now);
    ASSERT_FALSE(any_running(d)) << "a command started that nobody asked for (round " << i << ")";
  }
  ASSERT_EQ(d.deputy.commands().size(), 3u);
  for (const auto& [id, c] : d.deputy.commands()) {
    EXPECT_EQ(c.cmd.command_name[0], 'b');
    EXPECT_NE(fresh.find("testhost", id), nullptr);
  }
  for (const auto& c : fresh.commands()) EXPECT_EQ(fresh.status(c, now), CommandStatus::Stopped) << c.cmd.command_name;
  const auto b2 = fresh.select(TargetKind::Command, "b2");
  fresh.start(b2);
  for (int i = 0; i < 100 && !fresh.reached(b2, WaitFor::Running, now); ++i) exchange(fresh, d, now);
  EXPECT_TRUE(fresh.reached(b2, WaitFor::Running, now));
  int running = 0;
  for (const auto& [id, c] : d.deputy.commands()) running += c.pid != 0;
  EXPECT_EQ(running, 1);
}

// Two sheriffs in a row with different configs that share one command name: the
// shared command is adopted (it keeps running, same pid), the first sheriff's
// other commands are stopped and removed, the second's are not started.
TEST(SheriffSessions, TwoSheriffsInARowWithDifferentConfigs) {
  test::DeputyHarness d;
  int64_t now = 0;
  Sheriff first("sheriff-1");
  first.load(parse_pmd(R"PMD(
cmd "shared" { exec = "sleep 100"; host = "testhost"; }
cmd "only-first" { exec = "sleep 100"; host = "testhost"; }
)PMD"));
  exchange(first, d, now);
  const auto all = first.select(TargetKind::Everything, "");
  first.start(all);
  for (int i = 0; i < 100 && !first.reached(all, WaitFor::Running, now); ++i) exchange(first, d, now);
  ASSERT_TRUE(first.reached(all, WaitFor::Running, now));
  const int32_t shared_id = first.find_by_name("shared")->sheriff_id;
  const pid_t shared_pid = d.cmd(shared_id)->pid;
  const pid_t only_first_pid = d.cmd(first.find_by_name("only-first")->sheriff_id)->pid;

  Sheriff second("sheriff-2");
  second.load(parse_pmd(R"PMD(
cmd "shared" { exec = "sleep 100"; host = "testhost"; }
cmd "only-second" { exec = "sleep 100"; host = "testhost"; }
)PMD"));
  for (int i = 0; i < 100 && d.deputy.commands().size() != 2u; ++i) exchange(second, d, now);
  exchange(second, d, now, 10);
  ASSERT_EQ(d.deputy.commands().size(), 2u);
  EXPECT_EQ(second.find_by_name("shared")->sheriff_id, shared_id);  // adopted
  EXPECT_EQ(d.cmd(shared_id)->pid, shared_pid);                     // not restarted
  EXPECT_EQ(second.status(*second.find_by_name("shared"), now), CommandStatus::Running);
  EXPECT_EQ(kill(only_first_pid, 0), -1);                           // stopped (and reaped)
  const int32_t only_second = second.find_by_name("only-second")->sheriff_id;
  ASSERT_NE(d.cmd(only_second), nullptr);
  EXPECT_EQ(d.cmd(only_second)->pid, 0);  // not asked to run
  EXPECT_EQ(second.status(*second.find_by_name("only-second"), now), CommandStatus::Stopped);
  EXPECT_NE(d.text(0).find("taking orders from sheriff 'sheriff-2'"), std::string::npos) << d.text(0);
}
