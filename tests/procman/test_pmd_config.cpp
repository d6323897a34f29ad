#include <gtest/gtest.h>

#include <fstream>

#include "procman/pmd_config.hpp"
#include "tests/support/test_support.hpp"

using namespace aerie::procman;

namespace {

const char* kFull = R"PMD(
# A comment
cmd "top" { exec = "aerie-link --config \"config/link.yaml\""; host = "ground"; }
group "vision" {
    cmd "capture" {
        exec = "aerie-capture --fps 20";   # trailing comment
        host = "air";
        auto_respawn = "true";
        stop_signal = 15;
        stop_time_allowed = 5;
    }
    group "stereo" {
        cmd "vo" { exec = "aerie-vo"; host = "air"; stop_time_allowed = 2.5; }
    }
}
cmd { exec = "lcm-logger logs/x.lcm"; host = "ground"; group = "logging"; }
script "start_all" {
    start group "vision" wait "running";
    wait ms 500;
    stop cmd "top";
    restart everything;
    wait cmd "vo" status "stopped";
    wait group "vision/stereo" status "running";
    run_script "other";
}
script "other" { stop everything wait "stopped"; }
)PMD";

// Expects parse_pmd(text) to fail at line:column with a message containing `what`.
void expect_error(const std::string& text, int line, int column, const std::string& what) {
  try {
    parse_pmd(text, "broken.pmd");
    ADD_FAILURE() << "no error for:\n" << text;
  } catch (const PmdError& e) {
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_EQ(e.column(), column) << e.what();
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).rfind("broken.pmd:" + std::to_string(line) + ":" + std::to_string(column) + ": ", 0), 0u)
        << e.what();
  }
}

}  // namespace

TEST(PmdConfig, ParsesCommandsGroupsAndScripts) {
  const PmdConfig c = parse_pmd(kFull, "full.pmd");
  ASSERT_EQ(c.commands.size(), 4u);
  EXPECT_EQ(c.commands[0].name, "top");
  EXPECT_EQ(c.commands[0].exec, "aerie-link --config \"config/link.yaml\"");
  EXPECT_EQ(c.commands[0].group, "");
  EXPECT_EQ(c.commands[0].line, 3);
  EXPECT_EQ(c.commands[0].column, 1);
  const PmdCommand& cap = c.commands[1];
  EXPECT_EQ(cap.name, "capture");
  EXPECT_EQ(cap.host, "air");
  EXPECT_EQ(cap.group, "vision");
  EXPECT_TRUE(cap.auto_respawn);
  EXPECT_EQ(cap.stop_signal, 15);
  EXPECT_DOUBLE_EQ(cap.stop_time_allowed_s, 5.0);
  EXPECT_EQ(c.commands[2].group, "vision/stereo");
  EXPECT_DOUBLE_EQ(c.commands[2].stop_time_allowed_s, 2.5);
  EXPECT_EQ(c.commands[2].stop_signal, 2);  // libbot2 default: SIGINT
  EXPECT_FALSE(c.commands[2].auto_respawn);
  EXPECT_EQ(c.commands[3].name, "lcm-logger logs/x.lcm");  // unnamed: the exec string
  EXPECT_EQ(c.commands[3].group, "logging");
  EXPECT_EQ(c.hosts(), (std::vector<std::string>{"ground", "air"}));

  ASSERT_EQ(c.scripts.size(), 2u);
  const auto& a = c.find_script("start_all")->actions;
  ASSERT_EQ(a.size(), 7u);
  EXPECT_EQ(a[0].kind, ActionKind::Start);
  EXPECT_EQ(a[0].target, TargetKind::Group);
  EXPECT_EQ(a[0].ident, "vision");
  EXPECT_EQ(a[0].wait, WaitFor::Running);
  EXPECT_EQ(a[1].kind, ActionKind::WaitMs);
  EXPECT_EQ(a[1].wait_ms, 500);
  EXPECT_EQ(a[2].kind, ActionKind::Stop);
  EXPECT_EQ(a[2].target, TargetKind::Command);
  EXPECT_EQ(a[2].wait, WaitFor::Nothing);
  EXPECT_EQ(a[3].kind, ActionKind::Restart);
  EXPECT_EQ(a[3].target, TargetKind::Everything);
  EXPECT_EQ(a[4].kind, ActionKind::WaitStatus);
  EXPECT_EQ(a[4].wait, WaitFor::Stopped);
  EXPECT_EQ(a[5].ident, "vision/stereo");
  EXPECT_EQ(a[6].kind, ActionKind::RunScript);
  EXPECT_EQ(a[6].ident, "other");
}

