// aerie-sheriff <-> aerie-deputy over LCM (UDP multicast), as separate processes
// in a network namespace the test creates and removes.
#include <bot_procman/orders2_t.hpp>
#include <bot_procman/printf_t.hpp>
#include <gtest/gtest.h>
#include <signal.h>

#include <fstream>
#include <thread>

#include "common/bus/bus.hpp"
#include "procman/testbed.hpp"
#include "tests/procman/deputy_harness.hpp"
#include "tests/support/test_support.hpp"

using namespace aerie::procman;
using namespace std::chrono_literals;

namespace {

const std::string kUrl = "udpm://239.255.76.67:7667?ttl=0";

std::string bin(const std::string& name) { return (aerie::test::binary_dir() / "bin" / name).string(); }

std::vector<std::string> in(const testbed::NetNamespace& ns, std::vector<std::string> argv) {
  auto v = ns.exec_prefix();
  v.insert(v.end(), argv.begin(), argv.end());
  return v;
}

bool alive(pid_t pid) { return pid > 0 && kill(pid, 0) == 0; }

pid_t read_pid(const std::filesystem::path& p) {
  std::ifstream f(p);
  pid_t pid = 0;
  f >> pid;
  return pid;
}

bool contains(const std::string& text, const std::string& what) { return text.find(what) != std::string::npos; }

class ProcmanLcm : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const auto why = testbed::namespaces_unavailable(); !why.empty()) GTEST_SKIP() << why;
    ns_ = std::make_unique<testbed::NetNamespace>(testbed::unique_name("pm"));
    dir_ = aerie::test::scratch_dir("lcm");
  }
  std::unique_ptr<testbed::Process> deputy(const std::string& name, const std::string& log) {
    return std::make_unique<testbed::Process>(
        in(*ns_, {bin("aerie-deputy"), "--name", name, "--lcm-url", kUrl}), (dir_ / log).string());
  }
  // aerie-sheriff CONFIG --script SCRIPT --on-script-complete exit, in the namespace.
  std::unique_ptr<testbed::Process> sheriff(const std::string& config, const std::string& script,
                                            std::vector<std::string> extra = {}) {
    std::vector<std::string> argv{bin("aerie-sheriff"), config, "--script", script, "--on-script-complete", "exit",
                                  "--wait-timeout", "30", "--no-table", "--lcm-url", kUrl};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return std::make_unique<testbed::Process>(in(*ns_, argv), (dir_ / ("sheriff-" + script + ".log")).string());
  }
  std::string write_config(const std::string& text) {
    const auto p = dir_ / "test.pmd";
    std::ofstream(p) << text;
    return p.string();
  }
  std::unique_ptr<testbed::NetNamespace> ns_;
  std::filesystem::path dir_;
};

}  // namespace

TEST_F(ProcmanLcm, SheriffScriptStartsAndStopsCommandsOnADeputy) {
  const std::string cfg = write_config(
      "group \"g\" {\n"
      "  cmd \"talker\" { exec = \"sh -c 'echo hello from the talker; echo $$ > " + (dir_ / "talker.pid").string() +
      "; exec sleep 1000'\"; host = \"h1\"; stop_signal = 15; stop_time_allowed = 3; }\n"
      "  cmd \"crasher\" { exec = \"sh -c 'exit 4'\"; host = \"h1\"; }\n"
      "}\n"
      "script \"start_all\" {\n"
      "  start group \"g\";\n"
      "  wait cmd \"talker\" status \"running\";\n"
      "  wait cmd \"crasher\" status \"stopped\";\n"
      "  wait ms 300;\n"
      "  stop cmd \"talker\" wait \"stopped\";\n"
      "}\n");
  auto dep = deputy("h1", "deputy.log");
  auto sh = sheriff(cfg, "start_all", {"--show-output"});
  const auto rc = sh->wait(60s);
  const std::string log = sh->log();
  ASSERT_TRUE(rc.has_value()) << log;
  EXPECT_EQ(*rc, 0) << log;
  EXPECT_TRUE(contains(log, "script: done")) << log;
  EXPECT_TRUE(contains(log, "[h1:talker] hello from the talker")) << log;
  EXPECT_TRUE(contains(log, "h1/talker: starting -> running") || contains(log, "h1/talker: unknown -> running")) << log;
  EXPECT_TRUE(contains(log, "h1/talker: running -> ")) << log;
  EXPECT_TRUE(contains(log, "-> failed")) << log;  // the crasher, exit code 4
  EXPECT_TRUE(contains(log, "code 4")) << log;
  const pid_t talker = read_pid(dir_ / "talker.pid");
  EXPECT_GT(talker, 0);
  EXPECT_FALSE(alive(talker));
  EXPECT_EQ(dep->stop(SIGTERM, 10s), 0) << dep->log();
}

