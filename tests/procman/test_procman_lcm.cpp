// aerie-sheriff <-> aerie-deputy over LCM (UDP multicast), as separate processes
// in a network namespace the test creates and removes. Keyed by default (a test mission
// key); the libbot2 tests pass --insecure.
#include <aerie/process_status_t.hpp>
#include <bot_procman/orders2_t.hpp>
#include <bot_procman/printf_t.hpp>
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <functional>
#include <optional>
#include <thread>

#include "common/bus/bus.hpp"
#include "common/seal/keys.hpp"
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
    key_ = (dir_ / "mission.key").string();
    std::filesystem::remove(key_);
    aerie::seal::save_key(key_, aerie::seal::SecretKey::generate());
  }
  // Keyed (the test key, a state file of the test) unless `mode` says otherwise ({"--insecure"}, {}).
  std::unique_ptr<testbed::Process> deputy(const std::string& name, const std::string& log,
                                           std::optional<std::vector<std::string>> mode = std::nullopt) {
    std::vector<std::string> argv{bin("aerie-deputy"), "--name", name, "--lcm-url", kUrl};
    const auto m = mode.value_or(std::vector<std::string>{"--key", key_, "--state", (dir_ / (name + ".counters")).string()});
    argv.insert(argv.end(), m.begin(), m.end());
    return std::make_unique<testbed::Process>(in(*ns_, argv), (dir_ / log).string());
  }
  // aerie-sheriff CONFIG --script SCRIPT --on-script-complete exit, in the namespace (keyed
  // unless `extra` says --insecure).
  std::unique_ptr<testbed::Process> sheriff(const std::string& config, const std::string& script,
                                            std::vector<std::string> extra = {}, const std::string& log = "") {
    std::vector<std::string> argv{bin("aerie-sheriff"), config, "--script", script, "--on-script-complete", "exit",
                                  "--no-table", "--lcm-url", kUrl};
    if (std::find(extra.begin(), extra.end(), "--wait-timeout") == extra.end())
      argv.insert(argv.end(), {"--wait-timeout", "30"});
    if (std::find(extra.begin(), extra.end(), "--insecure") == extra.end()) argv.insert(argv.end(), {"--key", key_});
    argv.insert(argv.end(), extra.begin(), extra.end());
    return std::make_unique<testbed::Process>(
        in(*ns_, argv), (dir_ / (log.empty() ? "sheriff-" + script + ".log" : log)).string());
  }
  std::string write_config(const std::string& text) {
    const auto p = dir_ / "test.pmd";
    std::ofstream(p) << text;
    return p.string();
  }
  std::unique_ptr<testbed::NetNamespace> ns_;
  std::filesystem::path dir_;
  std::string key_;
};

