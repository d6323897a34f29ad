#pragma once
// util::MessageClock (the message-time policy, docs/architecture.md "Message time") reporting
// into a node's status, the same way in every node:
//   "<source>.time_jumps"    messages held as a jump forwards/backwards (warning with the reason);
//   "<source>.time_resyncs"  re-synchronisations to a new time base (restart, outage; health OK
//                            with the reason);
//   "<source>.stale"         1 while no message was accepted for longer than the timeout, else 0;
//   "<source>.outages"       how many times it went stale (warning "... stale: no message for ...").
#include <cstdint>
#include <string>

#include "common/bus/status.hpp"
#include "common/util/message_clock.hpp"

namespace aerie::bus {

class InputClock {
 public:
  InputClock(StatusReporter& status, std::string source, util::MessageClockConfig config = {});

  // A message stamped `utime` received at node time `now_us`; use it only if accepted().
  // On Verdict::kResynced the node drops what it kept of the old time base.
  util::MessageClock::Result observe(int64_t utime, int64_t now_us);
  // Reports the source going stale (call from the node's periodic tick).
  void check(int64_t now_us);
  bool stale(int64_t now_us) const { return clock_.stale(now_us); }
  const util::MessageClock& clock() const { return clock_; }

 private:
  void stale_changed(int64_t now_us, bool resynced);

  StatusReporter& status_;
  util::MessageClock clock_;
};

}  // namespace aerie::bus
