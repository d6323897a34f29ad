#pragma once
// The procman configuration format of libbot2 (bot2-procman's sheriff_config.py),
// so existing .pmd files load unchanged:
//
//   cmd "name" { exec = "aerie-capture --fps 20"; host = "air"; auto_respawn = "true";
//                stop_signal = 15; stop_time_allowed = 5; }
//   group "vision" { cmd "track" { ... }  group "sub" { ... } }
//   script "start_all" { start group "vision" wait "running"; wait ms 500;
//                        stop cmd "x"; wait cmd "x" status "stopped"; run_script "y"; }
//
// `#` starts a comment. Environment variables in `exec` ($VAR, ${VAR}) are expanded
// by the deputy that runs the command (procman/command_line.hpp). Errors name the
// file, line and column.
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace aerie::procman {

struct PmdCommand {
  std::string name;
  std::string exec;
  std::string host;
  std::string group;                  // "a/b" for nested groups, "" at top level
  bool auto_respawn = false;
  int stop_signal = 2;                // SIGINT, libbot2's default
  double stop_time_allowed_s = 7.0;   // then SIGKILL (libbot2's default)
  int line = 0, column = 0;           // where it is defined
};

enum class ActionKind { Start, Stop, Restart, WaitMs, WaitStatus, RunScript };
enum class TargetKind { Everything, Group, Command };
enum class WaitFor { Nothing, Running, Stopped };

struct ScriptAction {
  ActionKind kind = ActionKind::Start;
  TargetKind target = TargetKind::Everything;
  std::string ident;                  // group or command name, or the script for RunScript
  WaitFor wait = WaitFor::Nothing;    // Start/Stop/Restart "wait", or WaitStatus's status
  int64_t wait_ms = 0;                // WaitMs
  int line = 0, column = 0;
};

struct PmdScript {
  std::string name;
  std::vector<ScriptAction> actions;
  int line = 0, column = 0;
};

struct PmdConfig {
  std::string origin;                 // file name, for messages
  std::vector<PmdCommand> commands;
  std::vector<PmdScript> scripts;

  const PmdScript* find_script(const std::string& name) const;
  const PmdCommand* find_command(const std::string& name) const;
  // Hosts in order of first appearance.
  std::vector<std::string> hosts() const;
};

// A syntax or consistency error: what() is "origin:line:column: message".
class PmdError : public std::runtime_error {
 public:
  PmdError(const std::string& origin, int line, int column, const std::string& message);
  int line() const { return line_; }
  int column() const { return column_; }

 private:
  int line_, column_;
};

// Nesting bounds of a .pmd file, refused with the line of the offending group or
// run_script (20,000 nested groups or 50,000 chained scripts overflowed the stack).
inline constexpr int kMaxGroupDepth = 32;        // groups inside groups
inline constexpr int kMaxRunScriptDepth = 32;    // scripts calling scripts (run_script chains)

// Parses and validates (unique command names, a host and exec for every command,
// scripts referring only to existing commands, groups and scripts, no run_script cycle,
// the nesting bounds above).
PmdConfig parse_pmd(const std::string& text, const std::string& origin = "<string>");
PmdConfig load_pmd(const std::string& path);  // throws std::runtime_error if unreadable

// True when `group` is `prefix` or lies below it ("vision/stereo" is in "vision").
bool group_contains(const std::string& prefix, const std::string& group);

// Writes the configuration back in the same format (parse_pmd(to_pmd(c)) == c).
std::string to_pmd(const PmdConfig& config);

const char* to_string(WaitFor w);

}  // namespace aerie::procman
