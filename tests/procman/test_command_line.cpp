#include <gtest/gtest.h>

#include <map>

#include "procman/command_line.hpp"

using namespace aerie::procman;

namespace {
VariableLookup vars(std::map<std::string, std::string> m) {
  return [m](const std::string& k) -> std::optional<std::string> {
    const auto it = m.find(k);
    if (it == m.end()) return std::nullopt;
    return it->second;
  };
}
using Argv = std::vector<std::string>;
}  // namespace

TEST(CommandLine, SplitsWordsWithQuotesAndEscapes) {
  const auto c = split_command_line("prog  a 'b c' \"d e\" f\\ g \"q\\\"uote\" 'it''s' x\"y\"z", vars({}));
  EXPECT_EQ(c.argv, (Argv{"prog", "a", "b c", "d e", "f g", "q\"uote", "its", "xyz"}));
  EXPECT_TRUE(c.env.empty());
}

TEST(CommandLine, ExpandsVariablesExceptInSingleQuotes) {
  const auto look = vars({{"HOME", "/root"}, {"URL", "udpm://239.255.76.67:7667?ttl=1"}, {"EMPTY", ""}});
  const auto c = split_command_line("p $HOME/x ${HOME}y \"$URL\" '$HOME' ${NOPE:-dflt} ${EMPTY:-e} cost$ $", look);
  EXPECT_EQ(c.argv, (Argv{"p", "/root/x", "/rooty", "udpm://239.255.76.67:7667?ttl=1", "$HOME", "dflt", "e", "cost$", "$"}));
}

TEST(CommandLine, LeadingAssignmentsBecomeEnvironment) {
  const auto c = split_command_line("A=1 B='two words' LCM_DEFAULT_URL=$U prog C=3", vars({{"U", "memq://"}}));
  ASSERT_EQ(c.env.size(), 3u);
  EXPECT_EQ(c.env[0], (std::pair<std::string, std::string>{"A", "1"}));
  EXPECT_EQ(c.env[1], (std::pair<std::string, std::string>{"B", "two words"}));
  EXPECT_EQ(c.env[2], (std::pair<std::string, std::string>{"LCM_DEFAULT_URL", "memq://"}));
  EXPECT_EQ(c.argv, (Argv{"prog", "C=3"}));
  // A quoted or expanded name is not an assignment (as in a shell).
  EXPECT_EQ(split_command_line("\"A=1\" prog", vars({})).argv, (Argv{"A=1", "prog"}));
  EXPECT_EQ(split_command_line("$V prog", vars({{"V", "A=1"}})).argv, (Argv{"A=1", "prog"}));
}

TEST(CommandLine, RejectsBrokenInputWithAClearMessage) {
  auto message = [](const std::string& exec) {
    try {
      split_command_line(exec, vars({}));
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("prog 'open").find("unterminated single quote at column 6"), std::string::npos);
  EXPECT_NE(message("prog \"open").find("unterminated double quote"), std::string::npos);
  EXPECT_NE(message("prog $UNSET_VAR").find("environment variable UNSET_VAR is not set"), std::string::npos);
  EXPECT_NE(message("prog ${X").find("missing '}'"), std::string::npos);
  EXPECT_NE(message("prog ${1X}").find("bad variable name"), std::string::npos);
  EXPECT_NE(message("A=1 B=2").find("no program"), std::string::npos);
  EXPECT_NE(message("   ").find("no program"), std::string::npos);
  EXPECT_NE(message("prog \\").find("trailing backslash"), std::string::npos);
}
