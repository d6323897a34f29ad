// Sheriff logic: command states from deputy reports, orders, adoption of running
// commands, observer mode, and scripts run against a real in-process deputy.
#include <gtest/gtest.h>
#include <sys/wait.h>

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
  EXPECT_EQ(s.commands()[0].sheriff_id, 1);
  EXPECT_EQ(s.commands()[1].sheriff_id, 2);
  EXPECT_EQ(s.commands()[2].sheriff_id, 1);  // ids are per host
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
  auto state = [&](int64_t now) { return s.status(*s.find("testhost", 1), now); };
  EXPECT_EQ(state(0), CommandStatus::Unknown);  // no deputy yet
  s.on_info(info("testhost", {reported(1, "sleeper", 0, 0)}), 0);
  EXPECT_EQ(state(0), CommandStatus::Stopped);  // never started
  s.start(sleeper);
  EXPECT_EQ(state(0), CommandStatus::Starting);
  s.on_info(info("testhost", {reported(1, "sleeper", 100, 1)}), 100);
  EXPECT_EQ(state(100), CommandStatus::Running);
  EXPECT_TRUE(s.reached(sleeper, WaitFor::Running, 100));
  EXPECT_FALSE(s.reached(sleeper, WaitFor::Stopped, 100));
  s.restart(sleeper);
  EXPECT_EQ(state(100), CommandStatus::Restarting);
  EXPECT_FALSE(s.reached(sleeper, WaitFor::Running, 100));
  s.on_info(info("testhost", {reported(1, "sleeper", 101, 2)}), 200);
  EXPECT_EQ(state(200), CommandStatus::Running);
  s.stop(sleeper);
  EXPECT_EQ(state(200), CommandStatus::Stopping);
  s.on_info(info("testhost", {reported(1, "sleeper", 0, 2, W_EXITCODE(0, SIGTERM))}), 300);
  EXPECT_EQ(state(300), CommandStatus::Failed);  // ended by a signal
  EXPECT_TRUE(s.reached(sleeper, WaitFor::Stopped, 300));
  s.on_info(info("testhost", {reported(1, "sleeper", 0, 2, W_EXITCODE(0, 0))}), 400);
  EXPECT_EQ(state(400), CommandStatus::Stopped);
  // The deputy falls silent: unknown after the timeout.
  EXPECT_EQ(state(3400), CommandStatus::Stopped);
  EXPECT_EQ(state(3401), CommandStatus::Unknown);
  EXPECT_FALSE(s.deputy_alive("testhost", 3401));
  // A respawning command (auto_respawn, ended by itself).
  s.start(sleeper);
  s.on_info(info("testhost", {reported(1, "sleeper", 0, 3, W_EXITCODE(1, 0), true)}), 4000);
  EXPECT_EQ(state(4000), CommandStatus::Respawning);
  const std::string table = s.table(4000);
  EXPECT_NE(table.find("respawning"), std::string::npos) << table;
  EXPECT_NE(table.find("code 1"), std::string::npos) << table;
  EXPECT_NE(table.find("testhost"), std::string::npos) << table;
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
  EXPECT_NE(loop.deputy.text(2).find("talking"), std::string::npos);
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
