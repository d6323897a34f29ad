#pragma once
// aerie-log record: lcm-logger's job (every message on the LCM network into an event log in
// lcm-logger's format, which lcm-logplayer and aerie-log read) with a receive queue a loaded
// machine does not overflow. lcm-logger 1.3.1 subscribes with liblcm's default queue of 30
// messages per subscription; when its thread falls that far behind the receive thread,
// liblcm drops the next messages silently, with no socket drop to show for it (the
// 30-minute soak lost 7 of 640,345 messages that way, docs/results/soak.md). The recorder
// asks liblcm for `queue` messages and writes each one as it is handled.
#include <cstdint>
#include <string>

#include "common/bus/bus.hpp"
#include "common/logio/event_log.hpp"

namespace aerie::logtools {

struct RecordOptions {
  std::string path;
  std::string channels = ".*";  // LCM channel regular expression
  int queue = 2000;             // messages liblcm keeps for the recorder before it drops (0 = no limit)
  bool force = false;           // overwrite an existing file
  double flush_period_s = 0.1;  // the file is flushed this often (a crash loses at most this much)
};

class Recorder {
 public:
  // Opens the log and subscribes. Throws std::invalid_argument for an existing file without
  // `force`, a negative queue or flush period; std::runtime_error when the file cannot be created.
  Recorder(bus::Bus& bus, RecordOptions options);
  // From the thread that handles the bus: flushes the file every flush_period_s of `now_us`.
  void tick(int64_t now_us);
  void close();
  int64_t events() const { return writer_.events_written(); }
  int64_t bytes() const { return bytes_; }
  const std::string& path() const { return opt_.path; }

 private:
  RecordOptions opt_;
  logio::Writer writer_;
  int64_t bytes_ = 0, last_flush_us_ = 0;
};

}  // namespace aerie::logtools
