// The built aerie-cmd (build/<preset>/bin), run as an operator runs it: --help everywhere, exit
// status 2 with one line naming the bad value, and what it sends read back from an LCM log
// that its --lcm-url file://...?mode=w wrote.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <lcm/lcm-cpp.hpp>

#include <aerie/map_cmd_t.hpp>
#include <aerie/pilot_cmd_t.hpp>
#include <aerie/track_cmd_t.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "tests/support/test_support.hpp"
#include "tools/cmd/command.hpp"

namespace {

const std::string kTool = AERIE_BINARY_DIR "/bin/aerie-cmd";

struct ToolRun {
  int rc = -1;
  std::string out;
  std::string err;
};

// stdout and stderr apart (stderr through a file).
ToolRun run(const std::string& args) {
  const std::string err_file =
      (aerie::test::binary_dir() / "test-scratch" / ("aerie-cmd." + std::to_string(::getpid()) + ".stderr")).string();
  std::filesystem::create_directories(aerie::test::binary_dir() / "test-scratch");
  const aerie::test::ToolRun t = aerie::test::run_tool("'" + kTool + "' " + args + " 2>'" + err_file + "'");
  ToolRun r{t.rc, t.out, {}};
  std::ifstream e(err_file);
  r.err.assign(std::istreambuf_iterator<char>(e), {});
  return r;
}

struct Event {
  std::string channel;
  std::vector<uint8_t> data;
};

std::vector<Event> read_log(const std::string& path) {
  std::vector<Event> events;
  lcm::LogFile log(path, "r");
  EXPECT_TRUE(log.good()) << path;
  if (!log.good()) return events;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    const auto* d = static_cast<const uint8_t*>(ev->data);
    events.push_back({ev->channel, std::vector<uint8_t>(d, d + ev->datalen)});
  }
  return events;
}

template <typename M>
M decode(const Event& e) {
  M m{};
  EXPECT_EQ(m.decode(e.data.data(), 0, static_cast<int>(e.data.size())), static_cast<int>(e.data.size()));
  return m;
}

}  // namespace

TEST(CmdCli, HelpOnEverySubCommand) {
  ToolRun r = run("--help");
  EXPECT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("aerie-cmd: the operator's commands from the shell"), std::string::npos) << r.out;
  for (const char* word : {"track", "pilot", "map", "--lcm-url", "Exit status"})
    EXPECT_NE(r.out.find(word), std::string::npos) << word << " in " << r.out;
  const std::vector<std::pair<std::string, std::string>> subs = {
      {"track --help", "Usage: aerie-cmd track --box X,Y,W,H [--tracker NAME] [--camera CH] [--wait-ack S]"},
      {"track stop --help", "aerie-cmd track stop [--camera CH] [--wait-ack S]"},
      {"pilot --help", "Usage: aerie-cmd pilot abort|land|resume|start [--wait-ack S]"},
      {"map --help", "Usage: aerie-cmd map save [NAME] | load NAME | clear | publish"}};
  for (const auto& [args, usage] : subs) {
    r = run(args);
    EXPECT_EQ(r.rc, 0) << args << ": " << r.err;
    EXPECT_NE(r.out.find(usage), std::string::npos) << args << ": " << r.out;
  }
}

TEST(CmdCli, UsageErrorsExitTwoWithOneLine) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "aerie-cmd: A subcommand is required"},
      {"--bogus", "aerie-cmd: unknown option '--bogus' (see --help)"},
      {"fly", "aerie-cmd: unknown sub-command 'fly' (expected track, pilot or map; see --help)"},
      {"track --box 1,2,3 ", "--box '1,2,3': expected four numbers X,Y,W,H"},
      {"track --box 1,2,3,0", "H = 0"},
      {"track --box 1,2,3,4 --tracker nope", "--tracker 'nope': unknown tracker (known: "},
      {"track --box 1,2,3,4 --bogus", "aerie-cmd track: "},
      {"track --box 1,2,3,4 --wait-ack zero", "aerie-cmd track: --wait-ack: expected a number of seconds > 0, got 'zero'"},
      {"pilot abort --wait-ack 0", "aerie-cmd pilot: --wait-ack: expected a number of seconds > 0, got '0'"},
      {"pilot fly", "pilot: unknown command 'fly'"},
      {"map load", "map load: a file NAME is required"}};
  for (const auto& [args, message] : cases) {
    const ToolRun r = run(args + " --lcm-url memq://");
    EXPECT_EQ(r.rc, 2) << args << ": " << r.out << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << args << ": " << r.out;
  }
}

TEST(CmdCli, WhatItSendsIsInTheLog) {
  const auto dir = aerie::test::scratch_dir("log");
  // Runs `before URL after` with the LCM writing a log; the message of the one event, on `channel`.
  auto sent = [&]<typename M>(const std::string& before, const std::string& after, const std::string& channel, M m) {
    const std::string log = (dir / (channel + ".lcm")).string();
    const ToolRun r = run(before + " --lcm-url 'file://" + log + "?mode=w' " + after);
    EXPECT_EQ(r.rc, 0) << r.err;
    const auto events = read_log(log);
    EXPECT_EQ(events.size(), 1u) << log;
    if (events.size() != 1) return m;
    EXPECT_EQ(events[0].channel, channel);
    m = decode<M>(events[0]);
    EXPECT_EQ(m.seq, 0);
    EXPECT_GT(m.utime, 0);
    return m;
  };
  const auto t = sent("", "track --box 5,6,70,80 --tracker dcf --camera CAM_MONO", "TRACK_CMD", aerie::track_cmd_t{});
  EXPECT_EQ(t.command, aerie::track_cmd_t::INIT);
  EXPECT_EQ(t.tracker, "dcf");
  EXPECT_EQ(t.camera, "CAM_MONO");
  EXPECT_EQ(t.x, 5);
  EXPECT_EQ(t.y, 6);
  EXPECT_EQ(t.width, 70);
  EXPECT_EQ(t.height, 80);
  EXPECT_EQ(t.nparams, 0);
  // --lcm-url after the sub-command too.
  const auto p = sent("pilot land", "", "PILOT_CMD", aerie::pilot_cmd_t{});
  EXPECT_EQ(p.command, aerie::pilot_cmd_t::LAND);
  EXPECT_EQ(p.source, aerie::cmd::command_source());
  const auto m = sent("map save room.bt", "", "MAP_CMD", aerie::map_cmd_t{});
  EXPECT_EQ(m.command, aerie::map_cmd_t::SAVE);
  EXPECT_EQ(m.path, "room.bt");
  const ToolRun r = run("--lcm-url 'file://" + (dir / "out.lcm").string() + "?mode=w' track --box 5,6,70,80");
  EXPECT_EQ(r.out, "sent TRACK_CMD INIT tracker=(node's) camera=(node's) box=(5, 6, 70, 80)\n");
}

TEST(CmdCli, WaitAckWithNoAnswerExitsOne) {
  const ToolRun r = run("pilot abort --wait-ack 0.2 --lcm-url memq://");
  EXPECT_EQ(r.rc, 1) << r.err;
  EXPECT_NE(r.out.find("sent PILOT_CMD ABORT source=aerie-cmd@"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("not seen to take effect within 0.2 s: no message on PILOT_STATE"), std::string::npos) << r.out;
}

TEST(CmdCli, AnLcmThatCannotStartExitsOne) {
  const ToolRun r = run("pilot abort --lcm-url nosuch://x");
  EXPECT_EQ(r.rc, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("aerie-cmd pilot: "), std::string::npos) << r.err;
}
