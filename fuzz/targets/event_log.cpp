// The LCM event-log reader (common/logio/event_log.hpp) on the input as a log file, stopping
// at damage and resynchronising past it, and `aerie-log info` on it (tools/log/log_info.hpp:
// every payload typed by its fingerprint and decoded through the bounded decoder, sequence
// gaps, damage), printed as text and as JSON.
#include <sstream>

#include "common/logio/event_log.hpp"
#include "fuzz/fuzz_support.hpp"
#include "tools/log/log_info.hpp"

using namespace aerie;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::quiet();
  const std::string path = fuzz::temp_file("input.lcm", data, size);
  for (const bool resync : {false, true}) {
    fuzz::refusal_ok([&] {
      logio::Reader reader(path, {.resync = resync});
      logio::Event ev;
      while (reader.next(ev)) {
      }
    });
    fuzz::refusal_ok([&] {
      const logtools::LogSummary s = logtools::summarize(path, resync);
      std::ostringstream out;
      logtools::print_summary(s, out);
      logtools::print_summary_json(s, out);
    });
  }
  return 0;
}