TEST_F(ProcmanLcm, ObserverWatchesAndDeputyExitLeavesNothingRunning) {
  const std::string pidfile = (dir_ / "sleeper.pid").string();
  const std::string childfile = (dir_ / "child.pid").string();
  const std::string cfg = write_config(
      "cmd \"sleeper\" { exec = \"sh -c 'echo $$ > " + pidfile + "; sleep 1000 & echo $! > " + childfile +
      "; wait'\"; host = \"h1\"; "
      "stop_signal = 15; stop_time_allowed = 1; }\n"
      "script \"start\" { start everything wait \"running\"; }\n");
  auto dep = deputy("h1", "deputy.log");
  auto sh = sheriff(cfg, "start");
  ASSERT_EQ(sh->wait(60s).value_or(-1), 0) << sh->log();
  // The sheriff is gone; the command keeps running. An observer sees it.
  for (int i = 0; i < 500 && (read_pid(pidfile) == 0 || read_pid(childfile) == 0); ++i) std::this_thread::sleep_for(10ms);
  const pid_t leader = read_pid(pidfile);
  ASSERT_TRUE(alive(leader));
  ASSERT_TRUE(alive(read_pid(childfile)));
  testbed::Process observer(in(*ns_, {bin("aerie-sheriff"), "--observe", "--no-table", "--lcm-url", kUrl}),
                            (dir_ / "observer.log").string());
  std::this_thread::sleep_for(2500ms);
  EXPECT_EQ(observer.stop(SIGINT, 5s), 0);
  const std::string olog = observer.log();
  EXPECT_TRUE(contains(olog, "h1/sleeper: unknown -> running")) << olog;
  EXPECT_TRUE(contains(olog, "h1 ")) << olog;
  EXPECT_TRUE(alive(leader));  // observing sends no orders
  // Stopping the deputy stops its commands, the background sleep included.
  EXPECT_EQ(dep->stop(SIGTERM, 10s), 0) << dep->log();
  EXPECT_FALSE(alive(leader));
  const pid_t child = read_pid(childfile);
  EXPECT_GT(child, 0);
  EXPECT_FALSE(alive(child));
}

TEST_F(ProcmanLcm, CommandsDieWithAKilledDeputy) {
  // Even SIGKILL (no clean-up possible): the command dies with its deputy
  // (PR_SET_PDEATHSIG) and its children with their terminal's session (SIGHUP).
  const std::string pidfile = (dir_ / "leader.pid").string(), childfile = (dir_ / "child.pid").string();
  const std::string cfg = write_config("cmd \"c\" { exec = \"sh -c 'echo $$ > " + pidfile + "; sleep 1000 & echo $! > " +
                                       childfile + "; wait'\"; host = \"h1\"; }\n"
                                       "script \"start\" { start everything wait \"running\"; }\n");
  auto dep = deputy("h1", "deputy.log");
  auto sh = sheriff(cfg, "start");
  ASSERT_EQ(sh->wait(60s).value_or(-1), 0) << sh->log();
  for (int i = 0; i < 500 && (read_pid(pidfile) == 0 || read_pid(childfile) == 0); ++i) std::this_thread::sleep_for(10ms);
  const pid_t leader = read_pid(pidfile), child = read_pid(childfile);
  ASSERT_TRUE(alive(leader));
  ASSERT_TRUE(alive(child));
  dep->stop(SIGKILL, 5s);
  const auto until = std::chrono::steady_clock::now() + 5s;
  while ((alive(leader) || alive(child)) && std::chrono::steady_clock::now() < until) std::this_thread::sleep_for(20ms);
  EXPECT_FALSE(alive(leader));
  EXPECT_FALSE(alive(child));
}

TEST_F(ProcmanLcm, SecondDeputyWithTheSameNameExits) {
  auto first = deputy("twin", "first.log");
  std::this_thread::sleep_for(2000ms);  // past its discovery phase
  auto second = deputy("twin", "second.log");
  const auto rc = second->wait(10s);
  ASSERT_TRUE(rc.has_value());
  EXPECT_EQ(*rc, 2);
  EXPECT_TRUE(contains(second->log(), "another deputy named 'twin'")) << second->log();
  EXPECT_TRUE(first->running());
}

TEST_F(ProcmanLcm, StaleOrdersAreRefusedOverLcm) {
  auto dep = deputy("h1", "deputy.log");
  testbed::EnterNamespace inside(*ns_);
  aerie::bus::Bus bus(kUrl);
  std::string said;
  bus.subscribe<bot_procman::printf_t>("PMD_PRINTF", [&](const bot_procman::printf_t& m, const auto&) {
    if (m.deputy_name == "h1") said += m.text;
  });
  test::CmdSpec c;
  c.exec = "sleep 1000";
  const auto until = std::chrono::steady_clock::now() + 15s;
  while (!contains(said, "clocks") && std::chrono::steady_clock::now() < until) {
    bus.publish("PMD_ORDERS2", test::make_orders("h1", {c}, /*age_us=*/300'000'000));
    bus.handle(200);
  }
  EXPECT_TRUE(contains(said, "refusing orders from sheriff 'test-sheriff': they are 300.")) << said;
  EXPECT_TRUE(contains(said, "Check that the clocks")) << said;
}
