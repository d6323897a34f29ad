// The procman configuration parser (procman/pmd_config.hpp, libbot2's .pmd format) on the input
// as a file's text. An accepted configuration must survive to_pmd() and parse again; then a
// sheriff loads it, every command line is split as the deputy would before starting it
// (procman/command_line.hpp), and every script runs a few steps against the sheriff
// (start/stop/restart orders, waits with a timeout, nested run_script) without any process.
#include <cstdio>
#include <cstdlib>

#include "fuzz/fuzz_support.hpp"
#include "procman/command_line.hpp"
#include "procman/pmd_config.hpp"
#include "procman/sheriff.hpp"

using namespace aerie;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::quiet();
  procman::PmdConfig config;
  try {
    config = procman::parse_pmd(fuzz::as_text(data, size), "input.pmd");
  } catch (const std::runtime_error&) {  // PmdError, "file:line:column: ..."; anything else is a bug
    return 0;
  }
  try {
    procman::parse_pmd(procman::to_pmd(config), "written.pmd");
  } catch (const std::runtime_error& e) {
    std::fprintf(stderr, "to_pmd() wrote a configuration parse_pmd() refuses: %s\n", e.what());
    std::abort();
  }
  for (const procman::PmdCommand& c : config.commands)
    fuzz::refusal_ok([&] { procman::split_command_line(c.exec); });
  procman::Sheriff sheriff("fuzz", false, 3.0, 1);
  sheriff.load(config);
  for (const procman::PmdScript& s : config.scripts) {
    procman::ScriptRunner runner(sheriff, config, s.name, {}, 1.0);
    for (const int64_t now_ms : {0, 500, 1000, 2500})
      if (runner.step(now_ms) != procman::ScriptRunner::Status::Running) break;
    sheriff.orders(0);
  }
  return 0;
}
