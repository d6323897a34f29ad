// aerie-cmd: the operator's commands from the shell (TRACK_CMD, PILOT_CMD, MAP_CMD). See docs/cmd.md.
#include <iostream>
#include <string>
#include <vector>

#include "tools/cmd/cli.hpp"

int main(int argc, char** argv) {
  return aerie::cmd::run(std::vector<std::string>(argv + 1, argv + argc), std::cout, std::cerr);
}
