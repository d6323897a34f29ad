#pragma once
// Turns a procman `exec` string into what execvp needs, as libbot2's deputy does:
// words split like a POSIX shell ('single', "double" quotes, backslash escapes),
// $VAR, ${VAR} and ${VAR:-default} expanded (not inside single quotes), and leading
// NAME=value words taken as environment variables for the command:
//
//   "LCM_DEFAULT_URL=$AIR_URL aerie-capture --config '${HOME}/cap.yaml'"
//
// No globbing, no command substitution, no pipes: commands needing a shell say
// `sh -c '...'` explicitly.
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace aerie::procman {

struct CommandLine {
  std::vector<std::pair<std::string, std::string>> env;  // NAME=value prefixes
  std::vector<std::string> argv;
};

// Looks up a variable; std::nullopt when it is not set.
using VariableLookup = std::function<std::optional<std::string>(const std::string&)>;
VariableLookup environment_lookup();  // getenv

// Throws std::invalid_argument naming the problem (unterminated quote, unset
// variable without a default, missing '}', no program).
CommandLine split_command_line(const std::string& exec, const VariableLookup& lookup = environment_lookup());

}  // namespace aerie::procman
