#include "common/bus/input_clock.hpp"

#include <spdlog/spdlog.h>

namespace aerie::bus {

InputClock::InputClock(StatusReporter& status, std::string source, util::MessageClockConfig config)
    : status_(status), clock_(std::move(source), config) {
  status_.set(clock_.source() + ".stale", 0);
}

util::MessageClock::Result InputClock::observe(int64_t utime, int64_t now_us) {
  auto r = clock_.observe(utime, now_us);
  switch (r.verdict) {
    case util::MessageClock::Verdict::kHeld:
      status_.count(clock_.source() + ".time_jumps");
      status_.warn(r.reason);
      if (clock_.held() <= 10 || clock_.held() % 100 == 0) spdlog::warn("{}", r.reason);
      break;
    case util::MessageClock::Verdict::kResynced:
      status_.count(clock_.source() + ".time_resyncs");
      status_.ok(r.reason);
      spdlog::info("{}", r.reason);
      break;
    case util::MessageClock::Verdict::kAccepted:
      break;
  }
  if (r.accepted()) stale_changed(now_us, r.verdict == util::MessageClock::Verdict::kResynced);
  return r;
}

void InputClock::check(int64_t now_us) { stale_changed(now_us, false); }

void InputClock::stale_changed(int64_t now_us, bool resynced) {
  const auto change = clock_.stale_change(now_us);
  if (!change) return;
  const std::string& source = clock_.source();
  if (change->empty()) {
    status_.set(source + ".stale", 0);
    if (!resynced) status_.ok(source + " live again");
    spdlog::info("{} live again", source);
    return;
  }
  status_.set(source + ".stale", 1);
  status_.count(source + ".outages");
  status_.warn(*change);
  spdlog::warn("{}", *change);
}

}  // namespace aerie::bus
