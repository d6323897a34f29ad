#pragma once
// aerie-cmd's command line (docs/cmd.md), as a function so that tests run it on their own bus.
#include <iosfwd>
#include <string>
#include <vector>

#include "common/bus/bus.hpp"

namespace aerie::cmd {

// Runs `aerie-cmd ARGS...` (args without the program name). Returns the exit status: 0 sent
// (with --wait-ack: and it took effect), 1 not seen to take effect in time or the bus failed,
// 2 a usage error (one line on `err` naming the bad value). `bus`: send on it instead of
// opening --lcm-url (tests on memq://).
int run(const std::vector<std::string>& args, std::ostream& out, std::ostream& err, bus::Bus* bus = nullptr);

}  // namespace aerie::cmd