TEST(PmdConfig, RoundTripsThroughItsOwnWriter) {
  const PmdConfig c = parse_pmd(kFull, "full.pmd");
  const std::string text = to_pmd(c);
  const PmdConfig d = parse_pmd(text, "written.pmd");
  ASSERT_EQ(d.commands.size(), c.commands.size()) << text;
  for (size_t i = 0; i < c.commands.size(); ++i) {
    EXPECT_EQ(d.commands[i].name, c.commands[i].name);
    EXPECT_EQ(d.commands[i].exec, c.commands[i].exec);
    EXPECT_EQ(d.commands[i].host, c.commands[i].host);
    EXPECT_EQ(d.commands[i].group, c.commands[i].group);
    EXPECT_EQ(d.commands[i].auto_respawn, c.commands[i].auto_respawn);
    EXPECT_EQ(d.commands[i].stop_signal, c.commands[i].stop_signal);
    EXPECT_DOUBLE_EQ(d.commands[i].stop_time_allowed_s, c.commands[i].stop_time_allowed_s);
  }
  ASSERT_EQ(d.scripts.size(), c.scripts.size());
  EXPECT_EQ(to_pmd(d), text);
}

TEST(PmdConfig, GroupContainment) {
  EXPECT_TRUE(group_contains("vision", "vision"));
  EXPECT_TRUE(group_contains("vision", "vision/stereo"));
  EXPECT_FALSE(group_contains("vision", "visionary"));
  EXPECT_FALSE(group_contains("vision/stereo", "vision"));
  EXPECT_TRUE(group_contains("", "anything"));
}

TEST(PmdConfig, SyntaxErrorsNameLineAndColumn) {
  expect_error("cmd \"a\" { exec = \"x\" host = \"h\"; }", 1, 22, "expected ';'");
  expect_error("cmd \"a\" {\n  exec = \"x;\n  host = \"h\";\n}", 2, 10, "unterminated string");
  expect_error("cmd \"a\" {\n  exec = \"x\";\n  hots = \"h\";\n}", 3, 3, "unknown attribute 'hots'");
  expect_error("cmd \"a\" { exec = \"x\"; host = \"h\"; auto_respawn = \"yes\"; }", 1, 50, "auto_respawn must be");
  expect_error("cmd \"a\" { exec = \"x\"; host = \"h\"; stop_signal = 0; }", 1, 49, "stop_signal");
  expect_error("cmd \"a\" { exec = \"x\"; host = \"h\"; stop_time_allowed = \"5\"; }", 1, 55, "a number");
  expect_error("cmd \"a\" { host = \"h\"; }", 1, 1, "has no exec");
  expect_error("cmd \"a\" { exec = \"x\"; }", 1, 1, "has no host");
  expect_error("group \"g\" {\n  script \"s\" { }\n}", 2, 3, "expected 'cmd' or 'group'");
  expect_error("group \"a/b\" { }", 1, 7, "'/' is not allowed");
  expect_error("cmd \"a\" { exec = \"x\"; host = \"h\"; }\nbogus", 2, 1, "expected 'cmd', 'group' or 'script'");
  expect_error("script \"s\" { start cmd a; }", 1, 24, "cmd name in double quotes");
  expect_error("script \"s\" { jump everything; }", 1, 14, "unknown script action");
  expect_error("script \"s\" { wait ms 1.5; }", 1, 22, "integer");
  expect_error("script \"s\" { start everything wait \"done\"; }", 1, 36, "\"running\" or \"stopped\"");
  expect_error("cmd \"a\" { exec = \"x\"; host = \"h\";", 1, 34, "an attribute or '}'");
  expect_error("cmd \"a\" { exec = \"x\"; exec = \"y\"; host = \"h\"; }", 1, 23, "given twice");
  expect_error("cmd \"a\" { exec = \"x\"; host = \"h\"; } @", 1, 37, "unexpected character '@'");
}

