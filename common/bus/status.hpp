#pragma once
// A node's heartbeat: named cumulative counters and per-period timings, published
// as aerie.process_status_t on STATUS_<NODE> about once a second. Counters of every
// subscription on the bus (received, malformed, gaps, handler errors; a queued one adds
// queue_overflows and queued) are included.
#include <aerie/process_status_t.hpp>

#include <cstdint>
#include <map>
#include <string>

#include "common/bus/bus.hpp"

namespace aerie::bus {

class StatusReporter {
 public:
  StatusReporter(Bus& bus, std::string node, double period_s = 1.0);

  void count(const std::string& name, int64_t n = 1) { counters_[name] += n; }
  void set(const std::string& name, int64_t value) { counters_[name] = value; }
  void time_ms(const std::string& stage, double ms);  // accumulates a mean over the period
  void error(const std::string& message);             // health ERROR until the next ok()
  void warn(const std::string& message);
  void ok(const std::string& message = "");
  // Source utime of the input being processed and the wall-clock receive/publish times.
  void mark_hop(int64_t source_utime, int64_t receive_utime, int64_t publish_utime);

  // Publishes when the period has elapsed since the last publication (wall clock).
  void tick();
  void publish_now();
  const std::string& channel() const { return channel_; }
  int64_t counter(const std::string& name) const;
  const std::string& message() const { return message_; }  // the latest ok/warn/error message

 private:
  Bus& bus_;
  std::string node_, channel_, host_;
  int64_t period_us_;
  int64_t last_publish_ = 0;
  int64_t seq_ = 0;
  int8_t health_ = aerie::process_status_t::OK;
  std::string message_;
  std::map<std::string, int64_t> counters_;
  std::map<std::string, std::pair<double, int>> timings_;
  int64_t hop_source_ = 0, hop_receive_ = 0, hop_publish_ = 0;
};

}  // namespace aerie::bus