// The deputy's STATUS_DEPUTY_<NAME> heartbeats, heard from inside the namespace.
struct StatusWatch {
  explicit StatusWatch(const testbed::NetNamespace& ns, const std::string& deputy) : inside(ns), bus(kUrl) {
    std::string channel = "STATUS_DEPUTY_" + deputy;
    for (auto& ch : channel) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
    bus.subscribe<aerie::process_status_t>(channel, [this](const aerie::process_status_t& m, const auto&) {
      last = m;
      heard = true;
      if (m.health == aerie::process_status_t::ERROR) errors.push_back(m.message);
    });
  }
  // Handles messages until pred() holds or the timeout.
  bool until(const std::function<bool()>& pred, std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (!pred() && std::chrono::steady_clock::now() < end) bus.handle(100);
    return pred();
  }
  int64_t counter(const std::string& name) const {
    for (size_t i = 0; i < last.counter_names.size(); ++i)
      if (last.counter_names[i] == name) return last.counter_values[i];
    return -1;
  }
  testbed::EnterNamespace inside;
  aerie::bus::Bus bus;
  aerie::process_status_t last;
  bool heard = false;
  std::vector<std::string> errors;
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
  auto dep = deputy("h1", "deputy.log", std::vector<std::string>{"--insecure"});  // libbot2's plain orders
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

TEST_F(ProcmanLcm, DeputyAndSheriffWithoutKeyOrInsecureRefuseToStart) {
  auto dep = deputy("h1", "deputy.log", std::vector<std::string>{});
  ASSERT_EQ(dep->wait(10s).value_or(-1), 1) << dep->log();
  EXPECT_TRUE(contains(dep->log(), "refusing to start without a key: give the mission key with --key FILE")) << dep->log();
  EXPECT_TRUE(contains(dep->log(), "or --insecure")) << dep->log();
  const std::string cfg = write_config("cmd \"c\" { exec = \"true\"; host = \"h1\"; }\n");
  testbed::Process sh(in(*ns_, {bin("aerie-sheriff"), cfg, "--no-table", "--lcm-url", kUrl}),
                      (dir_ / "sheriff.log").string());
  ASSERT_EQ(sh.wait(10s).value_or(-1), 1) << sh.log();
  EXPECT_TRUE(contains(sh.log(), "refusing to send orders without a key")) << sh.log();
  // A key file others can read is refused too (seal::load_key), naming the file.
  std::filesystem::permissions(key_, std::filesystem::perms::others_read, std::filesystem::perm_options::add);
  auto open_key = deputy("h1", "deputy-0604.log");
  ASSERT_EQ(open_key->wait(10s).value_or(-1), 1) << open_key->log();
  EXPECT_TRUE(contains(open_key->log(), key_ + ": mission key is readable or writable by others")) << open_key->log();
}

TEST_F(ProcmanLcm, KeyedDeputyIgnoresAnUnkeyedRogueSheriff) {
  const std::string marker = (dir_ / "rogue-ran").string();
  const std::string cfg = write_config("cmd \"evil\" { exec = \"touch " + marker + "\"; host = \"h1\"; }\n"
                                       "script \"start\" { start everything wait \"running\"; }\n");
  auto dep = deputy("h1", "deputy.log");
  StatusWatch status(*ns_, "h1");
  auto rogue = sheriff(cfg, "start", {"--insecure", "--wait-timeout", "4"});
  // The rogue hears the deputy's reports, sends its orders, and its wait fails.
  EXPECT_EQ(rogue->wait(30s).value_or(-1), 1) << rogue->log();
  EXPECT_TRUE(status.until([&] { return status.counter("orders_unauthenticated") >= 3; }, 5s)) << status.last.message;
  EXPECT_EQ(status.counter("orders_accepted"), 0);
  EXPECT_FALSE(std::filesystem::exists(marker));
  EXPECT_TRUE(contains(status.last.message, "keyed, key " + aerie::seal::fingerprint(aerie::seal::load_key(key_))))
      << status.last.message;
  dep->stop(SIGTERM, 10s);
  // Said once (with the sender's name), counted every time.
  const std::string log = dep->log();
  EXPECT_TRUE(contains(log, "refusing plain PMD_ORDERS2 from sheriff 'aerie-sheriff@")) << log;
  EXPECT_EQ(log.find("refusing plain PMD_ORDERS2"), log.rfind("refusing plain PMD_ORDERS2")) << log;
}

TEST_F(ProcmanLcm, TwoKeyedSheriffsAreNoticedAndOnlyTheFirstIsObeyed) {
  const std::string pidfile = (dir_ / "talker.pid").string(), marker = (dir_ / "rival-ran").string();
  const std::string real_cfg = write_config(
      "cmd \"talker\" { exec = \"sh -c 'echo $$ > " + pidfile + "; exec sleep 1000'\"; host = \"h1\"; "
      "stop_signal = 15; stop_time_allowed = 2; }\n"
      "script \"fly\" { start everything wait \"running\"; wait ms 9000; stop everything wait \"stopped\"; }\n");
  const auto rival_path = dir_ / "rival.pmd";
  std::ofstream(rival_path) << "cmd \"evil\" { exec = \"touch " << marker << "\"; host = \"h1\"; }\n"
                            << "script \"start\" { start everything wait \"running\"; }\n";
  auto dep = deputy("h1", "deputy.log");
  StatusWatch status(*ns_, "h1");
  auto real = sheriff(real_cfg, "fly", {"--name", "real"}, "real.log");
  for (int i = 0; i < 1000 && read_pid(pidfile) == 0; ++i) std::this_thread::sleep_for(10ms);
  const pid_t talker = read_pid(pidfile);
  ASSERT_TRUE(alive(talker)) << real->log();
  // A second sheriff with the same key: its orders (which omit the talker) are refused.
  auto rival = sheriff(rival_path.string(), "start", {"--name", "rival", "--wait-timeout", "4"}, "rival.log");
  EXPECT_EQ(rival->wait(30s).value_or(-1), 1) << rival->log();
  EXPECT_TRUE(status.until([&] { return !status.errors.empty(); }, 5s)) << status.last.message;
  ASSERT_FALSE(status.errors.empty());
  EXPECT_TRUE(contains(status.errors.back(), "two sheriffs: following sheriff 'real' (id ")) << status.errors.back();
  EXPECT_TRUE(contains(status.errors.back(), "refusing sheriff 'rival' (id ")) << status.errors.back();
  EXPECT_GT(status.counter("orders_other_sheriff"), 0);
  EXPECT_TRUE(alive(talker));  // never stopped by the rival's orders
  EXPECT_FALSE(std::filesystem::exists(marker));
  // The real sheriff's script ends as planned: it stops the talker itself.
  EXPECT_EQ(real->wait(60s).value_or(-1), 0) << real->log();
  EXPECT_FALSE(alive(talker));
  EXPECT_TRUE(contains(real->log(), "two sheriffs: 'rival' (id ")) << real->log();
  dep->stop(SIGTERM, 10s);
  EXPECT_TRUE(contains(dep->log(), "two sheriffs: following sheriff 'real'")) << dep->log();
  EXPECT_FALSE(contains(real->log(), "h1/talker: running -> unknown")) << real->log();
}

TEST_F(ProcmanLcm, RecordedOrdersReplayedAfterADeputyRestartAreRefused) {
  const std::string pidfile = (dir_ / "talker.pid").string();
  const std::string cfg = write_config(
      "cmd \"talker\" { exec = \"sh -c 'echo $$ > " + pidfile + "; exec sleep 1000'\"; host = \"h1\"; "
      "stop_signal = 15; stop_time_allowed = 2; }\n"
      "script \"fly\" { start everything wait \"running\"; wait ms 1500; stop everything wait \"stopped\"; }\n");
  auto dep = deputy("h1", "deputy.log");
  // Record every sealed order, as an intruder on the network would.
  std::vector<std::vector<uint8_t>> recorded;
  {
    testbed::EnterNamespace inside(*ns_);
    aerie::bus::Bus tap(kUrl);
    tap.subscribe_raw("PMD_ORDERS2_SEALED", [&](const uint8_t* d, size_t n, const auto&) { recorded.emplace_back(d, d + n); }, 1000);
    auto sh = sheriff(cfg, "fly");
    const auto until = std::chrono::steady_clock::now() + 60s;
    while (sh->running() && std::chrono::steady_clock::now() < until) tap.handle(50);
    ASSERT_EQ(sh->wait(1s).value_or(-1), 0) << sh->log();
    while (tap.handle(200) > 0) {
    }
  }
  ASSERT_GE(recorded.size(), 2u);
  ASSERT_GT(read_pid(pidfile), 0);
  std::filesystem::remove(pidfile);
  ASSERT_EQ(dep->stop(SIGTERM, 10s), 0) << dep->log();
  // Restarted with the same state file; the recording is replayed within the time window.
  auto again = deputy("h1", "deputy-again.log");
  StatusWatch status(*ns_, "h1");
  ASSERT_TRUE(status.until([&] { return contains(again->log(), "discovery done"); }, 10s)) << again->log();
  for (const auto& m : recorded) status.bus.publish_raw("PMD_ORDERS2_SEALED", m.data(), m.size());
  EXPECT_TRUE(status.until([&] { return status.counter("orders_replayed") == static_cast<int64_t>(recorded.size()); }, 5s))
      << status.counter("orders_replayed") << " of " << recorded.size();
  EXPECT_EQ(status.counter("orders_accepted"), 0);
  std::this_thread::sleep_for(500ms);
  EXPECT_FALSE(std::filesystem::exists(pidfile));  // the talker was not started again
  again->stop(SIGTERM, 10s);
  EXPECT_TRUE(contains(again->log(), "is not above the last accepted")) << again->log();
}

TEST_F(ProcmanLcm, ASheriffThatLeftIsSucceededAtOnceByTheNext) {
  // Sheriffs run one after another (scripts/split-demo.sh: start_all, later stop_all), each
  // with a new random id: the first one's "leaving" orders let the deputy follow the next at
  // once, without a "two sheriffs" error or the handover's 10 s of silence.
  const std::string pidfile = (dir_ / "talker.pid").string();
  const std::string cfg = write_config(
      "cmd \"talker\" { exec = \"sh -c 'echo $$ > " + pidfile + "; exec sleep 1000'\"; host = \"h1\"; "
      "stop_signal = 15; stop_time_allowed = 2; }\n"
      "script \"start\" { start everything wait \"running\"; }\n"
      "script \"stop\" { stop everything wait \"stopped\"; }\n");
  auto dep = deputy("h1", "deputy.log");
  auto first = sheriff(cfg, "start");
  ASSERT_EQ(first->wait(60s).value_or(-1), 0) << first->log();
  for (int i = 0; i < 500 && read_pid(pidfile) == 0; ++i) std::this_thread::sleep_for(10ms);  // "running": forked
  const pid_t talker = read_pid(pidfile);
  ASSERT_TRUE(alive(talker));
  const auto t0 = std::chrono::steady_clock::now();
  auto second = sheriff(cfg, "stop");
  ASSERT_EQ(second->wait(60s).value_or(-1), 0) << second->log();
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 8s) << second->log();
  EXPECT_FALSE(alive(talker));
  dep->stop(SIGTERM, 10s);
  const std::string log = dep->log();
  EXPECT_TRUE(contains(log, ") left (its last orders are applied)")) << log;
  EXPECT_FALSE(contains(log, "; sheriff")) << log;  // a second goodbye does not re-follow
  EXPECT_FALSE(contains(log, "two sheriffs")) << log;
  // Both sheriffs were followed in turn.
  const auto first_follow = log.find("following sheriff");
  ASSERT_NE(first_follow, std::string::npos) << log;
  EXPECT_NE(log.find("following sheriff", first_follow + 1), std::string::npos) << log;
}