TEST(PmdConfig, ConsistencyErrorsNameTheLine) {
  expect_error("cmd \"a\" { exec = \"x\"; host = \"h\"; }\ncmd \"a\" { exec = \"y\"; host = \"h\"; }", 2, 1,
               "defined twice (first at line 1)");
  expect_error("cmd \"a\" { exec = \"x\"; host = \"h\"; }\nscript \"s\" {\n  stop cmd \"b\";\n}", 3, 3,
               "no command named \"b\"");
  expect_error("cmd \"a\" { exec = \"x\"; host = \"h\"; }\nscript \"s\" { start group \"g\"; }", 2, 14,
               "no group named \"g\"");
  expect_error("script \"s\" { run_script \"t\"; }", 1, 14, "no script named \"t\"");
  expect_error("script \"s\" { run_script \"t\"; }\nscript \"t\" { run_script \"s\"; }", 2, 14, "cycle");
  expect_error("script \"s\" { }\nscript \"s\" { }", 2, 1, "defined twice");
}

TEST(PmdConfig, LoadNamesTheFile) {
  EXPECT_THROW(load_pmd("/nonexistent/x.pmd"), std::runtime_error);
  const auto dir = aerie::test::scratch_dir("pmd");
  const auto path = (dir / "bad.pmd").string();
  std::ofstream(path) << "cmd \"a\" {\n  exec = 3;\n}\n";
  try {
    load_pmd(path);
    FAIL();
  } catch (const PmdError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path + ":2:10:", 0), 0u) << e.what();
  }
}

TEST(PmdConfig, ShippedConfigsParse) {
  for (const char* name : {"config/demo.pmd", "config/split.pmd"}) {
    const PmdConfig c = load_pmd((aerie::test::source_dir() / name).string());
    EXPECT_FALSE(c.commands.empty()) << name;
    EXPECT_NE(c.find_script("start_all"), nullptr) << name;
  }
  EXPECT_EQ(load_pmd((aerie::test::source_dir() / "config/split.pmd").string()).hosts().size(), 2u);
}

TEST(PmdConfig, NestingDepthIsBoundedWithAClearError) {
  // The reproducers: 20,000 nested groups and 50,000 chained run_script overflowed the stack.
  std::string groups = "cmd \"x\" { exec = \"true\"; host = \"h\"; }\n";
  for (int i = 0; i < 20000; ++i) groups += "group \"g" + std::to_string(i) + "\" {\n";
  groups += "cmd \"y\" { exec = \"true\"; host = \"h\"; }\n";
  for (int i = 0; i < 20000; ++i) groups += "}\n";
  expect_error(groups, 34, 1, "groups nested more than 32 deep");
  std::string chain = "cmd \"x\" { exec = \"true\"; host = \"h\"; }\n";
  for (int i = 0; i < 50000; ++i)
    chain += "script \"s" + std::to_string(i) + "\" { run_script \"s" + std::to_string(i + 1) + "\"; }\n";
  chain += "script \"s50000\" { start cmd \"x\"; }\n";
  expect_error(chain, 33, 16, "run_script \"s32\" chains scripts more than 32 deep");
  // Two chains of 20 checked one after the other: the second ends in the first, 40 deep.
  std::string late = "cmd \"x\" { exec = \"true\"; host = \"h\"; }\n";
  for (int i = 1; i < 20; ++i)
    late += "script \"s" + std::to_string(i) + "\" { run_script \"s" + std::to_string(i + 1) + "\"; }\n";
  late += "script \"s20\" { start cmd \"x\"; }\n";
  for (int i = 1; i < 20; ++i)
    late += "script \"a" + std::to_string(i) + "\" { run_script \"a" + std::to_string(i + 1) + "\"; }\n";
  late += "script \"a20\" { run_script \"s1\"; }\n";
  expect_error(late, 41, 16, "run_script \"s1\" chains scripts more than 32 deep");
  // 32 levels of each are fine.
  std::string ok = "cmd \"x\" { exec = \"true\"; host = \"h\"; }\n";
  for (int i = 0; i < 31; ++i) ok += "group \"g" + std::to_string(i) + "\" {\n";
  ok += "cmd \"y\" { exec = \"true\"; host = \"h\"; }\n";
  for (int i = 0; i < 31; ++i) ok += "}\n";
  for (int i = 0; i < 31; ++i) ok += "script \"s" + std::to_string(i) + "\" { run_script \"s" + std::to_string(i + 1) + "\"; }\n";
  ok += "script \"s31\" { start cmd \"x\"; }\n";
  EXPECT_NO_THROW(parse_pmd(ok));
}
